#!/usr/bin/env python3
"""Check a radiosity solve against Radiance on the same model, patch by patch.

1. ``radiosity solve MODEL --out DIR/solve --save DIR/solve/solution.rad --elements off
   [--solve-args]``, then ``radiosity export`` to a PLY (one face per patch, in patch order: the
   export draws the elements when there are any) for the patch polygons;
   the tool's irradiance per patch is (B - E) / rho from ``patches.csv``.
2. The same OBJ/MTL written as a Radiance scene (``objrad.py``: ``plastic`` with the tool's rho,
   ``light`` with radiance Ke), ``oconv``, and ``rtrace -I`` at stratified points inside each
   sampled patch, looking along its normal (Radiance's irradiance, W/m^2, averaged over the
   points). Emitters that also reflect (rho > 0, as in the project's scenes) get the radiance
   Ke + rho H / pi, H their irradiance found by Radiance itself in a few passes.
3. Compared on luminance-weighted irradiance Y = 0.2126 R + 0.7152 G + 0.0722 B.

Patches are sampled at random (seeded), stratified by area so small parts are represented; each
carries the weight (patches in its stratum / sampled in it), so the figures estimate the whole
scene's. Emitters and patches with a channel of rho = 0 (no irradiance from B) are left out.

    .venv-radiance/bin/python scripts/radiance/check.py scenes/office.obj --out out/check/office
    .venv-radiance/bin/python scripts/radiance/check.py MODEL.obj --solve-args=--two-sided

Writes DIR/report.json (settings, figures, every sampled patch) and prints a short table. Exit
code 1 only when something fails to run (the figures never make it fail).
"""

from __future__ import annotations

import argparse
import json
import os
import shlex
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import objrad  # noqa: E402
from common import (BINARY_HELP, LUMA, ROOT, children_cpu, oconv, parse_emit,  # noqa: E402
                    radiance_env, radiosity_binary, ray_lines, read_patches, rtrace_rgb, run)

STRATA = 8


# --------------------------------------------------------------------------------------------
# The tool's side.


def solve(binary: Path, model: Path, out: Path, solve_args: list[str]):
    """Solve and export; returns (patches table, patch polygons, summary, wall seconds)."""
    sdir = out / "solve"
    sdir.mkdir(parents=True, exist_ok=True)
    sol = sdir / "solution.rad"
    # The patch polygons come from the export, which draws the adaptive elements when the
    # solution has them: without elements it is one face per patch (patches.csv is the same
    # either way; the elements never feed back into the patches).
    no_elements = [] if any(a.startswith("--elements") for a in solve_args) else ["--elements", "off"]
    t0 = time.perf_counter()
    run([binary, "solve", model, "--out", sdir, "--save", sol, "--quiet", *no_elements, *solve_args])
    wall = time.perf_counter() - t0
    run([binary, "export", sol, "--out", sdir / "patches.ply", "--quiet"])
    table = read_patches(sdir / "patches.csv")
    polys = read_ply_faces(sdir / "patches.ply")
    if len(polys) != len(table):
        sys.exit(f"PLY has {len(polys)} faces, patches.csv {len(table)} rows (solve with "
                 "--elements off: the export then draws the patches)")
    summary = json.loads((sdir / "summary.json").read_text())
    return table, polys, summary, wall


def read_ply_faces(path: Path):
    """The faces of a binary little-endian PLY as vertex arrays."""
    data = path.read_bytes()
    end = data.index(b"end_header\n") + len(b"end_header\n")
    header = data[:end].decode().splitlines()
    sizes = {"float": "f4", "double": "f8", "uchar": "u1", "uint": "u4", "int": "i4",
             "char": "i1", "ushort": "u2", "short": "i2"}
    elements, cur = [], None
    for line in header:
        w = line.split()
        if w[0] == "element":
            cur = [w[1], int(w[2]), []]
            elements.append(cur)
        elif w[0] == "property":
            cur[2].append(w[1:])
    pos = end
    verts = None
    faces = []
    for name, count, props in elements:
        if name == "vertex":
            dt = np.dtype([(p[1], "<" + sizes[p[0]]) for p in props])
            arr = np.frombuffer(data, dtype=dt, count=count, offset=pos)
            pos += dt.itemsize * count
            verts = np.stack([arr["x"], arr["y"], arr["z"]], axis=1).astype(np.float64)
        elif name == "face":
            (_, cnt_t, idx_t, _), = props
            cs, isz = np.dtype(sizes[cnt_t]).itemsize, np.dtype(sizes[idx_t])
            for _ in range(count):
                n = int(np.frombuffer(data, dtype=sizes[cnt_t], count=1, offset=pos)[0])
                pos += cs
                idx = np.frombuffer(data, dtype="<" + sizes[idx_t], count=n, offset=pos)
                pos += isz.itemsize * n
                faces.append(verts[idx])
    return faces


