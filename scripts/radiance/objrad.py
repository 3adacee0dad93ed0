"""OBJ + MTL reading as the radiosity tool reads them, and the Radiance scene written from them.

The tool's model (README "Conventions", docs/design.md §1): rho = Kd x the mean linear colour of
``map_Kd`` (8/16-bit texels decoded from sRGB), a channel of 1 or more clamped to 0.98; a
material without Kd is grey 0.5, as are faces without a material; ``Ke`` is emitted *radiance*
(W/sr/m^2), so a Lambertian emitter's radiosity is E = pi Ke. In Radiance a diffuse surface of
reflectance rho is ``plastic`` with rho, no specularity; an emitter of radiance Ke is ``light``
with Ke (Radiance's ``light`` radiance is W/sr/m^2 too). Radiance's materials are two-sided, its
lights one-sided (their backs are black), and ``light`` does not reflect: see
:func:`write_rad` for emitters that also reflect.

Glazing (issue 14): a material with transmission in its MTL passes light straight through with
transmittance T, read by the tool's rule (``src/scene/obj/mtl.rs``, ``transmittance``): ``d`` < 1
(or ``Tr`` > 0 without ``d``) gives T = (1 - d) x mean ``Tf`` (1 without ``Tf``); else a
transparency ``illum`` (4, 6, 7, 9) with ``Tf`` gives T = mean ``Tf``; else a ``Tf`` strictly
between 0 and 1 in some channel gives T = mean ``Tf``; else opaque (exporters write ``Tf 1 1 1``
with ``d 1`` on opaque materials: Sponza's and Sibenik's MTL do). The same rule per channel
gives the colour T_c (e.g. (1 - d) x ``Tf``_c): grey glazing (equal channels) has T in every
channel, at most 1 - max rho; tinted glazing (channels that differ) keeps its colour, each
channel at most 1 - rho_c (docs/design.md §9, "Tinted glazing"). Its ``Kd`` (rho) stays the
pane's diffuse reflectance. In Radiance a grey pane is ``trans`` with no specular reflection
(spec 0) and all its transmission specular (tspec 1): its diffuse reflectance is c (1 - t) and
its straight-through transmittance c t, so c = rho + T and t = T / (rho + T) match the pane
exactly (see :func:`trans_parameters`). ``glass`` would not do: it adds Fresnel reflection and
its parameter is a transmissivity, not a transmittance. Radiance's shadow rays (the sun) and
ambient rays go through ``trans`` straight on with factor c t (``scripts/radiance/README.md``,
"Daylight", has the check). ``trans`` has one t for the three channels, so a pane whose
T_c / (rho_c + T_c) differs by channel (tinted glass) is written as ``BRTDfunc`` instead:
specular transmission T_c per channel, diffuse reflectance rho_c on both sides, nothing else
(:func:`brtd_pane`); Radiance's ``m_brdf`` casts its transmitted ray for shadow and ambient
rays too, with the coefficient T_c.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from PIL import Image

MAX_REFLECTANCE = 0.98
DEFAULT_GREY = 0.5


@dataclass
class Material:
    name: str
    rho: tuple = (DEFAULT_GREY,) * 3
    ke: tuple = (0.0, 0.0, 0.0)
    rho_source: str = "default"
    # Straight-through transmittance T per channel (0: opaque), and the MTL values it came from.
    transmittance: tuple = (0.0, 0.0, 0.0)
    tf: tuple | None = None
    d: float | None = None
    tr: float | None = None
    illum: int | None = None

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


def map_file(value: str) -> str:
    """The file name after a ``map_Kd`` statement's options (as the tool skips them)."""
    words = value.split()
    one_word = {"-blendu", "-blendv", "-cc", "-clamp", "-imfchan", "-type", "-colorspace"}
    numbers = {"-bm": 1, "-boost": 1, "-texres": 1, "-mm": 2}

    def is_num(w):
        try:
            float(w)
            return True
        except ValueError:
            return False

    i = 0
    while i < len(words) and words[i].startswith("-") and not is_num(words[i]):
        opt = words[i]
        i += 1
        if opt in one_word:
            i += 1
            continue
        for _ in range(numbers.get(opt, 3)):
            if i < len(words) and is_num(words[i]):
                i += 1
            else:
                break
    return " ".join(words[i:])


def srgb_to_linear(v):
    v = np.asarray(v, dtype=np.float64)
    return np.where(v <= 0.04045, v / 12.92, ((v + 0.055) / 1.055) ** 2.4)


