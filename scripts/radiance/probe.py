#!/usr/bin/env python3
"""Radiance's irradiance over one patch of a ``check.py`` run, at many uniform points, with the
closed-form direct irradiance of the run's light sources beside it.

For a patch whose figure looks wrong: is it the tool, or the reference's few points? ``check.py``
averages 8 to 128 points per patch; this takes ``--points`` (default 400) uniform points on the
patch polygon (from the run's ``solve/patches.ply``), runs ``rtrace -I`` on the run's own octree
(``scene.oct``) at ``-ab`` bounces, and sums Lambert's closed form over every light polygon of
``scene.rad`` (unoccluded; a light counts when the point is in front of it and the light wholly
in front of the patch's plane). With ``-ab 0`` the two must agree where nothing shadows the
lights: scripts/radiance/README.md, "Emitters Radiance can sample", was measured this way.

    .venv-radiance/bin/python scripts/radiance/probe.py out/check/conv3-plain 21298 --ab 0
"""

from __future__ import annotations

import argparse
import subprocess
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from check import read_ply_faces  # noqa: E402
from common import LUMA, radiance_env, ray_lines, rtrace_rgb  # noqa: E402


def light_polygons(rad: Path):
    """(vertices, radiance RGB) of every polygon of a ``light`` in a scene file objrad wrote."""
    lines = rad.read_text().split("\n")
    radiance, out = {}, []
    for i, line in enumerate(lines):
        w = line.split()
        if len(w) == 3 and w[1] == "light":
            radiance[w[2]] = np.array([float(x) for x in lines[i + 3].split()[1:4]])
        elif len(w) == 3 and w[1] == "polygon" and w[0] in radiance:
            v = np.array([float(x) for x in lines[i + 3].split()[1:]]).reshape(-1, 3)
            out.append((v, radiance[w[0]]))
    return out


def lambert(p: np.ndarray, n: np.ndarray, v: np.ndarray) -> float:
    """Irradiance at p facing n from a Lambertian polygon v of unit radiance (its front is
    counter-clockwise), 0 when p is behind it or it is not wholly in front of p's plane."""
    nv = np.cross(v[1] - v[0], v[2] - v[0])
    if np.dot(p - v[0], nv) <= 0 or np.any((v - p) @ n <= 0):
        return 0.0
    s = 0.0
    for k in range(len(v)):
        a, b = v[k] - p, v[(k + 1) % len(v)] - p
        a, b = a / np.linalg.norm(a), b / np.linalg.norm(b)
        g = np.cross(a, b)
        ng = np.linalg.norm(g)
        if ng > 1e-15:
            s += np.arctan2(ng, np.dot(a, b)) * np.dot(n, g / ng)
    return abs(s) / 2


def uniform_points(poly: np.ndarray, m: int, rng) -> np.ndarray:
    """m points uniform on a convex polygon (fan triangles by area), stratified in the first."""
    tris = [(poly[0], poly[i], poly[i + 1]) for i in range(1, len(poly) - 1)]
    area = np.array([np.linalg.norm(np.cross(b - a, c - a)) for a, b, c in tris])
    cdf = np.cumsum(area) / area.sum()
    pts = []
    for k in range(m):
        s = (k + rng.random()) / m
        j = min(int(np.searchsorted(cdf, s)), len(tris) - 1)
        a, b, c = tris[j]
        r1, r2 = np.sqrt(rng.random()), rng.random()
        pts.append((1 - r1) * a + r1 * (1 - r2) * b + r1 * r2 * c)
    return np.array(pts)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter,
                                 epilog=__doc__.split("\n\n", 1)[1])
    ap.add_argument("run", type=Path, help="a check.py --out folder")
    ap.add_argument("patch", type=int, help="patch id (patches.csv)")
    ap.add_argument("--points", type=int, default=400)
    ap.add_argument("--ab", type=int, default=12)
    ap.add_argument("--ad", type=int, default=1024)
    ap.add_argument("--lw", type=float, default=1e-4, help="rtrace -lw (default 1e-4)")
    ap.add_argument("--seed", type=int, default=5)
    args = ap.parse_args()
    bin_, env = radiance_env()
    poly = read_ply_faces(args.run / "solve" / "patches.ply")[args.patch]
    n = np.cross(poly[1] - poly[0], poly[2] - poly[0])
    n /= np.linalg.norm(n)
    pts = uniform_points(poly, args.points, np.random.default_rng(args.seed))
    opts = ["-h", "-I+", "-n", "2", "-ab", str(args.ab), "-ad", str(args.ad), "-as", "0",
            "-aa", "0", "-lr", "-12", "-lw", str(args.lw), "-dt", "0", "-dc", "1", "-ds", "0.02",
            "-dj", "0", "-dr", "0", "-u+"]
    res = subprocess.run([str(bin_ / "rtrace"), *opts, str(args.run / "scene.oct")],
                         input=ray_lines(pts, np.repeat(n[None], len(pts), axis=0)),
                         capture_output=True, text=True, env=env, check=True)
    y = rtrace_rgb(res.stdout, len(pts)) @ LUMA
    lights = light_polygons(args.run / "scene.rad")
    direct = np.array([sum(lambert(p, n, v) * float(L @ LUMA) for v, L in lights) for p in pts])
    se = y.std(ddof=1) / np.sqrt(len(y))
    print(f"patch {args.patch}: {len(poly)} corners, normal {np.round(n, 4)}")
    print(f"Radiance -ab {args.ab}: mean Y {y.mean():.6g} ± {se:.2g} over {len(pts)} points")
    print(f"closed-form direct of {len(lights)} light polygons (unoccluded): {direct.mean():.6g}")


if __name__ == "__main__":
    main()
