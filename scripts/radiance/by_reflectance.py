#!/usr/bin/env python3
"""The tool against itself: area-weighted irradiance per reflectance over several solves of one
model, each against the first.

``patches.csv`` carries no material name, but each material of the project's scenes has its own
reflectance, so the patches are grouped by rho (rounded to 3 places; emitters and patches with a
channel of rho = 0 left out). Every patch counts, not a sample, and the patch ids need not match:
solves by different methods or seeds give the faces lit from behind different back patches, so
``check.py --compare`` cannot take them, this can. Use it to ask whether the solver has
converged (a default solve against a much finer one) before asking Radiance whose a difference
is.

    .venv-radiance/bin/python scripts/radiance/by_reflectance.py FINE/patches.csv \\
        DEFAULT/patches.csv OTHER/patches.csv --top 14
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from check import tool_irradiance  # noqa: E402
from common import LUMA, read_patches  # noqa: E402


def by_reflectance(path: Path) -> dict[tuple, tuple[float, float]]:
    """{rho (3 places): (sum of area x luminance-weighted irradiance, area)}."""
    t = read_patches(path)
    h, _, _, rho = tool_irradiance(t)
    keep = rho.min(axis=1) > 0
    y = h[keep] @ LUMA
    area = t["area"][keep]
    out: dict[tuple, list[float]] = {}
    for r, yy, a in zip(np.round(rho[keep], 3), y, area):
        acc = out.setdefault(tuple(float(x) for x in r), [0.0, 0.0])
        acc[0] += a * yy
        acc[1] += a
    return {k: (v[0], v[1]) for k, v in out.items()}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("csv", type=Path, nargs="+", help="patches.csv files; the first is the base")
    ap.add_argument("--top", type=int, default=12, help="reflectances listed, by area (default 12)")
    args = ap.parse_args()
    runs = [by_reflectance(p) for p in args.csv]
    base = runs[0]
    total = [sum(v[0] for v in r.values()) for r in runs]
    print("base:", args.csv[0])
    for p, t in zip(args.csv[1:], total[1:]):
        print(f"  {p}: whole scene {100 * (t / total[0] - 1):+.2f} %")
    print(f"{'rho':>22} {'area m2':>9} {'mean Y':>8}  " + "  ".join(f"run {k + 1:>2}" for k in
                                                                  range(len(runs) - 1)))
    for k in sorted(base, key=lambda k: -base[k][1])[:args.top]:
        s, a = base[k]
        cells = []
        for r in runs[1:]:
            cells.append(f"{100 * (r[k][0] / s - 1):+6.2f} %" if k in r and s > 0 else "     -  ")
        rho = "(" + ", ".join(f"{x:.3f}" for x in k) + ")"
        print(f"{rho:>22} {a:9.2f} {s / a:8.4f}  " + "  ".join(cells))


if __name__ == "__main__":
    main()
