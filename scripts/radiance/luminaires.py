#!/usr/bin/env python3
"""Check luminaires (``--luminaires``) against Radiance: work-plane illuminance in a furnished
room lit only by photometric luminaires.

1. The room and its lights are written here (``--out DIR``): a 6 x 3 x 4.5 m room (Y up) with a
   table, a cabinet 10 cm off a wall and a low shelf; three IES files (an asymmetric Type C
   downlight, a narrow rotationally symmetric spot, a near-isotropic pendant); a schedule with a
   row of downlights (``count`` and ``step``), a second row at a light-loss factor of 0.8, the
   spot aimed at a wall point and spun, and the pendant over the table.
2. The tool: ``radiosity solve ROOM --luminaires SCHEDULE --grid 0.8,0.5 --out DIR/solve``.
3. Radiance at the same sensors: the room written by ``objrad.py`` from the tool's own
   materials; each luminaire by ``ies2rad -dm -i 0.01`` (with ``--opening W,L,H``, the webs carry
   that luminous opening and ``ies2rad`` makes its area source instead, made ``illum``; the
   pendant is then left out, since Radiance's openings shade each other) (an ``illum`` sphere of 1 cm at the
   photometric centre, Radiance's ``source.cal`` distribution: 0 deg horizontal along +X, 90 along
   +Y, the nadir -Z, the same local frame as the tool's), multiplied by its scale, tinted, then
   turned and moved by ``xform`` into the frame the tool reports (``radiosity info --json
   --luminaires``: position, aim, C0); ``rtrace -I`` with no ambient cache, ``--repeat`` runs.
4. Compared: mean and median sensor error, the grids' mean / min / U0, both CPU times.

    PY=.venv-radiance/bin/python
    $PY scripts/radiance/luminaires.py --out out/luminaires

Writes DIR/report.json; exit 1 only when a step fails to run.
"""

from __future__ import annotations

import argparse
import csv
import json
import math
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import objrad  # noqa: E402
from common import (BINARY_HELP, children_cpu, oconv, radiance_env, radiosity_binary,  # noqa: E402
                    ray_lines, rtrace_rgb, run)

EFFICACY = 179.0
PHOTOPIC = np.array([0.265, 0.670, 0.065])


# The luminous opening every web is written with (width, length), metres; (0, 0): points.
OPENING = (0.0, 0.0, 0.0)


def ies(name: str, vertical, horizontal, f) -> str:
    """An LM-63-2002 file of absolute candela f(C, gamma) over the given angles."""
    w, l, h = OPENING
    lines = ["IESNA:LM-63-2002", f"[TEST] {name}", "[MANUFAC] radiosity test webs", "TILT=NONE",
             f"1 -1 1 {len(vertical)} {len(horizontal)} 1 2 {w:g} {l:g} {h:g}", "1 1 30",
             " ".join(f"{v:g}" for v in vertical), " ".join(f"{h:g}" for h in horizontal)]
    for c in horizontal:
        lines.append(" ".join(f"{f(c, g):.4f}" for g in vertical))
    return "\n".join(lines) + "\n"


def write_webs(out: Path):
    steps = lambda lo, hi, d: [lo + d * k for k in range(int(round((hi - lo) / d)) + 1)]  # noqa
    cos = lambda deg: math.cos(math.radians(deg))  # noqa: E731
    (out / "downlight.ies").write_text(ies(
        "asymmetric downlight", steps(0, 90, 5), steps(0, 360, 30),
        lambda c, g: 900 * cos(g) ** 1.5 * (1 + 0.4 * cos(c))))
    (out / "spot.ies").write_text(ies(
        "narrow spot", steps(0, 90, 2.5), [0],
        lambda c, g: 4000 * max(cos(g), 0) ** 30 + 20 * max(cos(g), 0)))
    (out / "pendant.ies").write_text(ies(
        "pendant", steps(0, 180, 10), [0],
        # A flat opening (ies2rad's downward rectangle) cannot send light up: with one, the
        # pendant's upper half is dark in both programs.
        lambda c, g: 300 + 200 * cos(g) if g <= 90 or not any(OPENING) or OPENING[2] > 0 else 0))


