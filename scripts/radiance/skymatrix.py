"""The tool's hourly sky vectors (src/sky/matrix.rs) against Radiance's ``gendaymtx`` on the
same hours.

Writes a small ``.wea`` (a Chicago-like site, 41.98 N 87.92 W, time zone 90° W; hours of a clear,
an intermediate, a hazy, an overcast, a low-sun, a twilight and a dark sky), runs
``gendaymtx -m MF -O0 -h -of -c 1 1 1`` on it (float output: its ASCII output keeps 3 digits;
``-c 1 1 1``: a white sky, its default is slightly blue) with the sun in the patches and with
``-s`` (sky only), runs the tool's ``examples/skymatrix.rs`` on the same lines (the sun by
``gendaymtx``'s own formulas), and prints per MF and hour the per-patch relative difference of
the sky patches (max and mean), the ground's, and both horizontal illuminances
Σ L sin(a) Ω × 179. ``--variants`` adds the tool's integrated patches and NOAA sun against
``gendaymtx`` (where they differ, and by how much).

    $PY scripts/radiance/skymatrix.py [--mf 1 2 4] [--variants]
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from common import EFFICACY, ROOT, radiance_env, run  # noqa: E402

LAT, LON_WEST, TZ_WEST = 41.98, 87.92, 90.0
# (label, month, day, hour, dni, dhi): local standard time, W/m².
HOURS = [
    ("clear, high sun", 6, 21, 12.5, 850.0, 95.0),
    ("clear, spring", 3, 21, 10.5, 780.0, 70.0),
    ("intermediate", 4, 15, 14.5, 420.0, 210.0),
    ("hazy", 7, 15, 16.5, 250.0, 260.0),
    ("overcast", 11, 10, 11.5, 0.0, 140.0),
    ("thin overcast", 1, 20, 12.5, 40.0, 120.0),
    ("low sun", 12, 21, 8.5, 310.0, 35.0),
    ("twilight", 12, 21, 7.0, 0.0, 6.0),
    ("dark", 1, 1, 0.5, 0.0, 0.0),
]


def wea_text() -> str:
    head = (f"place Chicago-like\nlatitude {LAT}\nlongitude {LON_WEST}\ntime_zone {TZ_WEST}\n"
            "site_elevation 200\nweather_data_file_units 1\n")
    return head + "".join(f"{m} {d} {h} {dni} {dhi}\n" for _, m, d, h, dni, dhi in HOURS)


def gendaymtx(wea: Path, mf: int, extra: list[str]) -> np.ndarray:
    """(hours, patches) green channel of ``gendaymtx -O0`` (rows of its output are patches)."""
    bin_dir, env = radiance_env()
    cmd = [bin_dir / "gendaymtx", "-m", str(mf), "-O0", "-h", "-of", "-c", "1", "1", "1",
           *extra, wea]
    out = subprocess.run(cmd, capture_output=True, env=env, check=True).stdout
    vals = np.frombuffer(out, dtype=np.float32).reshape(-1, len(HOURS), 3)
    return vals[:, :, 1].T.astype(np.float64)


def tool(mf: int, flags: list[str]) -> np.ndarray:
    """(hours, patches) of the example, with the separate sun's lux dropped."""
    target = Path(os.environ.get("CARGO_TARGET_DIR", ROOT / "target"))
    exe = target / "release" / "examples" / "skymatrix"
    lines = "".join(f"{m} {d} {h} {dni} {dhi}\n" for _, m, d, h, dni, dhi in HOURS)
    args = [str(exe), str(LAT), str(-LON_WEST), str(-TZ_WEST / 15.0), str(mf), *flags]
    out = subprocess.run(args, input=lines, capture_output=True, text=True, check=True).stdout
    rows = np.array([[float(x) for x in line.split()] for line in out.splitlines()])
    return rows[:, :-1] if "separate" in flags else rows


def weights(mf: int) -> np.ndarray:
    """sin(centre altitude) × solid angle of the sky patches, gendaymtx's ``rh_init``."""
    alpha = (np.pi / 2) / (7 * mf + 0.5)
    w = []
    for r in range(7 * mf):
        n = [30, 30, 24, 24, 18, 12, 6][r // mf] * mf
        dom = 2 * np.pi * (np.sin(alpha * (r + 1)) - np.sin(alpha * r)) / n
        w += [np.sin(alpha * (r + 0.5)) * dom] * n
    w.append(2 * np.pi * (1 - np.cos(alpha / 2)))
    return np.array(w)


def compare(ours: np.ndarray, theirs: np.ndarray, mf: int) -> list[tuple]:
    """Per hour: (max %, mean %, ground %, E_h ours, E_h theirs) over the sky patches."""
    w = weights(mf)
    rows = []
    for h in range(len(HOURS)):
        a, b = ours[h], theirs[h]
        sky_a, sky_b = a[1:], b[1:]
        if b.max() == 0.0:
            rows.append((0.0, 0.0, 0.0, sky_a @ w * EFFICACY, 0.0, a.max() == 0.0))
            continue
        rel = np.abs(sky_a - sky_b) / np.maximum(sky_b, 1e-30) * 100
        ground = abs(a[0] - b[0]) / b[0] * 100
        rows.append((rel.max(), rel.mean(), ground, sky_a @ w * EFFICACY, sky_b @ w * EFFICACY,
                     True))
    return rows


def table(title: str, mf: int, rows: list[tuple]) -> None:
    print(f"\n{title}, MF {mf} ({len(weights(mf)) + 1} rows)\n")
    print("| hour | max % | mean % | ground % | E_h tool (lux) | E_h gendaymtx (lux) |")
    print("|---|---:|---:|---:|---:|---:|")
    for (label, m, d, h, dni, dhi), r in zip(HOURS, rows):
        name = f"{label} ({m}/{d} {h} h, {dni:g}/{dhi:g})"
        note = "" if r[5] else " (tool not dark!)"
        print(f"| {name}{note} | {r[0]:.1e} | {r[1]:.1e} | {r[2]:.1e} | {r[3]:.0f} | {r[4]:.0f} |")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--mf", type=int, nargs="+", default=[1, 2, 4])
    ap.add_argument("--variants", action="store_true",
                    help="also the tool's integrated patches and NOAA sun against gendaymtx")
    args = ap.parse_args()
    run(["cargo", "build", "--release", "--quiet", "--example", "skymatrix"], cwd=ROOT)
    with tempfile.TemporaryDirectory() as tmp:
        wea = Path(tmp) / "hours.wea"
        wea.write_text(wea_text())
        for mf in args.mf:
            table("Sky and sun in the patches (`gendaymtx` default)", mf,
                  compare(tool(mf, []), gendaymtx(wea, mf, []), mf))
            sky_only = gendaymtx(wea, mf, ["-s"])
            table("Sky only (`gendaymtx -s`; the tool's sun kept apart)", mf,
                  compare(tool(mf, ["separate"]), sky_only, mf))
            if args.variants:
                table("Variant: the tool's integrated patches against `gendaymtx -s`", mf,
                      compare(tool(mf, ["separate", "integrated"]), sky_only, mf))
                table("Variant: the tool's NOAA sun against `gendaymtx -s`", mf,
                      compare(tool(mf, ["separate", "noaa"]), sky_only, mf))


if __name__ == "__main__":
    main()