def tool_irradiance(table):
    """Irradiance per patch and channel, (B - E) / rho (NaN where rho = 0)."""
    b = np.stack([table["b_r"], table["b_g"], table["b_b"]], axis=1)
    e = np.stack([table["e_r"], table["e_g"], table["e_b"]], axis=1)
    rho = np.stack([table["rho_r"], table["rho_g"], table["rho_b"]], axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        h = np.where(rho > 0, (b - e) / rho, np.nan)
    return h, b, e, rho


def same_patches(a, b) -> bool:
    """Whether two patches.csv tables hold the same patches (count and centres)."""
    return len(a) == len(b) and np.allclose([a[c] for c in ("cx", "cy", "cz")],
                                            [b[c] for c in ("cx", "cy", "cz")])


def sample_patches(table, n: int, seed: int):
    """Patch ids sampled in STRATA area strata (equal patch counts), with their weights."""
    e = np.stack([table["e_r"], table["e_g"], table["e_b"]], axis=1)
    rho = np.stack([table["rho_r"], table["rho_g"], table["rho_b"]], axis=1)
    eligible = np.flatnonzero((e.max(axis=1) == 0) & (rho.min(axis=1) > 0))
    rng = np.random.default_rng(seed)
    if n >= len(eligible):
        return eligible, np.ones(len(eligible))
    order = eligible[np.argsort(table["area"][eligible], kind="stable")]
    ids, weights = [], []
    for k, stratum in enumerate(np.array_split(order, STRATA)):
        take = n // STRATA + (1 if k < n % STRATA else 0)
        take = min(take, len(stratum))
        ids.extend(rng.choice(stratum, size=take, replace=False))
        weights.extend([len(stratum) / take] * take)
    ids, weights = np.array(ids), np.array(weights)
    o = np.argsort(ids)
    return ids[o], weights[o]


# --------------------------------------------------------------------------------------------
# Radiance's side.


class Radiance:
    """rtrace -I on one octree with fixed settings."""

    def __init__(self, args, workdir: Path):
        self.bin, self.env = radiance_env()
        self.workdir = workdir
        self.opts = ["-h", "-I+", "-n", str(args.procs), "-ab", str(args.ab), "-ad",
                     str(args.ad), "-as", str(args.as_), "-aa", str(args.aa), "-lr",
                     str(args.lr), "-lw", str(args.lw), "-dt", "0", "-dc", "1", "-ds", "0.02",
                     "-dj", "0", "-dr", "0", "-u+"]
        self.seconds = 0.0
        self.cpu_seconds = 0.0
        self.rays = 0
        self.sources = {}
        # Scene files added to every octree (the luminaires of --luminaires).
        self.extra = []

    def octree(self, model, name, light_radiance=None):
        rad = self.workdir / f"{name}.rad"
        self.sources = objrad.write_rad(model, rad, light_radiance)
        return oconv(self.bin, self.env, [rad, *self.extra], self.workdir / f"{name}.oct")

    def add_luminaires(self, binary: Path, model: Path, solve_args: list[str]):
        """The luminaires a solve's ``--luminaires SCHEDULE`` places, as Radiance sources in
        every octree (``luminaires.luminaire_rad``: ies2rad, turned into the tool's frame)."""
        if "--luminaires" not in solve_args:
            return
        schedule = solve_args[solve_args.index("--luminaires") + 1]
        from luminaires import luminaire_rad
        info = json.loads(run([binary, "info", "--json", model, "--luminaires",
                               schedule]).stdout)
        text = "".join(luminaire_rad(self.bin, self.env, lum, k, self.workdir)
                       for k, lum in enumerate(info["luminaires"]))
        path = self.workdir / "luminaires.rad"
        path.write_text(text)
        self.extra = [path]

    def irradiance(self, octree: Path, origins: np.ndarray, dirs: np.ndarray) -> np.ndarray:
        """RGB irradiance at each origin on a surface facing dirs."""
        t0, c0 = time.perf_counter(), children_cpu()
        res = subprocess.run([self.bin / "rtrace", *self.opts, octree],
                             input=ray_lines(origins, dirs), capture_output=True, text=True,
                             env=self.env)
        self.seconds += time.perf_counter() - t0
        self.cpu_seconds += children_cpu() - c0
        if res.returncode != 0:
            sys.exit(f"rtrace failed: {res.stderr}")
        return rtrace_rgb(res.stdout, len(origins))


def points_for(polys, ids, k, seed):
    """k stratified points per patch (rows grouped by patch) and the patch normals."""
    rng = np.random.default_rng(seed)
    pts, normals = [], []
    for i in ids:
        p = polys[i]
        n = objrad.polygon_normal(p)
        n = n / np.linalg.norm(n)
        pts.append(objrad.face_points(p, k, rng))
        normals.append(np.repeat(n[None], k, axis=0))
    return np.concatenate(pts), np.concatenate(normals)


def light_iteration(model, radiance: Radiance, passes: int, k: int, seed: int):
    """Radiance per emitting face for emitters that also reflect (rho > 0): L = Ke + rho H / pi,
    H the face's mean irradiance from the rest of the scene, found by Radiance in ``passes``
    passes (each with the radiances of the last). Returns (radiances by face, history)."""
    faces = [i for i in objrad.emitter_faces(model)
             if max(model.materials[model.face_material[i]].rho) > 0]
    if not faces:
        return None, []
    rng = np.random.default_rng(seed)
    origins, dirs, owner = [], [], []
    for i in faces:
        p = model.vertices[model.faces[i]]
        n = objrad.polygon_normal(p)
        n = n / np.linalg.norm(n)
        pts = objrad.face_points(p, k, rng)
        origins.append(pts)
        dirs.append(np.repeat(n[None], k, axis=0))
        owner.extend([i] * k)
    origins, dirs, owner = np.concatenate(origins), np.concatenate(dirs), np.array(owner)
    radiances = {i: np.array(model.materials[model.face_material[i]].ke) for i in faces}
    history = []
    for step in range(passes):
        octree = radiance.octree(model, f"lights{step}", {i: r for i, r in radiances.items()})
        h = radiance.irradiance(octree, origins, dirs)
        new = {}
        for i in faces:
            m = model.materials[model.face_material[i]]
            mean_h = h[owner == i].mean(axis=0)
            new[i] = np.array(m.ke) + np.array(m.rho) * mean_h / np.pi
        change = max(float(np.max(np.abs(new[i] - radiances[i]) / np.maximum(new[i], 1e-30)))
                     for i in faces)
        history.append({"pass": step + 1, "max_relative_change": change})
        radiances = new
    return radiances, history


# --------------------------------------------------------------------------------------------
# Comparison.


def weighted_median(x, w):
    o = np.argsort(x)
    c = np.cumsum(w[o])
    return float(x[o][np.searchsorted(c, c[-1] / 2)])


# A patch Radiance sees at under this fraction of the sampled patches' area-weighted mean
# irradiance counts as dark: the insides of closed objects and the backs of walls that two-sided
# meshes (doubled faces, --two-sided) add, where Radiance's points pick up leaks of 1e-4 or
# less. Dark patches are left out of the median and the black count, not of the
# area-weighted error.
LIT_FRACTION = 0.01


def figures(y_tool, y_ref, area, weight):
    """The comparison's figures on luminance-weighted irradiance."""
    aw = area * weight
    mean_ref = float(np.sum(aw * y_ref) / np.sum(aw))
    lit = y_ref > LIT_FRACTION * mean_ref
    rel = np.full(len(y_ref), np.nan)
    rel[lit] = np.abs(y_tool[lit] - y_ref[lit]) / y_ref[lit]
    med_ref = weighted_median(y_ref[lit], weight[lit]) if lit.any() else 0.0
    black = (y_tool == 0) & lit
    return {
        "area_weighted_relative_error": float(np.sum(aw * np.abs(y_tool - y_ref))
                                              / np.sum(aw * y_ref)),
        "area_weighted_signed_error": float(np.sum(aw * (y_tool - y_ref)) / np.sum(aw * y_ref)),
        "median_patch_relative_error": weighted_median(rel[lit], weight[lit]),
        # The paper's average weighted percent error over the lit patches (what the tool's
        # error_estimate.weighted_percent estimates), and the gross ones.
        "mean_patch_relative_error": float(np.sum(weight[lit] * rel[lit]) / np.sum(weight[lit]))
        if lit.any() else 0.0,
        "off_by_100_percent": int(np.sum(rel[lit] >= 1.0)),
        "black_where_lit": int(black.sum()),
        "black_where_lit_area_share": float(np.sum(aw[black]) / np.sum(aw)),
        "median_reference_irradiance_Y": med_ref,
    }


def material_by_rho(model, rho):
    """Names of the materials with this rho (to name a patch's material in the report)."""
    names = [m.name for m in model.materials
             if not m.emits and np.allclose(m.rho, rho, rtol=2e-4, atol=1e-6)]
    return "/".join(names) if names else "?"


def compare_solve(label, table, summary, wall, ids, weight, y_ref, model, n_worst):
    """One solve's figures, times and worst patches against the reference."""
    h_tool, _, _, rho = tool_irradiance(table)
    y_tool = h_tool[ids] @ LUMA
    area = table["area"][ids]
    fig = figures(y_tool, y_ref, area, weight)
    rows = []
    for j, i in enumerate(ids):
        rows.append({
            "id": int(i),
            "centre": [float(table[c][i]) for c in ("cx", "cy", "cz")],
            "normal": [float(table[c][i]) for c in ("nx", "ny", "nz")],
            "area": float(area[j]),
            "weight": float(weight[j]),
            "material": material_by_rho(model, rho[i]),
            "tool_Y": float(y_tool[j]),
            "radiance_Y": float(y_ref[j]),
            "relative_error": float(abs(y_tool[j] - y_ref[j]) / y_ref[j]) if y_ref[j] > 0
            else None,
        })
    contrib = area * weight * np.abs(y_tool - y_ref)
    rel = np.nan_to_num(np.abs(y_tool - y_ref) / np.where(y_ref > 0, y_ref, np.inf), nan=0.0)
    return {
        "label": label,
        "figures": fig,
        "times": {"tool_solve_seconds": summary["seconds"]["solve"],
                  "tool_total_seconds": summary["seconds"]["total"],
                  "tool_wall_seconds": wall,
                  "tool_cpu_seconds": (summary.get("cpu_seconds") or {}).get("total")},
        "tool_summary": {k: summary.get(k) for k in ("patches", "rays", "shots", "stop_reason",
                                                     "energy", "error_estimate", "warnings")},
        "worst_by_error_share": [rows[j] for j in np.argsort(-contrib)[:n_worst]],
        "worst_by_relative_error": [rows[j] for j in np.argsort(-rel)[:n_worst]],
        "sampled_patches": rows,
    }


def reference_points(args, rad, octree, polys, ids):
    """Radiance's mean irradiance (RGB) over each sampled patch, per run, and the points per
    patch and run. Each run starts with ``--points`` stratified points per patch; a patch whose
    points still spread so that the standard error of their mean exceeds ``--point-error`` of
    it (of 5 % of the median patch's, for dark patches) gets three times as many again in every
    run, up to ``--max-points`` per run: a patch half under books, lit on a strip of it, is 0.03
    from 8 points and 0.073 from 120 (docs/results/converted-models.md)."""
    n, k = len(ids), args.points
    sums = np.zeros((args.repeat, n, 3))
    count = np.zeros(n, dtype=int)
    s1, s2 = np.zeros(n), np.zeros(n)
    todo, batch, step = np.arange(n), k, 0
    while len(todo):
        for r in range(args.repeat):
            seed = args.seed + 1 + r + 1000 * step
            pts, nrm = points_for(polys, ids[todo], batch, seed)
            h = rad.irradiance(octree, pts, nrm).reshape(len(todo), batch, 3)
            sums[r, todo] += h.sum(axis=1)
            y = h @ LUMA
            s1[todo] += y.sum(axis=1)
            s2[todo] += (y * y).sum(axis=1)
        count[todo] += batch
        total = count * args.repeat
        mean = s1 / total
        se = np.sqrt(np.maximum(s2 / total - mean ** 2, 0.0) / np.maximum(total - 1, 1))
        lit = mean > 0
        floor = 0.05 * (np.median(mean[lit]) if lit.any() else 0.0)
        batch = 3 * int(count[todo[0]])
        want = se > args.point_error * np.maximum(mean, floor)
        todo = np.flatnonzero(want & (count + batch <= args.max_points))
        step += 1
    return sums / count[None, :, None], count


def radiance_reference(args, model, rad, table, polys, ids, weight):
    """Radiance's irradiance at the sampled patches' points: runs, noise, lit-behind ids."""
    t0 = time.perf_counter()
    light_radiance, light_history = light_iteration(model, rad, args.light_passes, 16,
                                                    args.seed + 1000)
    light_seconds = time.perf_counter() - t0
    octree = rad.octree(model, "scene", light_radiance)
    rad.seconds = rad.cpu_seconds = 0.0
    runs, points = reference_points(args, rad, octree, polys, ids)
    radiance_seconds, radiance_cpu = rad.seconds, rad.cpu_seconds
    y_runs = np.array([h @ LUMA for h in runs])
    y_ref = y_runs.mean(axis=0)
    area = table["area"][ids]
    aw = area * weight
    lit = y_ref > 0
    noise = {}
    if args.repeat > 1:
        # The reference's own noise: the standard error of the mean of its independent runs.
        spread = y_runs.std(axis=0, ddof=1) / np.sqrt(args.repeat)
        noise = {
            "area_weighted": float(np.sum(aw * spread) / np.sum(aw * y_ref)),
            "median_patch": weighted_median(spread[lit] / y_ref[lit], weight[lit]),
            "run_to_run_area_weighted": float(np.sum(aw * np.abs(y_runs[0] - y_runs[1]))
                                              / np.sum(aw * y_ref)),
        }

    # Patches dark on their front whose back Radiance sees lit: light lands behind them.
    med = weighted_median(y_ref, weight)
    dark = np.flatnonzero(y_ref <= 0.01 * med)
    lit_behind = []
    if len(dark):
        pts, nrm = points_for(polys, ids[dark], args.points, args.seed + 99)
        hb = rad.irradiance(octree, pts, -nrm).reshape(len(dark), args.points, 3).mean(axis=1)
        lit_behind = [int(ids[d]) for d, y in zip(dark, hb @ LUMA) if y > 0.01 * med]

    return {"y_runs": y_runs.tolist(), "noise": noise, "lit_behind": lit_behind,
            "sources": rad.sources,
            "points_per_patch": points.tolist(),
            "light_history": light_history, "light_seconds": light_seconds,
            "seconds": radiance_seconds, "cpu_seconds": radiance_cpu}


def one_run_noise(y_runs, aw) -> float | None:
    """One Radiance run's area-weighted error from the reference's own runs, by leave-one-out
    (each run against the mean of the others, scaled by sqrt((k - 1) / k), as daylight.py's
    ``noise``): what a single run at the reference's settings would be off by."""
    k = len(y_runs)
    if k < 2:
        return None
    mean = y_runs.mean(axis=0)
    errs = []
    for j in range(k):
        others = np.delete(y_runs, j, axis=0).mean(axis=0)
        e = np.abs(y_runs[j] - others) * np.sqrt((k - 1) / k)
        errs.append(float(np.sum(aw * e) / np.sum(aw * mean)))
    return float(np.mean(errs))


def match_accuracy(args, out, model, table, polys, ids, weight, y_ref, target, one_run,
                   tries=4):
    """``--match``: Radiance's CPU seconds at the first solve's area-weighted error, measured.
    Single runs of the reference's own procedure (``--points``, more points where they spread,
    ``--repeat 1``, new points) at another ``-ad``, each compared with the reference as the
    tool is (so both errors hold the reference's own noise); the next ``-ad`` from a power law
    error ~ ad^slope through the runs so far (slope -0.5 until two runs give one, kept within
    [-1, -0.25]), until a run is within 15 % of ``target`` or ``tries`` runs are done. The time
    at ``target`` is read off the same law (time ~ ad) from the run closest to it, as
    daylight.py's ``match_accuracy``, never below ``-ad 1``: when even that run is more
    accurate than ``target`` by more than 15 %, its time is a bound (``by``: ``bound``; Radiance
    needs at most that long), not a time at ``target``. Times are for the sampled patches only."""
    octree = out / "scene.oct"
    if not octree.is_file():  # a reused reference whose octree was removed: make it again
        rad = Radiance(args, out)
        lights, _ = light_iteration(model, rad, args.light_passes, 16, args.seed + 1000)
        octree = rad.octree(model, "scene", lights)
    area = table["area"][ids]
    runs = []
    ad = args.ad * (one_run / target) ** 2
    slope = -0.5
    for k in range(tries):
        ad = int(min(max(round(ad), 1), 65536))
        if any(r["ad"] == ad for r in runs):
            break
        sub = argparse.Namespace(**{**vars(args), "ad": ad, "repeat": 1,
                                    "lw": min(args.lw, 0.5 / ad),
                                    "seed": args.seed + 7919 * (k + 1)})
        rad = Radiance(sub, out)
        h, points = reference_points(sub, rad, octree, polys, ids)
        err = figures(h[0] @ LUMA, y_ref, area, weight)["area_weighted_relative_error"]
        runs.append({"ad": ad, "area_weighted_error": err, "seconds": rad.seconds,
                     "cpu_seconds": rad.cpu_seconds, "points": int(np.sum(points)),
                     "rtrace": " ".join(rad.opts)})
        print(f"  Radiance -ad {ad}, one run: {100 * err:.2f} % area-weighted against the "
              f"reference, {rad.cpu_seconds:.1f} CPU s (target {100 * target:.2f} %)")
        if abs(err / target - 1) < 0.15:
            break
        if len(runs) >= 2:
            a, b = runs[-2], runs[-1]
            if a["ad"] != b["ad"] and a["area_weighted_error"] > 0 and err > 0:
                fit = np.log(err / a["area_weighted_error"]) / np.log(b["ad"] / a["ad"])
                slope = float(min(max(fit, -1.0), -0.25))
        ad = ad * (target / err) ** (1 / slope)
    best = min(runs, key=lambda r: abs(np.log(r["area_weighted_error"] / target)))
    ad_at = best["ad"] * (target / best["area_weighted_error"]) ** (1 / slope)
    by = "measured"
    if ad_at < 1.0:
        # Read past the cheapest run Radiance has: its time there bounds Radiance's at target.
        best = min(runs, key=lambda r: r["ad"])
        ad_at, by = float(best["ad"]), "bound"
    return {"target_area_weighted_error": target, "one_run_noise": one_run, "runs": runs,
            "slope": slope, "ad_at_tool_accuracy": float(ad_at),
            "seconds_at_tool_accuracy": best["seconds"] * ad_at / best["ad"],
            "cpu_seconds_at_tool_accuracy": best["cpu_seconds"] * ad_at / best["ad"],
            "by": by}


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter,
                                 epilog=__doc__.split("\n\n", 1)[1])
    ap.add_argument("model", type=Path, help="OBJ file (its MTL beside it)")
    ap.add_argument("--out", type=Path, help="output folder (default out/check/MODEL)")
    ap.add_argument("--solve-args", default="", help="extra flags for radiosity solve, quoted")
    ap.add_argument("--also", action="append", default=[], metavar="ARGS",
                    help="another solve (its extra flags, quoted) checked against the same "
                    "reference; it must mesh the same patches; repeatable")
    ap.add_argument("--radiosity", help=BINARY_HELP)
    ap.add_argument("--samples", type=int, default=1000, help="patches sampled (default 1000)")
    ap.add_argument("--points", type=int, default=8, help="points per patch (default 8)")
    ap.add_argument("--point-error", type=float, default=0.02,
                    help="more points for a patch until the standard error of its points' mean "
                    "is below this fraction of it (default 0.02)")
    ap.add_argument("--max-points", type=int, default=128,
                    help="at most this many points per patch and run (default 128: 8, then 32, "
                    "then 128, each step 4 times the last)")
    ap.add_argument("--seed", type=int, default=1, help="seed of the sampling")
    ap.add_argument("--repeat", type=int, default=2,
                    help="Radiance runs with independent points (their spread is the reference's "
                    "noise; the reference is their mean); default 2")
    ap.add_argument("--ab", type=int, default=12, help="rtrace -ab (default 12)")
    ap.add_argument("--ad", type=int, default=512, help="rtrace -ad (default 512)")
    ap.add_argument("--as", dest="as_", type=int, default=0, help="rtrace -as (default 0)")
    ap.add_argument("--aa", type=float, default=0.0, help="rtrace -aa (default 0: no cache)")
    ap.add_argument("--lr", type=int, default=-12, help="rtrace -lr (default -12)")
    ap.add_argument("--lw", type=float, default=1e-4, help="rtrace -lw (default 1e-4)")
    ap.add_argument("--light-passes", type=int, default=3,
                    help="passes for emitters that also reflect (default 3)")
    ap.add_argument("--procs", type=int, default=os.cpu_count() or 1, help="rtrace -n")
    ap.add_argument("--reuse", action="store_true",
                    help="reuse Radiance's result saved in --out when made for the same model, "
                         "points and settings (to compare solver changes quickly)")
    ap.add_argument("--worst", type=int, default=10, help="worst patches listed")
    ap.add_argument("--match", action="store_true",
                    help="also measure Radiance's CPU seconds at the first solve's "
                    "area-weighted error: single runs at another -ad against the reference "
                    "(report.json radiance.matched; see match_accuracy)")
    ap.add_argument("--compare", action="append", default=[], type=Path, metavar="CSV",
                    help="no solve, no Radiance: compare this patches.csv (of a solve made "
                    "elsewhere, on the same patches) against the reference saved in --out by an "
                    "earlier check; repeatable")
    args = ap.parse_args()
    if args.compare:
        compare_saved(args)
        return

    model_path = args.model.resolve()
    out = (args.out or ROOT / "out" / "check" / model_path.stem).resolve()
    out.mkdir(parents=True, exist_ok=True)
    binary = radiosity_binary(args.radiosity, must_exist=True)

    # The tool: the first solve fixes the patches and the sample.
    arg_sets = [shlex.split(args.solve_args)] + [shlex.split(a) for a in args.also]
    solves = []
    for k, solve_args in enumerate(arg_sets):
        sub = out if k == 0 else out / f"also{k}"
        table, polys, summary, wall = solve(binary, model_path, sub, solve_args)
        if solves:
            if not same_patches(table, solves[0][1]):
                sys.exit(f"--also {shlex.join(solve_args)}: not the same patches as the first solve")
        solves.append((solve_args, table, polys, summary, wall))
    table, polys = solves[0][1], solves[0][2]
    ids, weight = sample_patches(table, args.samples, args.seed)

    # Radiance, or its saved result for the same model, points and settings (--reuse).
    model = objrad.read_obj(model_path, binary, parse_emit(arg_sets[0]))
    rad = Radiance(args, out)
    rad.add_luminaires(binary, model_path, arg_sets[0])
    key = {"model": str(model_path), "bytes": model_path.stat().st_size,
           "mtime": model_path.stat().st_mtime, "rtrace": " ".join(rad.opts),
           "ids": [int(i) for i in ids], "points": args.points, "seed": args.seed,
           "point_error": args.point_error, "max_points": args.max_points,
           "repeat": args.repeat, "light_passes": args.light_passes,
           "emit": arg_sets[0]}
    saved = out / "radiance.json"
    cached = None
    if args.reuse and saved.is_file():
        cached = json.loads(saved.read_text())
        if cached.get("key") != key:
            print(f"{saved}: made for other points or settings; running Radiance")
            cached = None
    if cached is None:
        cached = radiance_reference(args, model, rad, table, polys, ids, weight)
        cached["key"] = key
        saved.write_text(json.dumps(cached))
    else:
        print(f"Radiance's result reused from {saved} (--reuse)")
    y_runs = np.array(cached["y_runs"])
    y_ref = y_runs.mean(axis=0)
    noise = cached["noise"]
    lit_behind = cached["lit_behind"]
    light_history = cached["light_history"]
    light_seconds = cached["light_seconds"]
    radiance_seconds = cached["seconds"]
    radiance_cpu = cached.get("cpu_seconds")  # None: saved before CPU seconds were kept

    results = []
    for k, (solve_args, tbl, _, summary, wall) in enumerate(solves):
        res = compare_solve(" ".join(solve_args) or "(defaults)", tbl, summary, wall, ids,
                            weight, y_ref, model, args.worst)
        res["figures"]["dark_front_lit_back"] = len(lit_behind)
        results.append(res)
    report = {
        "model": str(args.model),
        "quantity": "irradiance Y = 0.2126 R + 0.7152 G + 0.0722 B (W/m^2); tool: (B - E)/rho",
        "patches": int(len(table)),
        "sampled": int(len(ids)),
        "points_per_patch": args.points,
        "radiance": {"rtrace": " ".join(rad.opts), "version": "pyradiance 1.3.1 (RADIANCE 6.0a)",
                     "repeat": args.repeat, "noise": noise, "seconds": radiance_seconds,
                     "cpu_seconds": radiance_cpu,
                     "points": int(np.sum(cached.get("points_per_patch", [args.points] * len(ids)))
                                   * args.repeat),
                     "patches_refined": int(np.sum(np.array(cached.get(
                         "points_per_patch", [args.points] * len(ids))) > args.points)),
                     "light_passes": light_history, "light_pass_seconds": light_seconds,
                     "sources": cached.get("sources", rad.sources),
                     "runs_Y": y_runs.tolist()},
        "warnings": model.warnings,
        "lit_behind_ids": lit_behind,
        "solves": results,
    }
    aw = table["area"][ids] * weight
    one_run = one_run_noise(y_runs, aw)
    if one_run is not None:
        report["radiance"]["noise"] = {**noise, "one_run_area_weighted": one_run}
    if args.match:
        target = results[0]["figures"]["area_weighted_relative_error"]
        if one_run is None:
            report["warnings"].append("--match needs --repeat 2 or more (the one-run noise)")
        elif target <= 1.5 * noise["area_weighted"]:
            report["warnings"].append("--match: the tool's error is within 1.5x the "
                                      "reference's own noise; Radiance's time at it not measured")
        else:
            report["radiance"]["matched"] = match_accuracy(args, out, model, table, polys, ids,
                                                           weight, y_ref, target, one_run)
    (out / "report.json").write_text(json.dumps(report, indent=1))
    print_table(report, out)


