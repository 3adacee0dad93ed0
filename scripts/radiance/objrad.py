"""An OBJ with the tool's materials, and the Radiance scene written from them.

The geometry (vertices, faces, ``usemtl``) is read here; the materials are not: they come from
``radiosity info --json`` (:func:`common.tool_info`), which reports each material exactly as
the tool's loader made it, so there is one reader of the MTL (``src/scene/obj/mtl.rs``) and
nothing here to drift from it. Per material the JSON gives ``rho`` (RGB, after the clamp to
0.98), ``rho_source`` (``Kd``, ``Kd`` x a texture's mean colour, clamped, the default grey),
``ke`` (emitted radiance, W/sr/m^2, after ``--emit``), ``emission`` (E = pi Ke, W/m^2) and
``transmittance_rgb`` (the glazing's straight-through transmittance per channel, after the cut
to rho_c + T_c <= 1; 0 when opaque). Faces with no (known) material take the tool's default
grey (named ``default``, or ``default-grey`` when the library has a ``default``).

In Radiance a diffuse surface of reflectance rho is ``plastic`` with rho, no specularity; an
emitter of radiance Ke is ``light`` with Ke (Radiance's ``light`` radiance is W/sr/m^2 too).
Radiance's materials are two-sided, its lights one-sided (their backs are black), and
``light`` does not reflect: see :func:`write_rad` for emitters that also reflect.

Glazing: a grey pane (rho, T) is ``trans`` with no specular reflection (spec 0) and all its
transmission specular (tspec 1): its diffuse reflectance is c (1 - t) and its straight-through
transmittance c t, so c = rho + T and t = T / (rho + T) match the pane exactly (see
:func:`trans_parameters`). ``glass`` would not do: it adds Fresnel reflection and its
parameter is a transmissivity, not a transmittance. Radiance's shadow rays (the sun) and
ambient rays go through ``trans`` straight on with factor c t (``scripts/radiance/README.md``,
"Daylight", has the check). ``trans`` has one t for the three channels, so a pane whose
T_c / (rho_c + T_c) differs by channel (tinted glass, docs/design.md §9) is written as
``BRTDfunc`` instead: specular transmission T_c per channel, diffuse reflectance rho_c on both
sides, nothing else (:func:`brtd_pane`); Radiance's ``m_brdf`` casts its transmitted ray for
shadow and ambient rays too, with the coefficient T_c.
"""

from __future__ import annotations

import math
import re
import sys
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import common  # noqa: E402

DEFAULT_GREY = 0.5
DEFAULT_NAMES = ("default-grey", "default")  # the tool's grey for faces without a material


@dataclass
class Material:
    """One material as ``radiosity info --json`` reports it."""

    name: str
    rho: tuple = (DEFAULT_GREY,) * 3
    ke: tuple = (0.0, 0.0, 0.0)
    rho_source: str = "default"
    # Straight-through transmittance T per channel (0: opaque).
    transmittance: tuple = (0.0, 0.0, 0.0)

    @property
    def emits(self) -> bool:
        return any(k > 0 for k in self.ke)

    @property
    def transmits(self) -> bool:
        return any(t > 0 for t in self.transmittance)


@dataclass
class Model:
    """Polygons (vertex arrays, counter-clockwise around the front) with material indices."""

    vertices: np.ndarray
    faces: list  # lists of vertex indices (0-based)
    face_material: list
    materials: list = field(default_factory=list)
    warnings: list = field(default_factory=list)


def logical_lines(text: str):
    """Lines with a trailing backslash joined to the next, and ``#`` comments (a ``#`` that
    begins a word) removed."""
    buf = ""
    for raw in text.splitlines():
        if raw.endswith("\\"):
            buf += raw[:-1] + " "
            continue
        line = buf + raw
        buf = ""
        line = re.sub(r"(^|\s)#.*$", "", line).strip()
        if line:
            yield line
    if buf.strip():
        yield re.sub(r"(^|\s)#.*$", "", buf).strip()


def source_text(src: dict) -> str:
    """The tool's ``rho_source`` object in a few words (for the comments of the scene)."""
    kind = src.get("kind", "?")
    if kind == "kd_times_texture":
        return f"Kd x mean({src.get('file')})"
    if kind == "texture_not_loaded":
        return f"{source_text(src.get('fallback', {}))} ({src.get('file')} not loaded)"
    if kind == "clamped":
        return f"{source_text(src.get('from', {}))}, clamped"
    return {"kd": "Kd"}.get(kind, kind)


