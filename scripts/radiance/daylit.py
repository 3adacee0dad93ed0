#!/usr/bin/env python3
"""Write the project's daylit test scenes (side-lit, deep-plan, atrium) as OBJ + MTL, deterministic.

Metres, +Y up, north = -Z (the tool's defaults: ``--zenith 0,1,0 --north 0,0,-1``), so east is
+X and **south is +Z**. Every building is modelled inside and out: walls, floors and roofs are
solids of real thickness, windows are holes through them with a glass pane in the hole.

Scenes (``--scene``, default all):

* ``sidelit``: a side-lit room, inside 4.0 m wide (x 0..4) x 6.0 m deep (z 0..6, the window
  wall at z = 6) x 3.0 m high (y 0..3); walls, floor and roof 0.2 m thick; one window
  3.0 x 1.5 m (x 0.5..3.5, sill 0.9 m, head 2.4 m) in the south wall, its pane in the middle of
  the wall (z = 6.1), facing north into the room;
* ``sidelit-open``: the same room with the hole left open (no pane), to tell glazing errors
  from the rest;
* ``deepplan``: a deep-plan office floor, inside 20 x 12 x 3 m (x 0..20, z 0..12), glazed on
  both long facades (north z = 0 and south z = 12) with ribbon windows: 8 panes of 2.3 x 1.4 m
  per facade (sill 0.9 m, head 2.3 m) between 0.2 m piers; a service core (2.8 x 2.2 m, full
  height) in the middle, eight desks (1.6 x 0.8 m, top at 0.75 m on two end panels) and six
  partitions 1.5 m high;
* ``atrium``: a top-lit atrium, inside 18 x 18 m (x, z 0..18) and 12 m high (y 0..12), three
  storeys (floors at y 0, 4, 8; slabs 0.3 m); the atrium 10 x 10 m (x, z 4..14) is open through
  all three storeys, ringed on the upper two by 4 m deep galleries with solid parapets (1.0 m
  high, 0.15 m thick); no windows in the walls; the roof (0.3 m) has a roof light over the whole
  atrium, its pane in the middle of the roof slab (y = 12.15), facing down into the building.

Geometry is built from axis-aligned boxes, added or cut in order, on the grid of all their
coordinates; a face is written wherever a solid cell meets an empty one, lying on their shared
plane with its front towards the empty cell (counter-clockwise seen from the front: the tool's
one-sided convention), and coplanar neighbouring faces of the same material are merged into
rectangles. So every solid is closed, no two faces overlap, and faces that touch (a desk's end
panel on the floor, a partition on the floor) are cut where they touch. A reveal (the side of a
hole) is split at its pane's plane, so its patches are either outside or inside the glass.

A face's material follows from what it faces: an empty cell inside the building (a room box)
makes floor (facing up), ceiling (facing down) or wall; a cell in a hole makes reveal; a cell
outside makes roof, facade or soffit (the underside of the ground slab). Furniture has its own,
and the atrium's parapets are wall all round (so only floors are ``floor``: the grid's rule in
``daylight.py --points-only`` puts its work plane over faces of that name).

Materials (``daylit.mtl``, grey, diffuse reflectance Kd): ceiling 0.8, wall 0.6, floor 0.3,
reveal 0.6, facade 0.4, roof 0.2, soffit 0.2, desk 0.5, partition 0.5, and ``glass``: Kd 0.08
(the pane's diffuse reflectance) with ``Tf 0.7 0.7 0.7`` (straight-through transmittance). The
pane is a single polygon (the tool lets a transmissive face pass rays from both sides).

    python3 scripts/radiance/daylit.py --out out/daylit                  # all scenes
    python3 scripts/radiance/daylit.py --out out/daylit --scene sidelit
"""

from __future__ import annotations

import argparse
import sys
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from common import r6  # noqa: E402

SCENES = ("sidelit", "sidelit-open", "deepplan", "atrium")
MTL_NAME = "daylit.mtl"

# name: (Kd, extra MTL lines)
MATERIALS = {
    "ceiling": (0.8, []),
    "wall": (0.6, []),
    "floor": (0.3, []),
    "reveal": (0.6, []),
    "facade": (0.4, []),
    "roof": (0.2, []),
    "soffit": (0.2, []),
    "desk": (0.5, []),
    "partition": (0.5, []),
    "glass": (0.08, ["Tf 0.7 0.7 0.7"]),
}

SHELL = 1  # solid kinds: the building's fabric, then furniture
KIND_MATERIAL = {2: "desk", 3: "partition", 4: "wall"}
DESK, PARTITION, PARAPET = 2, 3, 4


Box = tuple  # (x0, x1, y0, y1, z0, z1)


