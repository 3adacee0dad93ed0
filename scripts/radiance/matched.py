#!/usr/bin/env python3
"""Two meshes of one model on the same points: a check's sampled patches read from another
solve's ``patches.csv`` wherever it has a patch with the same centre.

``check.py --compare`` needs the same patches; a mesher change (cuts near lights, say) moves
some, and a fresh sample of the new mesh differs from the old one's by more than the change.
Here the reference of one ``check.py`` run (its ``report.json``, with the sampled patches'
centres and Radiance's values) is read against the solve it checked and against OTHER, on the
sampled patches both meshes share, so the two are compared on the same points.

    .venv-radiance/bin/python scripts/radiance/matched.py out/check/s7-plain/report.json \\
        out/near/uncut/patches.csv
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from check import tool_irradiance  # noqa: E402
from common import LUMA, read_patches  # noqa: E402


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("report", type=Path, help="a check.py report.json")
    ap.add_argument("other", type=Path, help="patches.csv of another solve of the same model")
    a = ap.parse_args()
    sampled = json.loads(a.report.read_text())["solves"][0]["sampled_patches"]
    table = read_patches(a.other)
    h, *_ = tool_irradiance(table)
    y = h @ LUMA
    centres = np.stack([table["cx"], table["cy"], table["cz"]], axis=1)
    at = {tuple(np.round(c, 4)): i for i, c in enumerate(centres)}
    rows = [(p["weight"] * p["area"], p["tool_Y"], y[at[k]], p["radiance_Y"])
            for p in sampled if (k := tuple(np.round(p["centre"], 4))) in at]
    if not rows:
        sys.exit(f"matched.py: no sampled patch of {a.report} has a centre in {a.other}")
    w, checked, other, ref = map(np.array, zip(*rows))
    total = (w * ref).sum()

    def figures(t):
        return 100 * (w * np.abs(t - ref)).sum() / total, 100 * (w * (t - ref)).sum() / total

    print(f"{len(rows)} of {len(sampled)} sampled patches matched")
    for name, t in (("checked solve", checked), (str(a.other), other)):
        e, s = figures(t)
        print(f"  {name}: area-weighted {e:.2f} %, signed {s:+.2f} %")


if __name__ == "__main__":
    main()