def compare_saved(args):
    """``--compare``: each CSV's figures against the reference an earlier check saved in
    --out, on the patches it sampled (the same ids and weights), with the signed error per
    material (its share of the area-weighted reference)."""
    out = (args.out or ROOT / "out" / "check" / args.model.resolve().stem).resolve()
    saved = out / "radiance.json"
    if not saved.is_file():
        sys.exit(f"{saved}: no saved reference (run the check once without --compare)")
    cached = json.loads(saved.read_text())
    base = read_patches(out / "solve" / "patches.csv")
    ids, weight = sample_patches(base, args.samples, args.seed)
    if [int(i) for i in ids] != cached["key"]["ids"]:
        sys.exit(f"{saved}: sampled for other patches (--samples and --seed as the check's)")
    y_ref = np.array(cached["y_runs"]).mean(axis=0)
    binary = radiosity_binary(args.radiosity, must_exist=True)
    model = objrad.read_obj(args.model.resolve(), binary, parse_emit(cached["key"]["emit"]))
    print(f"against {saved}: {len(ids)} patches, Radiance noise "
          f"{100 * cached['noise'].get('area_weighted', 0):.2f} %")
    for csv in args.compare:
        table = read_patches(csv)
        if not same_patches(table, base):
            print(f"{csv}: not the same patches as {out / 'solve'}; skipped")
            continue
        h_tool, _, _, rho = tool_irradiance(table)
        y_tool = h_tool[ids] @ LUMA
        area = table["area"][ids]
        fig = figures(y_tool, y_ref, area, weight)
        print(f"{csv}: area-weighted {100 * fig['area_weighted_relative_error']:.2f} %, signed "
              f"{100 * fig['area_weighted_signed_error']:+.2f} %, median "
              f"{100 * fig['median_patch_relative_error']:.2f} %, mean "
              f"{100 * fig['mean_patch_relative_error']:.2f} %, >= 100 % off "
              f"{fig['off_by_100_percent']}")
        aw = area * weight
        total = np.sum(aw * y_ref)
        names = [material_by_rho(model, rho[i]) for i in ids]
        for name in sorted(set(names)):
            m = np.array([n == name for n in names])
            print(f"    {name[:28]:<28} {m.sum():>4} patches  signed "
                  f"{100 * np.sum(aw[m] * (y_tool[m] - y_ref[m])) / total:+.2f} %  abs "
                  f"{100 * np.sum(aw[m] * np.abs(y_tool[m] - y_ref[m])) / total:.2f} %")