def inside_box(p, b: Box) -> bool:
    """Whether point ``p`` lies strictly inside box ``b``."""
    return (b[0] < p[0] < b[1]) and (b[2] < p[1] < b[3]) and (b[4] < p[2] < b[5])


@dataclass
class Pane:
    """A glass rectangle in a hole: plane ``axis`` = ``coord``, facing ``sign`` along the axis,
    spanning the hole's box in the other two axes."""

    hole: Box
    axis: int
    coord: float
    sign: int


@dataclass
class Building:
    """Boxes added (with a solid kind) or cut, in order; room boxes (inside the building);
    holes (cut boxes whose empty cells are reveals); panes."""

    ops: list = field(default_factory=list)
    rooms: list = field(default_factory=list)
    holes: list = field(default_factory=list)
    panes: list = field(default_factory=list)

    def add(self, box: Box, kind: int = SHELL):
        self.ops.append((tuple(r6(c) for c in box), kind))

    def cut(self, box: Box):
        self.ops.append((tuple(r6(c) for c in box), 0))

    def window(self, hole: Box, axis: int, sign: int, glazed: bool = True):
        """A hole through a wall or roof along ``axis``, with a pane in its middle facing
        ``sign`` (towards the inside) when ``glazed``."""
        self.cut(hole)
        self.holes.append(tuple(r6(c) for c in hole))
        mid = r6((hole[2 * axis] + hole[2 * axis + 1]) / 2)
        if glazed:
            self.panes.append(Pane(tuple(r6(c) for c in hole), axis, mid, sign))
        else:
            # Keep the split of the reveal at the same place as in the glazed variant.
            self.panes.append(Pane(tuple(r6(c) for c in hole), axis, mid, 0))


# --------------------------------------------------------------------------------------------
# Cells and faces.


def cell_grid(b: Building):
    """Break coordinates per axis and the cells' solid kind (0 empty), ops applied in order."""
    breaks = []
    for a in range(3):
        cs = {c for box, _ in b.ops for c in (box[2 * a], box[2 * a + 1])}
        cs |= {p.coord for p in b.panes if p.axis == a}
        breaks.append(np.array(sorted(cs)))
    kind = np.zeros([len(x) - 1 for x in breaks], dtype=np.int8)
    for box, k in b.ops:
        sl = tuple(slice(int(np.searchsorted(breaks[a], box[2 * a])),
                         int(np.searchsorted(breaks[a], box[2 * a + 1]))) for a in range(3))
        kind[sl] = k
    return breaks, kind


def face_material(b: Building, solid_kind: int, axis: int, sign: int, centre) -> str:
    """The material of a face of a ``solid_kind`` cell facing ``sign`` along ``axis`` towards
    the empty cell centred at ``centre``."""
    if solid_kind != SHELL:
        return KIND_MATERIAL[solid_kind]
    if any(inside_box(centre, r) for r in b.rooms):
        if axis == 1:
            return "floor" if sign > 0 else "ceiling"
        return "wall"
    if any(inside_box(centre, h) for h in b.holes):
        return "reveal"
    if axis == 1:
        return "roof" if sign > 0 else "soffit"
    return "facade"


def region(b: Building, centre) -> tuple:
    """Which side of each pane's plane a face cell inside that pane's hole lies on (so reveals
    are split at the pane)."""
    key = []
    for p in b.panes:
        if inside_box(centre, p.hole):
            key.append(1 if centre[p.axis] > p.coord else -1)
        else:
            key.append(0)
    return tuple(key)


def greedy_rectangles(labels):
    """Rectangles (i0, i1, j0, j1, label) covering the non-None cells of a 2D list-of-lists,
    each of one label, grown along j then i (deterministic)."""
    ni, nj = len(labels), len(labels[0]) if labels else 0
    done = [[False] * nj for _ in range(ni)]
    rects = []
    for i in range(ni):
        for j in range(nj):
            lab = labels[i][j]
            if lab is None or done[i][j]:
                continue
            j1 = j + 1
            while j1 < nj and labels[i][j1] == lab and not done[i][j1]:
                j1 += 1
            i1 = i + 1
            while i1 < ni and all(labels[i1][jj] == lab and not done[i1][jj]
                                  for jj in range(j, j1)):
                i1 += 1
            for ii in range(i, i1):
                for jj in range(j, j1):
                    done[ii][jj] = True
            rects.append((i, i1, j, j1, lab))
    return rects


def rect_vertices(axis, coord, sign, u0, u1, v0, v1):
    """The 4 corners (x, y, z) of an axis-aligned rectangle, counter-clockwise seen from the
    side ``sign`` points to (u = axis+1, v = axis+2, so u x v = +axis)."""
    u, v = (axis + 1) % 3, (axis + 2) % 3
    corners = [(u0, v0), (u1, v0), (u1, v1), (u0, v1)]
    if sign < 0:
        corners = corners[::-1]
    out = []
    for cu, cv in corners:
        p = [0.0, 0.0, 0.0]
        p[axis], p[u], p[v] = coord, cu, cv
        out.append(tuple(r6(c) for c in p))
    return out