def box(verts, faces, lo, hi, mat, inward=False):
    """An axis-aligned box's six faces (outward unless ``inward``)."""
    (x0, y0, z0), (x1, y1, z1) = lo, hi
    quads = [((x0, y0, z0), (x0, y0, z1), (x0, y1, z1), (x0, y1, z0)),
             ((x1, y0, z0), (x1, y1, z0), (x1, y1, z1), (x1, y0, z1)),
             ((x0, y0, z0), (x1, y0, z0), (x1, y0, z1), (x0, y0, z1)),
             ((x0, y1, z0), (x0, y1, z1), (x1, y1, z1), (x1, y1, z0)),
             ((x0, y0, z0), (x0, y1, z0), (x1, y1, z0), (x1, y0, z0)),
             ((x0, y0, z1), (x1, y0, z1), (x1, y1, z1), (x0, y1, z1))]
    for k, q in enumerate(quads):
        m = mat[k] if isinstance(mat, list) else mat
        q = q[::-1] if inward else q
        faces.append((m, [len(verts) + i + 1 for i in range(4)]))
        verts.extend(q)


def write_room(out: Path) -> Path:
    verts, faces = [], []
    box(verts, faces, (0, 0, 0), (6, 3, 4.5),
        ["wall", "wall", "floor", "ceiling", "wall", "wall"], inward=True)
    box(verts, faces, (2.2, 0.7, 1.8), (3.8, 0.75, 2.7), "table")
    for x, z in ((2.3, 1.9), (3.65, 1.9), (2.3, 2.55), (3.65, 2.55)):
        box(verts, faces, (x, 0, z), (x + 0.05, 0.7, z + 0.05), "metal")
    box(verts, faces, (0.1, 0, 0.3), (0.7, 1.3, 0.8), "metal")        # cabinet, 10 cm off x=0
    box(verts, faces, (4.2, 0, 4.1), (5.8, 0.9, 4.45), "shelf")      # low shelf at the back
    (out / "room.mtl").write_text(
        "newmtl wall\nKd 0.65 0.63 0.6\nnewmtl floor\nKd 0.3 0.25 0.2\n"
        "newmtl ceiling\nKd 0.82 0.82 0.82\nnewmtl table\nKd 0.55 0.45 0.35\n"
        "newmtl metal\nKd 0.5 0.5 0.52\nnewmtl shelf\nKd 0.7 0.7 0.68\n")
    lines = ["mtllib room.mtl"] + [f"v {x:g} {y:g} {z:g}" for x, y, z in verts]
    current = None
    for m, idx in faces:
        if m != current:
            lines.append(f"usemtl {m}")
            current = m
        lines.append("f " + " ".join(map(str, idx)))
    path = out / "room.obj"
    path.write_text("\n".join(lines) + "\n")
    return path


def write_schedule(out: Path) -> Path:
    rows = ["name,file,x,y,z,count,step_x,step_y,step_z,llf,aim_x,aim_y,aim_z,spin,r,g,b",
            "front,downlight.ies,1.5,2.95,1.2,3,1.5,0,0,1,,,,0,,,",
            "back,downlight.ies,1.5,2.95,3.3,3,1.5,0,0,0.8,,,,90,1,0.9,0.75",
            "spot,spot.ies,5.5,2.8,1,1,,,,1,0,1.4,3,20,,,",
            "pendant,pendant.ies,3,2.1,2.25,1,,,,1,,,,0,,,"]
    if any(OPENING):
        # In Radiance an opening is a surface that shades the other luminaires (the pendant's
        # hides a downlight from the sensors beyond it); in the tool a luminaire has no body.
        # With openings the pendant is left out, so that both see the same lights.
        rows.pop()
    path = out / "lights.csv"
    path.write_text("\n".join(rows) + "\n")
    return path


