#!/usr/bin/env python3
"""Whole surfaces against Radiance: the mean irradiance over every patch of a material, the
tool's against Radiance's at stratified points in each of those patches.

``check.py`` samples 300 patches of all sizes, so its signed figure carries the sample's noise
and Radiance's (about 1 % on the project's converted rooms); a systematic difference of that
size on the large surfaces needs a sharper instrument. Here every patch of each material asked
for gets ``--points`` stratified points (as ``check.py``'s, from the solve's own patch
polygons), so the area-weighted mean over the surface has neither a patch sample's noise nor
that of points spread at random over large faces (the luminaires' hot spots on the ceiling make
that 5 % noisy at 1,500 points). The tool's patches of a material are those with its
reflectance (``patches.csv`` carries no material name: untextured materials only, each with a
reflectance of its own, to 3 significant places).

    .venv-radiance/bin/python scripts/radiance/surfaces.py out/furnished/converted-plain.obj \\
        --out out/surf/plain --material wall_plaster --material ceiling

Writes DIR/surfaces.json (per patch: id, area, tool, Radiance) and prints one line per material;
``--reuse`` takes an earlier run's solve (to try other Radiance settings on the same patches).
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import objrad  # noqa: E402
from check import Radiance, points_for, read_ply_faces, solve, tool_irradiance  # noqa: E402
from common import BINARY_HELP, LUMA, radiosity_binary, read_patches  # noqa: E402


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter,
                                 epilog=__doc__.split("\n\n", 1)[1])
    ap.add_argument("model", type=Path, help="OBJ file (its MTL beside it)")
    ap.add_argument("--out", type=Path, required=True, help="output folder")
    ap.add_argument("--material", action="append", required=True, help="material (repeatable)")
    ap.add_argument("--points", type=int, default=4, help="Radiance points per patch (default 4)")
    ap.add_argument("--solve-args", default="", help="extra flags for radiosity solve")
    ap.add_argument("--radiosity", help=BINARY_HELP)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--ab", type=int, default=12, help="rtrace -ab (default 12)")
    ap.add_argument("--ad", type=int, default=128, help="rtrace -ad (default 128: the mean is "
                    "over thousands of points)")
    ap.add_argument("--lw", type=float, default=1e-4, help="rtrace -lw (default 1e-4)")
    ap.add_argument("--within", type=float, nargs=6, metavar=("X0", "X1", "Y0", "Y1", "Z0", "Z1"),
                    help="only the patches whose centre lies in this box (e.g. a surface's hot "
                    "spots, with many --points)")
    ap.add_argument("--reuse", action="store_true",
                    help="take DIR/solve's patches.csv and patches.ply from an earlier run")
    ap.add_argument("--procs", type=int, default=os.cpu_count() or 1)
    args = ap.parse_args()
    args.as_, args.aa, args.lr = 0, 0.0, -12

    args.out.mkdir(parents=True, exist_ok=True)
    binary = radiosity_binary(args.radiosity, must_exist=True)
    model = objrad.read_obj(args.model.resolve(), binary)
    names = [m.name for m in model.materials]
    for m in args.material:
        if m not in names:
            sys.exit(f"{args.model}: no material {m!r} (it has {', '.join(names)})")
    sdir = args.out / "solve"
    if args.reuse and (sdir / "patches.csv").exists() and (sdir / "patches.ply").exists():
        table, polys = read_patches(sdir / "patches.csv"), read_ply_faces(sdir / "patches.ply")
    else:
        table, polys, _, _ = solve(binary, args.model, args.out, args.solve_args.split())
    h, _, _, rho = tool_irradiance(table)
    tool_y = h @ LUMA

    radiance = Radiance(args, args.out)
    octree = radiance.octree(model, "scene")
    report = {"model": str(args.model), "points_per_patch": args.points, "materials": {}}
    t0 = time.perf_counter()
    for m in args.material:
        # To 3 significant places, so that reflectances scaled down (a direct-only run) keep apart.
        want = np.asarray(model.materials[names.index(m)].rho)
        ids = np.where(np.all(np.isclose(rho, want, rtol=5e-4, atol=0.0), axis=1))[0]
        if len(ids) == 0:
            sys.exit(f"no patch has {m}'s reflectance {want.tolist()}")
        if args.within:
            x0, x1, y0, y1, z0, z1 = args.within
            c = [table[k][ids] for k in ("cx", "cy", "cz")]
            ids = ids[(c[0] >= x0) & (c[0] <= x1) & (c[1] >= y0) & (c[1] <= y1) & (c[2] >= z0)
                      & (c[2] <= z1)]
            if len(ids) == 0:
                sys.exit(f"no patch of {m} has its centre in the box {args.within}")
        pts, nrm = points_for(polys, ids, args.points, args.seed)
        y = (radiance.irradiance(octree, pts, nrm) @ LUMA).reshape(len(ids), args.points)
        rad = y.mean(axis=1)
        area = table["area"][ids]
        t_mean = float((area * tool_y[ids]).sum() / area.sum())
        r_mean = float((area * rad).sum() / area.sum())
        # Radiance's noise: the points' spread within each patch, over the points, summed by
        # area (the patches' means are independent).
        # (An upper bound: the points are stratified. None with one point per patch.)
        se = (np.sqrt(((area / area.sum()) ** 2 * y.var(axis=1, ddof=1) / args.points).sum())
              if args.points > 1 else None)
        report["materials"][m] = {
            "area": float(area.sum()), "patches": int(len(ids)), "tool": t_mean,
            "radiance": r_mean, "radiance_se": se if se is None else float(se),
            "per_patch": [{"id": int(i), "area": float(a), "tool": float(tool_y[i]),
                           "radiance": float(r)} for i, a, r in zip(ids, area, rad)]}
        noise = "" if se is None else f" (Radiance's noise at most {100 * se / r_mean:.2f} %)"
        print(f"  {m:16s} {area.sum():8.2f} m2 {len(ids):6d} patches  tool {t_mean:.4f}  "
              f"Radiance {r_mean:.4f}  tool/Radiance {100 * (t_mean / r_mean - 1):+.2f} %{noise}",
              flush=True)
    report["radiance_seconds"] = time.perf_counter() - t0
    (args.out / "surfaces.json").write_text(json.dumps(report, indent=1))


if __name__ == "__main__":
    main()
