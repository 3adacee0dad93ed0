#!/usr/bin/env python3
"""Writes the glTF files of the bad-input corpus (tests/integration/bad_input.rs).

Run by hand from anywhere (`python3 tests/corpus/make_gltf.py`), not by cargo: the files it
writes are committed, and this script is how they were made and how to make them again. It
uses only Python's standard library, and writes the same bytes on every run.

Every file is built from one small model: a closed room 4 m x 2.5 m x 3 m (glTF is Y-up, in
metres), its faces turned inward, the floor plain grey and the walls and ceiling a base
colour times a 2 x 2 PNG texture, lit by a KHR_lights_punctual point light under the
ceiling. It writes:

- `odd-gltf-room.glb`: the room as a .glb, the texture in the binary chunk. Valid: it loads
  and solves without a warning (the ODD table).
- `odd-gltf-room-data-uri.gltf`: the room as a .gltf whose buffer and texture are `data:`
  URIs, lit by a spot light aimed at the floor as well. Valid, as above; with the .glb it is
  also the seed of the mutation test (tests/integration/gltf_mutations.rs).
- `gltf-*.glb`, `gltf-*.gltf` (and `gltf-buffer-short.bin`): one fault each, named by the
  file name; the FILES table says what the one error line about each must hold. A fault in
  the binary data (a NaN, an index past the vertex count) is in a .glb; a fault in the
  document's structure is in a .gltf, where a reader of the corpus can see it.
"""

import base64
import copy
import json
import math
import os
import struct
import zlib

HERE = os.path.dirname(os.path.abspath(__file__))

# The room's extent, in metres.
W, H, D = 4.0, 2.5, 3.0


def png_rgb(pixels):
    """A PNG (8-bit RGB, no interlace) of `pixels`, a list of rows of (r, g, b)."""

    def chunk(kind, data):
        crc = zlib.crc32(kind + data) & 0xFFFFFFFF
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", crc)

    height, width = len(pixels), len(pixels[0])
    raw = b"".join(b"\x00" + bytes(c for px in row for c in px) for row in pixels)
    header = struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)
    return (
        b"\x89PNG\r\n\x1a\n"
        + chunk(b"IHDR", header)
        + chunk(b"IDAT", zlib.compress(raw, 9))
        + chunk(b"IEND", b"")
    )


TEXTURE = png_rgb([[(200, 190, 180), (150, 150, 150)], [(150, 150, 150), (200, 190, 180)]])


def quad(origin, u, v):
    """The four corners of the parallelogram at `origin` spanned by `u` and `v` (its normal
    u x v), and its two triangles."""
    o = origin
    corners = [
        o,
        [o[k] + u[k] for k in range(3)],
        [o[k] + u[k] + v[k] for k in range(3)],
        [o[k] + v[k] for k in range(3)],
    ]
    return corners, [(0, 1, 2), (0, 2, 3)]


def room_faces():
    """(floor, walls and ceiling) of the room, each a list of (corners, triangles), every
    face's normal pointing into the room."""
    floor = [quad([0, 0, 0], [0, 0, D], [W, 0, 0])]
    rest = [
        quad([0, H, 0], [W, 0, 0], [0, 0, D]),
        quad([0, 0, 0], [0, H, 0], [0, 0, D]),
        quad([W, 0, 0], [0, 0, D], [0, H, 0]),
        quad([0, 0, 0], [W, 0, 0], [0, H, 0]),
        quad([0, 0, D], [0, H, 0], [W, 0, 0]),
    ]
    centre = [W / 2, H / 2, D / 2]
    for corners, _ in floor + rest:
        a, b, c = corners[0], corners[1], corners[3]
        u = [b[k] - a[k] for k in range(3)]
        v = [c[k] - a[k] for k in range(3)]
        n = [u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]]
        assert sum(n[k] * (centre[k] - a[k]) for k in range(3)) > 0, "a face turned outward"
    return floor, rest


def merge(faces):
    """One vertex list and one triangle list from several (corners, triangles)."""
    points, tris = [], []
    for corners, t in faces:
        base = len(points)
        points.extend(corners)
        tris.extend(tuple(base + i for i in tri) for tri in t)
    return points, tris