def materials_from_info(info: dict) -> dict:
    """Materials by name from ``radiosity info --json``."""
    out = {}
    for m in info["materials"]:
        t = m.get("transmittance_rgb") or [m.get("transmittance", 0.0)] * 3
        out[m["name"]] = Material(m["name"], tuple(m["rho"]), tuple(m["ke"]),
                                  source_text(m.get("rho_source", {})), tuple(t))
    return out


def read_obj(path: Path, binary: Path | None = None, emit: dict | None = None) -> Model:
    """An OBJ file's polygons, with the materials the tool loads for it (``radiosity info
    --json``, :func:`common.tool_info`); ``emit`` maps material names to Ke (the tool's
    ``--emit``), passed to the tool; ``binary`` defaults to :func:`common.radiosity_binary`."""
    path = Path(path)
    binary = binary or common.radiosity_binary(None, must_exist=True)
    info = common.tool_info(binary, path, emit)
    lib = materials_from_info(info)
    warnings: list = list(info.get("warnings", []))
    verts, faces, face_mat = [], [], []
    index: dict = {}
    materials: list = []
    current = None

    fallback = next((lib[n] for n in DEFAULT_NAMES if n in lib), None) or Material("default")

    def material_index(name):
        m = lib.get(name) if name is not None else None
        m = m or fallback
        if m.name not in index:
            index[m.name] = len(materials)
            materials.append(m)
        return index[m.name]

    raw_faces = []
    for line in logical_lines(path.read_text(errors="replace")):
        word, _, rest = line.partition(" ")
        if word == "v":
            verts.append([float(x) for x in rest.split()[:3]])
        elif word == "f":
            raw_faces.append(([int(t.split("/")[0]) for t in rest.split()], current))
        elif word == "usemtl":
            current = rest.strip()
    nv = len(verts)
    for idx, mat in raw_faces:
        ids = [i - 1 if i > 0 else nv + i for i in idx]
        faces.append(ids)
        face_mat.append(material_index(mat))
    return Model(np.array(verts, dtype=np.float64).reshape(-1, 3), faces, face_mat, materials,
                 warnings)


def trans_parameters(rho, t):
    """Radiance ``trans`` (colour c, transmissivity t_R, with spec 0 and tspec 1) for a pane of
    diffuse reflectance ``rho`` and straight-through transmittance ``t`` per channel:
    c = rho + T, t_R = T / (rho + T). t_R is one number: the luminance-weighted one when the
    channels differ (then the match is not exact). Returns (c, t_R, exact)."""
    c = tuple(r + x for r, x in zip(rho, t))
    ratios = [x / ci if ci > 0 else 0.0 for x, ci in zip(t, c)]
    w = tuple(common.LUMA)
    num = sum(wi * x for wi, x in zip(w, t))
    den = sum(wi * ci for wi, ci in zip(w, c))
    t_r = num / den if den > 0 else 0.0
    exact = max(ratios) - min(ratios) < 1e-9
    return c, t_r, exact


def brtd_pane(rho, t) -> str:
    """The real and string arguments of a Radiance ``BRTDfunc`` pane of diffuse reflectance
    ``rho`` (both sides) and straight-through (specular) transmittance ``t`` per channel, with
    no specular reflection, directional-diffuse part or diffuse transmission: exact per
    channel, where ``trans`` cannot be (its t is one number)."""
    return ("10 0 0 0 " + " ".join(f"{x:.9g}" for x in t) + " 0 0 0 .\n0\n"
            + "9 " + " ".join(f"{x:.9g}" for x in tuple(rho) * 2) + " 0 0 0")


def polygon_normal(p: np.ndarray) -> np.ndarray:
    """Newell's normal (length = 2 x area)."""
    q = np.roll(p, -1, axis=0)
    return np.array([np.sum((p[:, 1] - q[:, 1]) * (p[:, 2] + q[:, 2])),
                     np.sum((p[:, 2] - q[:, 2]) * (p[:, 0] + q[:, 0])),
                     np.sum((p[:, 0] - q[:, 0]) * (p[:, 1] + q[:, 1]))])


def planar_pieces(p: np.ndarray):
    """The polygon itself if planar (within 1e-5 of its size), else its fan triangles."""
    if len(p) == 3:
        return [p]
    n = polygon_normal(p)
    ln = np.linalg.norm(n)
    if ln == 0:
        return []
    n = n / ln
    size = np.ptp(p, axis=0).max()
    if np.abs((p - p.mean(axis=0)) @ n).max() <= 1e-5 * max(size, 1e-9):
        return [p]
    return [np.array([p[0], p[i], p[i + 1]]) for i in range(1, len(p) - 1)]


def emitter_faces(model: Model):
    """Indices of faces whose material emits."""
    return [i for i, m in enumerate(model.face_material) if model.materials[m].emits]