def euler_xyz(r: np.ndarray):
    """(a, b, c), degrees, with r = Rx(c)·Ry(b)·Rz(a): ``xform -rz a -ry b -rx c``."""
    b = math.asin(max(-1.0, min(1.0, r[0, 2])))
    a = math.atan2(-r[0, 1], r[0, 0])
    c = math.atan2(-r[1, 2], r[2, 2])
    return tuple(math.degrees(v) for v in (a, b, c))


def luminaire_rad(bin_dir, env, lum: dict, k: int, out: Path) -> str:
    """One luminaire as Radiance text: ies2rad's output, scaled and tinted, turned and moved."""
    stem = out / f"lum{k}"
    # Points as 1 cm spheres; webs with an opening as ies2rad makes them (area sources).
    sphere = [] if any(OPENING) else ["-i", "0.01"]
    res = subprocess.run([bin_dir / "ies2rad", "-dm", *sphere, "-m", f"{lum['scale']:.9g}",
                          "-o", str(stem), lum["file"]], capture_output=True, text=True, env=env)
    if res.returncode != 0:
        sys.exit(f"ies2rad failed: {res.stderr}")
    text = stem.with_suffix(".rad").read_text()
    rgb = " ".join(f"{c:.9g}" for c in lum["colour"])
    text = text.replace("3 1 1 1", f"3 {rgb}", 1)
    # An opening as an `illum`, seen by direct light only: the tool's luminaires have no
    # surface, so the reference's must not shade the ceiling or soak up light that meets it.
    text = text.replace(f"lum{k}_dist' light ", f"lum{k}_dist' illum ")
    stem.with_suffix(".rad").write_text(text)
    aim, c0 = np.array(lum["aim"]), np.array(lum["c0"])
    c90 = np.cross(-aim, c0)
    r = np.stack([c0, c90, -aim], axis=1)  # local -> world, columns: local X, Y, Z
    a, b, c = euler_xyz(r)
    x, y, z = lum["position"]
    return (f"!xform -rz {a:.9g} -ry {b:.9g} -rx {c:.9g} -t {x:.9g} {y:.9g} {z:.9g} "
            f"{stem.with_suffix('.rad')}\n")