class Model:
    """A glTF document and its one binary buffer, built up part by part."""

    def __init__(self):
        self.bin = bytearray()
        self.doc = {
            "asset": {"version": "2.0", "generator": "tests/corpus/make_gltf.py"},
            "scene": 0,
            "scenes": [{"nodes": []}],
            "nodes": [],
            "meshes": [],
            "materials": [],
            "accessors": [],
            "bufferViews": [],
            "buffers": [],
        }

    def view(self, data, **extra):
        """A buffer view of `data`, appended to the buffer at a multiple of 4 bytes."""
        while len(self.bin) % 4:
            self.bin.append(0)
        self.doc["bufferViews"].append(
            dict(buffer=0, byteOffset=len(self.bin), byteLength=len(data), **extra)
        )
        self.bin.extend(data)
        return len(self.doc["bufferViews"]) - 1

    def positions(self, points):
        """A VEC3 float accessor of `points`, with the min and max glTF requires."""
        data = b"".join(struct.pack("<3f", *p) for p in points)
        finite = [p for p in points if all(math.isfinite(c) for c in p)]
        self.doc["accessors"].append(
            {
                "bufferView": self.view(data, target=34962),
                "componentType": 5126,
                "count": len(points),
                "type": "VEC3",
                "min": [min(p[k] for p in finite) for k in range(3)],
                "max": [max(p[k] for p in finite) for k in range(3)],
            }
        )
        return len(self.doc["accessors"]) - 1

    def indices(self, tris):
        """A SCALAR unsigned-short accessor of the triangles' indices."""
        flat = [i for t in tris for i in t]
        data = struct.pack("<%dH" % len(flat), *flat)
        self.doc["accessors"].append(
            {
                "bufferView": self.view(data, target=34963),
                "componentType": 5123,
                "count": len(flat),
                "type": "SCALAR",
            }
        )
        return len(self.doc["accessors"]) - 1

    def mesh(self, name, prims):
        """A mesh of primitives, each (points, triangles, material index or None)."""
        out = []
        for points, tris, material in prims:
            p = {"attributes": {"POSITION": self.positions(points)}, "indices": self.indices(tris)}
            if material is not None:
                p["material"] = material
            out.append(p)
        self.doc["meshes"].append({"name": name, "primitives": out})
        return len(self.doc["meshes"]) - 1

    def node(self, root=True, **fields):
        """A node; a root of the scene unless `root` is false."""
        self.doc["nodes"].append(fields)
        index = len(self.doc["nodes"]) - 1
        if root:
            self.doc["scenes"][0]["nodes"].append(index)
        return index

    def light(self, light):
        """A KHR_lights_punctual light; its index."""
        ext = self.doc.setdefault("extensions", {}).setdefault("KHR_lights_punctual", {})
        ext.setdefault("lights", []).append(light)
        used = self.doc.setdefault("extensionsUsed", [])
        if "KHR_lights_punctual" not in used:
            used.append("KHR_lights_punctual")
        return len(ext["lights"]) - 1

    def glb(self):
        """The .glb: its buffer the binary chunk."""
        doc = copy.deepcopy(self.doc)
        doc["buffers"] = [{"byteLength": len(self.bin)}]
        js = json.dumps(doc, separators=(",", ":")).encode()
        js += b" " * (-len(js) % 4)
        bin_ = bytes(self.bin) + b"\x00" * (-len(self.bin) % 4)
        body = struct.pack("<I4s", len(js), b"JSON") + js + struct.pack("<I4s", len(bin_), b"BIN\x00") + bin_
        return struct.pack("<4sII", b"glTF", 2, 12 + len(body)) + body

    def gltf(self, uri=None, byte_length=None):
        """The .gltf text: its buffer a `data:` URI, or the file `uri` (`byte_length`, if
        given, what it claims to hold)."""
        doc = copy.deepcopy(self.doc)
        if uri is None:
            uri = "data:application/octet-stream;base64," + base64.b64encode(self.bin).decode()
        n = len(self.bin) if byte_length is None else byte_length
        doc["buffers"] = [{"byteLength": n, "uri": uri}]
        return (json.dumps(doc, indent=1) + "\n").encode()