def print_table(r, out):
    """The short table: one column per solve."""
    rad = r["radiance"]
    print(f"{r['model']}: {r['patches']} patches, {r['sampled']} sampled x "
          f"{r['points_per_patch']} points x {rad['repeat']} Radiance runs "
          f"({rad.get('patches_refined', 0)} patches given more points)")
    if rad["noise"]:
        print(f"  Radiance noise (its mean): {100 * rad['noise']['area_weighted']:.2f} % "
              f"area-weighted, {100 * rad['noise']['median_patch']:.2f} % median patch; "
              f"{rad['seconds']:.1f} s for {rad['points']} points")
    if rad.get("matched"):
        m = rad["matched"]
        print(f"  Radiance at the tool's {100 * m['target_area_weighted_error']:.2f} %: "
              f"-ad {m['ad_at_tool_accuracy']:.0f}, {m['cpu_seconds_at_tool_accuracy']:.1f} "
              f"CPU s for the sampled patches ({m['by']}, {len(m['runs'])} runs)")
    rows = [("solve", lambda s: s["label"][:24]),
            ("area-weighted error %", lambda s: f"{100 * s['figures']['area_weighted_relative_error']:.2f}"),
            ("  signed %", lambda s: f"{100 * s['figures']['area_weighted_signed_error']:+.2f}"),
            ("median patch error %", lambda s: f"{100 * s['figures']['median_patch_relative_error']:.2f}"),
            ("mean patch error %", lambda s: f"{100 * s['figures'].get('mean_patch_relative_error', 0):.2f}"),
            ("lit patches >= 100 % off", lambda s: str(s["figures"].get("off_by_100_percent", "-"))),
            ("black where lit", lambda s: str(s["figures"]["black_where_lit"])),
            ("dark front, lit back", lambda s: str(s["figures"]["dark_front_lit_back"])),
            ("tool solve s", lambda s: f"{s['times']['tool_solve_seconds']:.2f}"),
            ("tool run s (wall)", lambda s: f"{s['times']['tool_wall_seconds']:.2f}")]
    for name, get in rows:
        print(f"  {name:<22}" + "".join(f"{get(s):>26}" for s in r["solves"]))
    s = r["solves"][0]
    print(f"  worst patches of '{s['label']}' (share of the area-weighted error):")
    print(f"    {'id':>7} {'material':<16} {'area m2':>9} {'tool Y':>9} {'Radiance':>9} {'rel':>7}")
    for w in s["worst_by_error_share"][:5]:
        rel = f"{100 * w['relative_error']:6.1f}%" if w["relative_error"] is not None else "   -"
        print(f"    {w['id']:>7} {w['material'][:16]:<16} {w['area']:9.5f} {w['tool_Y']:9.4f} "
              f"{w['radiance_Y']:9.4f} {rel:>7}")
    print(f"  report: {out / 'report.json'}")


if __name__ == "__main__":
    main()