def read_grid(path: Path):
    with open(path) as f:
        rows = list(csv.DictReader(f))
    pts = np.array([[float(r[k]) for k in ("x", "y", "z")] for r in rows])
    nrm = np.array([[float(r[k]) for k in ("nx", "ny", "nz")] for r in rows])
    lux = np.array([float(r["lux"]) for r in rows])
    return pts, nrm, lux


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", type=Path, required=True)
    ap.add_argument("--radiosity", help=BINARY_HELP)
    ap.add_argument("--repeat", type=int, default=2, help="Radiance runs (default 2)")
    ap.add_argument("--ab", type=int, default=8)
    ap.add_argument("--ad", type=int, default=2048)
    ap.add_argument("--procs", type=int, default=2)
    ap.add_argument("--opening", default="0,0,0", metavar="W,L,H",
                    help="write every web with a luminous opening W x L x H metres (ies2rad then "
                         "makes area sources: a rectangle lit downward only for H 0, a box lit on "
                         "every side otherwise; the tool spreads the web over its footprint); "
                         "default points")
    args = ap.parse_args()
    global OPENING
    OPENING = tuple(float(x) for x in (args.opening.split(",") + ["0", "0"])[:3])
    out = args.out.resolve()
    out.mkdir(parents=True, exist_ok=True)
    binary = radiosity_binary(args.radiosity, must_exist=True)
    write_webs(out)
    room, schedule = write_room(out), write_schedule(out)

    c_tool = children_cpu()
    run([binary, "solve", room, "--luminaires", schedule, "--grid", "0.8,0.5", "--elements",
         "off", "--out", out / "solve", "--quiet"])
    tool_cpu = children_cpu() - c_tool
    info = json.loads(run([binary, "info", "--json", room, "--luminaires", schedule]).stdout)
    pts, nrm, tool_lux = read_grid(out / "solve" / "grid.csv")

    bin_dir, env = radiance_env()
    model = objrad.read_obj(room, binary)
    objrad.write_rad(model, out / "room.rad")
    lums = "".join(luminaire_rad(bin_dir, env, lum, k, out)
                   for k, lum in enumerate(info["luminaires"]))
    (out / "lights.rad").write_text(lums)
    octree = oconv(bin_dir, env, [out / "room.rad", out / "lights.rad"], out / "scene.oct")
    opts = ["-h", "-I+", "-n", str(args.procs), "-ab", str(args.ab), "-ad", str(args.ad),
            "-as", "0", "-aa", "0", "-lr", "-12", "-lw", "1e-5", "-dt", "0", "-dc", "1",
            "-ds", "0.02", "-dj", "0", "-dr", "0", "-u+"]
    runs, rad_cpu = [], 0.0
    rng = np.random.default_rng(1)
    for _ in range(args.repeat):
        order = rng.permutation(len(pts))
        c0, t0 = children_cpu(), time.perf_counter()
        res = subprocess.run([bin_dir / "rtrace", *opts, octree],
                             input=ray_lines(pts[order], nrm[order]), capture_output=True,
                             text=True, env=env)
        if res.returncode != 0:
            sys.exit(f"rtrace failed: {res.stderr}")
        rad_cpu += children_cpu() - c0
        lux = np.empty(len(order))
        lux[order] = EFFICACY * (rtrace_rgb(res.stdout, len(order)) @ PHOTOPIC)
        runs.append(lux)
    runs = np.array(runs)
    ref = runs.mean(axis=0)
    rel = np.abs(tool_lux - ref) / np.maximum(ref, 1e-9)
    noise = (np.abs(runs[0] - runs[-1]).sum() / 2 / np.sqrt(len(runs)) / ref.sum()
             if len(runs) > 1 else float("nan"))
    fig = {
        "sensors": int(len(ref)),
        "mean_error": float(np.abs(tool_lux - ref).sum() / ref.sum()),
        "signed_error": float((tool_lux - ref).sum() / ref.sum()),
        "median_sensor_error": float(np.median(rel)),
        "worst_sensor_error": float(rel.max()),
        "radiance_noise": float(noise),
        "tool": {"mean": float(tool_lux.mean()), "min": float(tool_lux.min()),
                 "u0": float(tool_lux.min() / tool_lux.mean())},
        "radiance": {"mean": float(ref.mean()), "min": float(ref.min()),
                     "u0": float(ref.min() / ref.mean())},
        "tool_cpu_seconds": tool_cpu,
        "radiance_cpu_seconds_per_run": rad_cpu / len(runs),
        "luminaires": [{k: lum[k] for k in ("name", "lumens")} for lum in info["luminaires"]],
    }
    (out / "report.json").write_text(json.dumps(fig, indent=2))
    print(f"{fig['sensors']} sensors: mean error {100 * fig['mean_error']:.2f} % "
          f"(signed {100 * fig['signed_error']:+.2f} %), median {100 * fig['median_sensor_error']:.2f} %, "
          f"worst {100 * fig['worst_sensor_error']:.1f} %; Radiance's noise {100 * noise:.2f} %")
    print(f"  tool: mean {fig['tool']['mean']:.1f} lux, min {fig['tool']['min']:.1f}, U0 "
          f"{fig['tool']['u0']:.3f}; Radiance: mean {fig['radiance']['mean']:.1f}, min "
          f"{fig['radiance']['min']:.1f}, U0 {fig['radiance']['u0']:.3f}")
    print(f"  CPU s: tool {tool_cpu:.1f} (whole solve), Radiance {fig['radiance_cpu_seconds_per_run']:.1f} a run")


if __name__ == "__main__":
    main()