def write_rad(model: Model, path: Path, light_radiance: dict | None = None):
    """The Radiance scene: one ``plastic`` per non-emitting material (rho, no specularity), a
    ``light`` per emitting material (radiance Ke), or per emitting face when
    ``light_radiance[face]`` gives that face's radiance (emitters that also reflect: Ke + rho
    H / pi, found by :func:`check.light_iteration`). Emitting faces are written as the
    parallelograms Radiance's direct light samples exactly (:func:`light_sources`). Returns
    what was done to them (counts)."""
    out = ["# written by scripts/radiance/objrad.py: the OBJ's faces, the tool's materials"]
    for k, m in enumerate(model.materials):
        if m.emits:
            out.append(f"# {m.name}: Ke {m.ke} (W/sr/m^2), rho {m.rho} (not reflected by light)")
            out.append(f"void light m{k}\n0\n0\n3 {m.ke[0]:.9g} {m.ke[1]:.9g} {m.ke[2]:.9g}")
        elif m.transmits:
            c, t_r, exact = trans_parameters(m.rho, m.transmittance)
            if exact:
                out.append(f"# {m.name}: rho {m.rho}, straight-through T {m.transmittance}: "
                           "trans c = rho + T, t = T / (rho + T), spec 0, tspec 1")
                out.append(f"void trans m{k}\n0\n0\n7 {c[0]:.9g} {c[1]:.9g} {c[2]:.9g} 0 0 "
                           f"{t_r:.9g} 1")
            else:
                # Tinted (or T / (rho + T) differs by channel): trans's one t cannot match.
                out.append(f"# {m.name}: rho {m.rho}, straight-through T {m.transmittance}: "
                           "BRTDfunc, specular transmission T_c, diffuse reflectance rho_c")
                out.append(f"void BRTDfunc m{k}\n{brtd_pane(m.rho, m.transmittance)}")
        else:
            out.append(f"# {m.name}: rho {m.rho} ({m.rho_source})")
            out.append(f"void plastic m{k}\n0\n0\n5 {m.rho[0]:.9g} {m.rho[1]:.9g} "
                       f"{m.rho[2]:.9g} 0 0")
    light_radiance = light_radiance or {}
    emitting = {}  # modifier -> [(face, piece)]
    for i, (face, mat) in enumerate(zip(model.faces, model.face_material)):
        p = model.vertices[face]
        modifier = f"m{mat}"
        if i in light_radiance:
            r = light_radiance[i]
            out.append(f"void light lf{i}\n0\n0\n3 {r[0]:.9g} {r[1]:.9g} {r[2]:.9g}")
            modifier = f"lf{i}"
        if model.materials[mat].emits:
            emitting.setdefault(modifier, []).extend((i, q) for q in planar_pieces(p))
            continue
        for j, piece in enumerate(planar_pieces(p)):
            coords = " ".join(f"{c:.9g}" for c in piece.reshape(-1))
            out.append(f"{modifier} polygon f{i}_{j}\n0\n0\n{3 * len(piece)} {coords}")
    stats = {"emitter_pieces": 0, "merged_pairs": 0, "repeats_dropped": 0, "subdivided": 0,
             "sources": 0}
    for modifier, pieces in emitting.items():
        stats["emitter_pieces"] += len(pieces)
        for k, (i, piece) in enumerate(light_sources(pieces, stats)):
            coords = " ".join(f"{c:.9g}" for c in piece.reshape(-1))
            out.append(f"{modifier} polygon f{i}_s{k}\n0\n0\n{3 * len(piece)} {coords}")
            stats["sources"] += 1
    Path(path).write_text("\n".join(out) + "\n")
    return stats


# Radiance's direct light from a flat source samples it as a parallelogram (its parts, -ds,
# cover the source's own rectangle): a source of another shape — a triangle, a trapezoid — is
# off by 0.4-1.5x at receivers closer than a few times its size (scripts/radiance/README.md,
# "Emitters Radiance can sample"). So emitting faces are written as parallelograms: triangle
# pairs that make one (exporters' fan-triangulated rectangles) merged back, exact repeats
# (doubled faces) dropped as the tool drops them, and any other shape cut into parallelograms
# and triangles no longer than SOURCE_PIECE.
SOURCE_PIECE = 0.01  # metres: the largest triangle left in a subdivided emitter
SOURCE_DEPTH = 8  # at most 2^8 - 1 parallelograms and 2^8 triangles per triangle


def is_parallelogram(p: np.ndarray) -> bool:
    if len(p) != 4:
        return False
    size = np.ptp(p, axis=0).max()
    return bool(np.abs(p[0] + p[2] - p[1] - p[3]).max() <= 1e-6 * max(size, 1e-9))