def faces_of(b: Building):
    """All faces (material, 4 corners): the boundary between solid and empty cells, merged, and
    the panes."""
    breaks, kind = cell_grid(b)
    centres = [(x[:-1] + x[1:]) / 2 for x in breaks]
    faces = []
    for axis in range(3):
        u, v = (axis + 1) % 3, (axis + 2) % 3
        k = np.moveaxis(kind, (axis, u, v), (0, 1, 2))
        pad = np.zeros((1,) + k.shape[1:], dtype=k.dtype)
        k = np.concatenate([pad, k, pad])  # k[m] is cell m - 1; plane m lies at breaks[m]
        for m in range(len(breaks[axis])):
            below, above = k[m], k[m + 1]
            for sign, solid, empty in ((1, below, above), (-1, above, below)):
                mask = (solid > 0) & (empty == 0)
                if not mask.any():
                    continue
                # The empty cell's centre along the axis (beyond the grid: 1 m outside).
                if sign > 0:
                    e_centre = (centres[axis][m] if m < len(centres[axis])
                                else breaks[axis][m] + 1.0)
                else:
                    e_centre = centres[axis][m - 1] if m > 0 else breaks[axis][0] - 1.0
                labels = [[None] * mask.shape[1] for _ in range(mask.shape[0])]
                for i, j in zip(*np.nonzero(mask)):
                    c = [0.0, 0.0, 0.0]
                    c[axis], c[u], c[v] = e_centre, centres[u][i], centres[v][j]
                    labels[i][j] = (face_material(b, int(solid[i, j]), axis, sign, c),
                                    region(b, c))
                for i0, i1, j0, j1, lab in greedy_rectangles(labels):
                    faces.append((lab[0], rect_vertices(axis, breaks[axis][m], sign,
                                                        breaks[u][i0], breaks[u][i1],
                                                        breaks[v][j0], breaks[v][j1])))
    for p in b.panes:
        if p.sign == 0:
            continue
        u, v = (p.axis + 1) % 3, (p.axis + 2) % 3
        faces.append(("glass", rect_vertices(p.axis, p.coord, p.sign, p.hole[2 * u],
                                             p.hole[2 * u + 1], p.hole[2 * v],
                                             p.hole[2 * v + 1])))
    return faces


# --------------------------------------------------------------------------------------------
# The scenes.


def shell(b: Building, inside: Box, t_wall: float, t_floor: float, t_roof: float):
    """A closed shell around the room box ``inside``: walls ``t_wall`` thick, a ground slab
    ``t_floor`` and a roof ``t_roof`` thick."""
    x0, x1, y0, y1, z0, z1 = inside
    b.add((x0 - t_wall, x1 + t_wall, y0 - t_floor, y1 + t_roof, z0 - t_wall, z1 + t_wall))
    b.cut(inside)
    b.rooms.append(tuple(r6(c) for c in inside))


def sidelit(glazed: bool = True) -> Building:
    """The side-lit room (see the module docstring)."""
    b = Building()
    shell(b, (0.0, 4.0, 0.0, 3.0, 0.0, 6.0), 0.2, 0.2, 0.2)
    b.window((0.5, 3.5, 0.9, 2.4, 6.0, 6.2), axis=2, sign=-1, glazed=glazed)
    return b


def desk(b: Building, x0: float, z0: float, width=1.6, depth=0.8, height=0.75, top=0.03,
         panel=0.03):
    """A desk: a top on two end panels standing on the floor (y = 0)."""
    b.add((x0, x0 + width, height - top, height, z0, z0 + depth), DESK)
    for px in (x0 + 0.05, x0 + width - 0.05 - panel):
        b.add((px, px + panel, 0.0, height - top, z0 + 0.05, z0 + depth - 0.05), DESK)


def deepplan() -> Building:
    """The deep-plan office floor (see the module docstring)."""
    b = Building()
    shell(b, (0.0, 20.0, 0.0, 3.0, 0.0, 12.0), 0.2, 0.2, 0.3)
    for i in range(8):
        x = 0.1 + i * 2.5
        b.window((x, x + 2.3, 0.9, 2.3, 12.0, 12.2), axis=2, sign=-1)  # south
        b.window((x, x + 2.3, 0.9, 2.3, -0.2, 0.0), axis=2, sign=1)  # north
    b.add((8.6, 11.4, 0.0, 3.0, 4.9, 7.1))  # the core, part of the fabric
    for x in (1.5, 4.0, 14.4, 16.9):
        desk(b, x, 9.6)  # south zone
        desk(b, x, 1.6)  # north zone
    for z in (8.4, 3.54):  # partitions between the desks and the core zone
        b.add((1.0, 6.0, 0.0, 1.5, z, z + 0.06), PARTITION)
        b.add((14.0, 19.0, 0.0, 1.5, z, z + 0.06), PARTITION)
    b.add((6.97, 7.03, 0.0, 1.5, 9.0, 11.0), PARTITION)  # across the south zone
    b.add((12.97, 13.03, 0.0, 1.5, 1.0, 3.0), PARTITION)  # across the north zone
    return b