def texture_mean(path: Path):
    """The mean colour of an image in linear light (integer texels read as sRGB, float linear),
    or None when it does not load."""
    try:
        img = Image.open(path)
        img.load()
    except Exception:
        return None
    if img.mode in ("I;16", "I;16B", "I;16L", "I"):
        a = np.asarray(img, dtype=np.float64) / 65535.0
        lin = srgb_to_linear(a)
        return (float(lin.mean()),) * 3
    if img.mode == "F":
        m = float(np.asarray(img, dtype=np.float64).mean())
        return (m, m, m)
    a = np.asarray(img.convert("RGB"), dtype=np.float64) / 255.0
    lin = srgb_to_linear(a).reshape(-1, 3).mean(axis=0)
    return tuple(float(x) for x in lin)


def find_file(folder: Path, name: str) -> Path:
    """A file named in an MTL: as written, with ``\\`` read as ``/``, or in another letter case."""
    for cand in (folder / name, folder / name.replace("\\", "/")):
        if cand.is_file():
            return cand
    cand = folder / name.replace("\\", "/")
    if cand.parent.is_dir():
        for p in cand.parent.iterdir():
            if p.is_file() and p.name.lower() == cand.name.lower():
                return p
    return folder / name


TF_RULES = ("tool",)


def numbers(rest: str) -> list:
    """The words of a statement that read as numbers (options such as ``-halo`` or ``xyz``
    skipped)."""
    out = []
    for w in rest.split():
        try:
            out.append(float(w))
        except ValueError:
            continue
    return out


def transmittance(m: Material, tf_rule: str, warnings: list) -> tuple:
    """T per channel from the material's Tf / d / Tr / illum, the tool's rule (see the module
    docstring): grey (T, T, T) when Tf's channels are equal, else Tf's colour T_c;
    ``tf_rule`` is kept for the command line and must be "tool"."""
    mean = (lambda c: sum(c) / 3.0)
    opacity = m.d if m.d is not None else (1.0 - m.tr if m.tr is not None else None)
    colour, scale = None, 1.0
    if opacity is not None and opacity < 1.0:
        t = (1.0 - opacity) * (mean(m.tf) if m.tf is not None else 1.0)
        colour, scale = m.tf, 1.0 - opacity
    elif m.tf is not None and m.illum in (4, 6, 7, 9):
        t = mean(m.tf)
        colour = m.tf
    elif m.tf is not None and any(0.0 < x < 1.0 for x in m.tf):
        t = mean(m.tf)
        colour = m.tf
    else:
        t = 0.0
    if t > 0.0 and colour is not None and len(set(colour)) > 1:
        # Tinted: each channel at most 1 - rho_c (the tool's `glazing` in mtl.rs).
        tc = tuple(scale * x for x in colour)
        kept = tuple(min(x, max(0.0, 1.0 - r)) for x, r in zip(tc, m.rho))
        if kept != tc:
            warnings.append(f"material {m.name!r}: transmittance {tc} cut to {kept} "
                            "(rho_c + T_c <= 1)")
        return kept
    room = max(0.0, 1.0 - max(m.rho))
    if t > room:
        warnings.append(f"material {m.name!r}: transmittance {t:g} cut to {room:g} (rho + T <= 1)")
        t = room
    return (t, t, t)


def trans_parameters(rho, t):
    """Radiance ``trans`` (colour c, transmissivity t_R, with spec 0 and tspec 1) for a pane of
    diffuse reflectance ``rho`` and straight-through transmittance ``t`` per channel:
    c = rho + T, t_R = T / (rho + T). t_R is one number: the luminance-weighted one when the
    channels differ (then the match is not exact). Returns (c, t_R, exact)."""
    c = tuple(r + x for r, x in zip(rho, t))
    ratios = [x / ci if ci > 0 else 0.0 for x, ci in zip(t, c)]
    w = (0.2126, 0.7152, 0.0722)
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


