#!/usr/bin/env python3
"""How honest a solve's error estimate is, without a reference: two solves of one model that
differ only in `--seed` give each patch's noise as |B1 - B2| / ((B1 + B2) / 2) / sqrt(2) (B the
mean of the three channels); its mean over the patches lit in either is set beside the mean of
the two solves' own estimates (summary.json, the last trace point's `weighted_percent`, the
paper's average weighted percent error).

    radiosity solve MODEL --out A --seed 1 [FLAGS]
    radiosity solve MODEL --out B --seed 2 [FLAGS]
    python3 scripts/seed_noise.py A B

The noise leaves out what both solves share (the light still owed, a bias), so a ratio under 1
is expected where the estimate counts owed light; over 1, the estimate is optimistic.
Standard library only.
"""

import csv
import json
import math
import sys
from pathlib import Path


def radiosity(folder: Path) -> list[float]:
    with open(folder / "patches.csv", newline="") as f:
        return [(float(r["b_r"]) + float(r["b_g"]) + float(r["b_b"])) / 3.0
                for r in csv.DictReader(f)]


def estimate(folder: Path) -> float:
    summary = json.loads((folder / "summary.json").read_text())
    return summary["trace"][-1]["estimate"]["weighted_percent"]


def main() -> int:
    if len(sys.argv) != 3:
        print(__doc__.strip(), file=sys.stderr)
        return 2
    a_dir, b_dir = Path(sys.argv[1]), Path(sys.argv[2])
    a, b = radiosity(a_dir), radiosity(b_dir)
    if len(a) != len(b):
        print(f"seed_noise: {len(a)} patches against {len(b)}: not the same model and "
              "patch size", file=sys.stderr)
        return 1
    rel = [abs(x - y) / ((x + y) / 2.0) for x, y in zip(a, b) if x + y > 0.0]
    if not rel:
        print("seed_noise: no lit patch", file=sys.stderr)
        return 1
    noise = sum(rel) / len(rel) / math.sqrt(2.0)
    est = (estimate(a_dir) + estimate(b_dir)) / 2.0
    ratio = f"{noise / est:.2f}" if est > 0.0 else "-"
    print(f"patches {len(rel)}  estimate {100 * est:.2f} %  between-seed noise "
          f"{100 * noise:.2f} %  noise / estimate {ratio}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