def atrium() -> Building:
    """The top-lit atrium (see the module docstring)."""
    b = Building()
    shell(b, (0.0, 18.0, 0.0, 12.0, 0.0, 18.0), 0.3, 0.3, 0.3)
    void = (4.0, 14.0, 4.0, 14.0)  # x0, x1, z0, z1
    for level in (4.0, 8.0):
        b.add((0.0, 18.0, level - 0.3, level, 0.0, 18.0))  # the slab, ...
        b.cut((void[0], void[1], level - 0.3, level, void[2], void[3]))  # ... open over the atrium
        t, h = 0.15, 1.0  # parapets on the slab's edge, around the void
        x0, x1, z0, z1 = void
        b.add((x0 - t, x0, level, level + h, z0 - t, z1 + t), PARAPET)
        b.add((x1, x1 + t, level, level + h, z0 - t, z1 + t), PARAPET)
        b.add((x0, x1, level, level + h, z0 - t, z0), PARAPET)
        b.add((x0, x1, level, level + h, z1, z1 + t), PARAPET)
    b.window((void[0], void[1], 12.0, 12.3, void[2], void[3]), axis=1, sign=-1)
    return b


def build(scene: str) -> Building:
    return {"sidelit": lambda: sidelit(True), "sidelit-open": lambda: sidelit(False),
            "deepplan": deepplan, "atrium": atrium}[scene]()


# --------------------------------------------------------------------------------------------
# Files.


def write_mtl(path: Path):
    lines = [f"# {MTL_NAME}: written by scripts/radiance/daylit.py. Kd = diffuse reflectance;",
             "# glass: Tf = straight-through transmittance of the pane, Kd its diffuse reflectance."]
    for name, (kd, extra) in MATERIALS.items():
        lines += ["", f"newmtl {name}", f"Kd {kd:g} {kd:g} {kd:g}", *extra]
    path.write_text("\n".join(lines) + "\n")


def write_obj(path: Path, scene: str, faces):
    """The OBJ: shared vertices, faces grouped by material (in MATERIALS order)."""
    index, verts = {}, []
    groups = {m: [] for m in MATERIALS}
    for mat, corners in faces:
        ids = []
        for c in corners:
            if c not in index:
                index[c] = len(verts) + 1
                verts.append(c)
            ids.append(index[c])
        groups[mat].append(ids)
    out = [f"# {scene}: written by scripts/radiance/daylit.py (metres, +Y up, north -Z, "
           "south +Z)", f"mtllib {MTL_NAME}", f"o {scene}"]
    out += [f"v {x:g} {y:g} {z:g}" for x, y, z in verts]
    for mat, fs in groups.items():
        if fs:
            out.append(f"usemtl {mat}")
            out += ["f " + " ".join(map(str, ids)) for ids in fs]
    path.write_text("\n".join(out) + "\n")
    return len(verts), sum(len(f) for f in groups.values())


def closure(faces):
    """(|sum of n A| over the opaque faces, the enclosed solid volume): a closed, consistently
    oriented surface has sum n A = 0, and its volume by the divergence theorem is
    (1/3) sum (p . n) A, the normals facing out of the solid into the air."""
    total, volume = np.zeros(3), 0.0
    for mat, corners in faces:
        if mat == "glass":
            continue
        p = np.array(corners)
        na = 0.5 * np.cross(p[2] - p[0], p[3] - p[1])  # quad: n A
        total += na
        volume += p.mean(axis=0) @ na / 3.0
    return float(np.linalg.norm(total)), volume


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter,
                                 epilog=__doc__.split("\n\n", 1)[1])
    ap.add_argument("--out", type=Path, default=Path("out/daylit"), help="output folder")
    ap.add_argument("--scene", choices=SCENES, action="append",
                    help="scene to write (repeatable; default all)")
    args = ap.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    write_mtl(args.out / MTL_NAME)
    for scene in args.scene or SCENES:
        faces = faces_of(build(scene))
        nv, nf = write_obj(args.out / f"{scene}.obj", scene, faces)
        gap, volume = closure(faces)
        print(f"{args.out / (scene + '.obj')}: {nf} faces, {nv} vertices; "
              f"|sum n A| = {gap:.2g} m^2, solid volume {volume:.3f} m^3")


if __name__ == "__main__":
    main()