def room(light="point", texture="bin", material_fault=None):
    """The room (see the top of the file). `texture`: "bin" (in the buffer), "uri" (a data
    URI) or None; `light`: "point", "point+spot" or None."""
    m = Model()
    floor, rest = room_faces()
    m.doc["materials"] = [
        {"name": "floor", "pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.5, 0.5, 1.0]}},
        {"name": "plaster", "pbrMetallicRoughness": {"baseColorFactor": [0.9, 0.9, 0.9, 1.0]}},
    ]
    if texture is not None:
        if texture == "bin":
            image = {"bufferView": None, "mimeType": "image/png"}
        else:
            image = {"uri": "data:image/png;base64," + base64.b64encode(TEXTURE).decode()}
        m.doc["images"] = [image]
        m.doc["textures"] = [{"source": 0}]
        m.doc["materials"][1]["pbrMetallicRoughness"]["baseColorTexture"] = {"index": 0}
    if material_fault is not None:
        m.doc["materials"][0]["pbrMetallicRoughness"]["baseColorFactor"] = material_fault
    mesh = m.mesh("room", [merge(floor) + (0,), merge(rest) + (1,)])
    m.node(name="room", mesh=mesh)
    if texture == "bin":
        # After the geometry, so the accessors' views come first.
        m.doc["images"][0]["bufferView"] = m.view(TEXTURE)
    if light in ("point", "point+spot"):
        lamp = m.light({"name": "lamp", "type": "point", "color": [1.0, 0.95, 0.9], "intensity": 60.0})
        m.node(name="lamp", translation=[W / 2, H - 0.3, D / 2], extensions={"KHR_lights_punctual": {"light": lamp}})
    if light == "point+spot":
        spot = m.light(
            {"name": "spot", "type": "spot", "intensity": 200.0, "spot": {"innerConeAngle": 0.3, "outerConeAngle": 0.6}}
        )
        # −Z, where a spot light aims, turned down to −Y.
        s = math.sqrt(0.5)
        m.node(name="spot", translation=[1.0, H - 0.1, 1.0], rotation=[-s, 0.0, 0.0, s],
               extensions={"KHR_lights_punctual": {"light": spot}})
    return m


def write(name, data):
    with open(os.path.join(HERE, name), "wb") as f:
        f.write(data)


def one_triangle(points, tris, **accessor_fields):
    """A model of one mesh over `points` and `tris` (no material), lit by a point light;
    `accessor_fields` overwrite the positions accessor's fields."""
    m = Model()
    m.mesh("tri", [(points, tris, None)])
    m.doc["accessors"][0].update(accessor_fields)
    m.node(name="tri", mesh=0)
    lamp = m.light({"type": "point", "intensity": 10.0})
    m.node(name="lamp", translation=[0.3, 0.3, 1.0], extensions={"KHR_lights_punctual": {"light": lamp}})
    return m


def valid():
    write("odd-gltf-room.glb", room().glb())
    write("odd-gltf-room-data-uri.gltf", room(light="point+spot", texture="uri").gltf())


def broken_containers():
    """Faults in the file itself: cut short, not JSON, a bad .glb header, a buffer missing
    or short."""
    glb = room().glb()
    bin_start = glb.index(b"BIN\x00") + 4
    write("gltf-truncated.glb", glb[: bin_start + (len(glb) - bin_start) // 2])
    write("gltf-bad-magic.glb", b"glTX" + glb[4:])
    write("gltf-bad-version.glb", glb[:4] + struct.pack("<I", 1) + glb[8:])
    write("gltf-not-json.gltf", b"This is not JSON; a glTF document starts with '{'.\n")
    write("gltf-empty-object.gltf", b"{}\n")
    m = room(texture=None)
    write("gltf-missing-bin.gltf", m.gltf(uri="no-such-buffer.bin"))
    write("gltf-buffer-short.bin", bytes(m.bin[: len(m.bin) // 2]))
    write("gltf-buffer-short.gltf", m.gltf(uri="gltf-buffer-short.bin", byte_length=len(m.bin)))


def broken_data():
    """Faults in the binary data and the accessors and views that read it."""
    tri = [[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]]
    write("gltf-position-nan.glb", one_triangle([[0, 0, 0], [1, 0, 0], [0, float("nan"), 0]], [(0, 1, 2)]).glb())
    write("gltf-index-out-of-range.glb", one_triangle(tri, [(0, 1, 2), (1, 7, 2)]).glb())
    write("gltf-accessor-count-zero.gltf", one_triangle(tri, [(0, 1, 2)], count=0).gltf())
    m = one_triangle(tri, [(0, 1, 2)])
    m.doc["bufferViews"][0]["byteLength"] += 4096
    write("gltf-view-past-buffer.gltf", m.gltf())
    m = one_triangle(tri, [(0, 1, 2)])
    m.doc["bufferViews"][0]["byteStride"] = 8
    write("gltf-stride-shorter-than-element.gltf", m.gltf())
    m = one_triangle(tri, [(0, 1, 2)])
    m.doc["meshes"][0]["primitives"][0]["mode"] = 1
    write("gltf-lines-only.gltf", m.gltf())


def broken_structure():
    """Faults in the document: a node cycle, an extension required, bad light and material
    values, no light."""
    tri = [[0, 0, 0], [1, 0, 0], [0, 1, 0]]
    m = one_triangle(tri, [(0, 1, 2)])
    # Node 0 (the mesh) and the lamp stay; the scene's root is a new node 2 over node 0,
    # whose child is node 3, whose child is node 0 again.
    m.doc["nodes"][0]["children"] = [3]
    m.node(root=False, name="top", children=[0])
    m.node(root=False, name="loop", children=[0])
    m.doc["scenes"][0]["nodes"] = [2, 1]
    write("gltf-node-cycle.gltf", m.gltf())
    m = one_triangle(tri, [(0, 1, 2)])
    m.doc["extensionsUsed"].append("KHR_draco_mesh_compression")
    m.doc["extensionsRequired"] = ["KHR_draco_mesh_compression"]
    write("gltf-requires-draco.gltf", m.gltf())
    m = one_triangle(tri, [(0, 1, 2)])
    m.doc["extensions"]["KHR_lights_punctual"]["lights"][0] = {
        "name": "downlight",
        "type": "spot",
        "intensity": -5.0,
        "spot": {"outerConeAngle": 0.5},
    }
    write("gltf-spot-negative-intensity.gltf", m.gltf())
    write("gltf-base-colour-negative.gltf", room(texture=None, material_fault=[-0.5, 0.5, 0.5, 1.0]).gltf())
    write("gltf-no-light.gltf", room(light=None, texture=None).gltf())


if __name__ == "__main__":
    valid()
    broken_containers()
    broken_data()
    broken_structure()