def light_sources(pieces, stats):
    """The (face, polygon) list of one light's emitting pieces, as parallelograms Radiance
    samples exactly (see SOURCE_PIECE)."""
    key = lambda v: tuple(np.round(v, 7))  # noqa: E731
    tris = [(i, p) for i, p in pieces if len(p) == 3]
    rest = [(i, p) for i, p in pieces if len(p) != 3]
    # Merge triangles sharing an edge (in opposite directions) into parallelograms.
    by_edge = {}
    for t, (_, p) in enumerate(tris):
        for e in range(3):
            by_edge.setdefault((key(p[e]), key(p[(e + 1) % 3])), []).append((t, e))
    used = [False] * len(tris)
    merged = []
    for t, (i, p) in enumerate(tris):
        if used[t]:
            continue
        n = polygon_normal(p)
        for e in range(3):
            a, b, c = p[(e + 2) % 3], p[e], p[(e + 1) % 3]  # edge b -> c, a opposite
            for u, f in by_edge.get((key(c), key(b)), []):
                if used[u] or u == t:
                    continue
                q = tris[u][1]
                d = q[(f + 2) % 3]
                m = polygon_normal(q)
                quad = np.array([a, b, d, c])
                if np.dot(n, m) > 0.999999 * np.linalg.norm(n) * np.linalg.norm(m) and \
                        is_parallelogram(quad):
                    used[t] = used[u] = True
                    merged.append((i, quad))
                    stats["merged_pairs"] += 1
                    break
            if used[t]:
                break
        if not used[t]:
            merged.append((i, p))
    # Drop exact repeats (the same polygon facing the same way).
    seen, unique = set(), []
    for i, p in merged + rest:
        k = (frozenset(key(v) for v in p), tuple(np.sign(np.round(polygon_normal(p), 9))))
        if k in seen:
            stats["repeats_dropped"] += 1
            continue
        seen.add(k)
        unique.append((i, p))
    out = []
    for i, p in unique:
        if len(p) == 4 and is_parallelogram(p):
            out.append((i, p))
            continue
        stats["subdivided"] += 1
        for r in range(1, len(p) - 1):
            out.extend((i, q) for q in parallelogram_pieces(np.array([p[0], p[r], p[r + 1]])))
    return out


def parallelogram_pieces(t: np.ndarray):
    """Triangle ``t`` (a, b, c) as parallelograms and small triangles, all wound as ``t``: the
    parallelogram (mid ab, b, mid bc, mid ca) and the triangles (a, mid ab, mid ca) and
    (mid ca, mid bc, c), the triangles cut again until none is longer than SOURCE_PIECE."""
    size = max(np.linalg.norm(t[k] - t[(k + 1) % 3]) for k in range(3))
    depth = min(SOURCE_DEPTH, max(0, math.ceil(math.log2(max(size / SOURCE_PIECE, 1.0)))))
    todo, out = [(t, depth)], []
    while todo:
        (a, b, c), d = todo.pop()
        if d == 0:
            out.append(np.array([a, b, c]))
            continue
        ab, bc, ca = (a + b) / 2, (b + c) / 2, (c + a) / 2
        out.append(np.array([ab, b, bc, ca]))
        todo.append((np.array([a, ab, ca]), d - 1))
        todo.append((np.array([ca, bc, c]), d - 1))
    return out


def face_points(p: np.ndarray, k: int, rng: np.random.Generator, shrink=0.98):
    """``k`` stratified points on polygon ``p`` (fan triangles chosen by area), pulled towards
    its centroid by ``shrink`` so no point lies on an edge."""
    tris = [(p[0], p[i], p[i + 1]) for i in range(1, len(p) - 1)]
    areas = np.array([np.linalg.norm(np.cross(b - a, c - a)) / 2 for a, b, c in tris])
    if areas.sum() <= 0:
        return np.repeat(p.mean(axis=0)[None], k, axis=0)
    cdf = np.cumsum(areas) / areas.sum()
    centre = (areas[:, None] * np.array([(a + b + c) / 3 for a, b, c in tris])).sum(0) / areas.sum()
    s = (np.arange(k) + rng.random(k)) / k  # stratified in the area CDF
    t = (rng.permutation(k) + rng.random(k)) / k  # Latin-hypercube second coordinate
    pts = []
    for si, ti in zip(s, t):
        j = min(int(np.searchsorted(cdf, si)), len(tris) - 1)
        lo = cdf[j - 1] if j > 0 else 0.0
        u = (si - lo) / max(cdf[j] - lo, 1e-300)
        a, b, c = tris[j]
        su = math.sqrt(min(max(u, 0.0), 1.0))
        q = (1 - su) * a + su * (1 - ti) * b + su * ti * c
        pts.append(centre + shrink * (q - centre))
    return np.array(pts)