def read_mtl(path: Path, warnings: list, tf_rule: str = "tool") -> dict:
    """Materials by name from one MTL file."""
    mats, cur, tex = {}, None, {}
    kd_seen = {}
    for line in logical_lines(path.read_text(errors="replace")):
        word, _, rest = line.partition(" ")
        rest = rest.strip()
        if word == "newmtl":
            cur = Material(rest)
            mats[rest] = cur
        elif cur is None:
            continue
        elif word == "Kd":
            cur.rho = tuple(float(x) for x in rest.split()[:3])
            cur.rho_source = "Kd"
            kd_seen[cur.name] = True
        elif word == "Ke":
            cur.ke = tuple(float(x) for x in rest.split()[:3])
        elif word == "Tf":
            vals = numbers(rest)[:3]
            if vals:
                cur.tf = tuple((vals * 3)[:3]) if len(vals) < 3 else tuple(vals)
        elif word == "d":
            vals = numbers(rest)
            if vals:
                cur.d = vals[0]
        elif word == "illum":
            vals = numbers(rest)
            if vals:
                cur.illum = int(vals[0])
        elif word == "Tr":
            vals = numbers(rest)
            if vals:
                cur.tr = vals[0]
        elif word == "map_Kd":
            tex[cur.name] = map_file(rest)
    for name, file in tex.items():
        m = mats[name]
        mean = texture_mean(find_file(path.parent, file)) if file else None
        if mean is None:
            warnings.append(f"texture {file!r} of {name!r} not loaded: Kd alone")
            continue
        kd = m.rho if kd_seen.get(name) else (1.0, 1.0, 1.0)
        m.rho = tuple(k * t for k, t in zip(kd, mean))
        m.rho_source = f"Kd x mean({file})"
    for m in mats.values():
        if any(r >= 1.0 for r in m.rho):
            m.rho = tuple(MAX_REFLECTANCE if r >= 1.0 else r for r in m.rho)
            m.rho_source += " clamped"
        m.transmittance = transmittance(m, tf_rule, warnings)
    return mats


def read_obj(path: Path, emit: dict | None = None, tf_rule: str = "tool") -> Model:
    """An OBJ file with its MTL libraries; ``emit`` maps material names to Ke (the tool's
    ``--emit``); ``tf_rule``: the tool's glazing rule (:data:`TF_RULES`)."""
    path = Path(path)
    warnings: list = []
    verts, faces, face_mat = [], [], []
    lib: dict = {}
    index: dict = {}
    materials: list = []
    current = None

    def material_index(name):
        if name not in index:
            m = lib.get(name)
            if m is None:
                warnings.append(f"material {name!r} not defined: grey")
                m = Material(name)
            index[name] = len(materials)
            materials.append(m)
        return index[name]

    raw_faces = []
    for line in logical_lines(path.read_text(errors="replace")):
        word, _, rest = line.partition(" ")
        if word == "v":
            verts.append([float(x) for x in rest.split()[:3]])
        elif word == "f":
            raw_faces.append(([int(t.split("/")[0]) for t in rest.split()], current))
        elif word == "usemtl":
            current = rest.strip()
        elif word == "mtllib":
            name = rest.strip()
            cands = [name] if (path.parent / name).exists() else name.split()
            for n in cands:
                p = path.parent / n
                if p.is_file():
                    lib.update(read_mtl(p, warnings, tf_rule))
                else:
                    warnings.append(f"material library {n!r} missing")
    nv = len(verts)
    for idx, mat in raw_faces:
        ids = [i - 1 if i > 0 else nv + i for i in idx]
        faces.append(ids)
        face_mat.append(material_index(mat if mat is not None else "default"))
    for name, ke in (emit or {}).items():
        if name in index:
            materials[index[name]].ke = tuple(ke)
        else:
            warnings.append(f"--emit {name}: no faces use it")
    return Model(np.array(verts, dtype=np.float64).reshape(-1, 3), faces, face_mat, materials,
                 warnings)


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
    H / pi, found by :func:`check.light_iteration`)."""
    out = ["# written by scripts/radiance/objrad.py from the OBJ/MTL"]
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
    for i, (face, mat) in enumerate(zip(model.faces, model.face_material)):
        p = model.vertices[face]
        modifier = f"m{mat}"
        if i in light_radiance:
            r = light_radiance[i]
            out.append(f"void light lf{i}\n0\n0\n3 {r[0]:.9g} {r[1]:.9g} {r[2]:.9g}")
            modifier = f"lf{i}"
        for j, piece in enumerate(planar_pieces(p)):
            coords = " ".join(f"{c:.9g}" for c in piece.reshape(-1))
            out.append(f"{modifier} polygon f{i}_{j}\n0\n0\n{3 * len(piece)} {coords}")
    Path(path).write_text("\n".join(out) + "\n")


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
