#!/usr/bin/env python3
"""Radiance's reference for annual daylight: a year of hourly illuminance at sensors, and the LM-83 metrics.

Runs by hand, not from ``cargo test``. Given a model (OBJ), a weather file (EPW or ``.wea``) and
sensors, it computes Radiance's hourly illuminance at every sensor for the 8,760 hours of the
year by the two-phase method (daylight coefficients x sky matrix), with the direct sun traced
exactly per hour, then the annual metrics in numpy (independently of the tool), and can compare
the tool's annual output with it.

1. **Weather**: an EPW is turned into a ``.wea`` by Radiance's own ``epw2wea`` (each hour at its
   centre in local standard time: EPW hour h is h - 0.5); a ``.wea`` is used as it is.
2. **Sky matrices** (``gendaymtx``, visible radiance ``-O0``, a white sky ``-c 1 1 1``, the
   ground ``-g RHO``, Reinhart subdivision ``-m MF``, default 1: Tregenza's 145 patches plus
   the ground, ground first, the tool's patch order):
   ``gendaymtx -m MF -c 1 1 1 -O0 -g RHO RHO RHO -of W.wea > sky.smx`` (sky and sun in the
   patches) and ``gendaymtx -m MF -c 1 1 1 -O0 -g RHO RHO RHO -of -d -D suns.rad -M suns.txt
   W.wea > sun.smx`` (the sun alone in the patches, and every hour's sun as a 0.533 deg
   ``light`` source at its exact position, named ``solarN`` with N the minutes from 1 Jan 0:00
   to the hour's centre). The
   sky matrix is RGB radiance in W/sr/m^2 of visible light (Radiance's 179 lm/W): the hourly
   values are turned into lux at the end, lux = 179 (0.265 R + 0.670 G + 0.065 B) (the tool's
   and Radiance's photopic weights). ``-O0`` rather than ``-O1`` (solar radiance) because the
   quantity is illuminance; with the white sky the three channels are equal for grey models.
3. **The model** (``objrad.py``, the tool's own materials from ``radiosity info --json``; glass
   as ``trans``) rotated into ``gendaymtx``'s frame (x east, y north, z up) from ``--zenith`` and
   ``--north`` (as ``daylight.py``).
4. **Daylight coefficients** at the sensors, per sky patch, with the sky a ``glow`` of radiance 1
   over the whole sphere (``skyglow source skydome 0 0 4 0 0 1 360``), binned the way
   ``gendaymtx`` orders its rows (``reinhart.cal``: bin 0 the ground, then the sky patches):
   ``rcontrib -h -faf -I+ -n P -ab AB -ad AD -as 0 -aa 0 -lr -12 -lw 0.5/AD -dt 0 -dc 1 -ds 0.02
   -dj 0 -dr 0 -e MF:MF -f reinhart.cal -b rbin -bn Nrbins -m skyglow sky.oct`` (the total, every
   bounce) and the same with ``-ab 1`` (the sky seen directly, through glass only: no bounce).
5. **The direct sun**, exact per hour: ``rcontrib -h -faf -I+ -V+ -ab 0 -dt 0 -dc 1 -ds 0 -dj 0
   -dr 0 -M suns.txt sun.oct`` on the model with the year's suns from ``gendaymtx -D`` (each a
   source, at the sun's true position of that hour, not a bin): shadow rays only, through glass
   with its transmittance, no reflection (IES LM-83's "direct sunlight"). A sun at or below
   the horizon gives nothing. This is the five-phase method's sun, but with every hour's own
   sun instead of MF 6's 5,185 binned positions: exact in position, and cheap (4,400 shadow
   rays per sensor).
6. **The hourly illuminance** (``dctimestep``): with DC the total coefficients, D the direct ones,
   ``dctimestep DC sky.smx - dctimestep D sun.smx + the exact direct sun``: the sun's light
   that reaches a sensor after at least one reflection comes from its share of the patches
   (smooth), the sun seen directly is the exact one (not spread over a patch 12 deg wide).
   The direct sun alone is ``radiance-direct-sun.npy``.
7. **Noise**: ``--repeat`` (default 2) runs of both coefficient runs, the sensors in a new
   (seeded) random order each run, so each run's Monte Carlo is independent (as
   ``daylight.py``); the reference is their mean. Noise by leave-one-out over the sensor-hours
   above 100 lux (:func:`noise`): mean, median and aggregate relative error of one run, and of
   the reference (divided by sqrt(k)); and the metrics of each run (their spread). The direct
   sun has no noise (one shadow ray to the sun's centre).
8. **Metrics** (numpy, :func:`metrics`): occupied hours are those whose centre lies in
   [8, 18) local standard time (``--occupied``; no daylight saving, as IES LM-83-12), every day:
   3,650 hours. DA300 per sensor: % of occupied hours with E >= 300 lux. sDA300/50%: % of the
   sensors (equal weights) with DA300 >= 50 %. ASE1000,250h: % of the sensors whose direct sun
   is >= 1000 lux for more than 250 occupied hours. UDI: % of occupied hours below 100 lux
   (fell short), in [100, 3000] (useful), above 3000 (exceeded), averaged over the sensors.
   Sensors marked ``indoor`` 0 in a tool ``grid.csv`` are left out of the metrics.

Settings (``--ab 12 --ad 65536``, ``-lw 0.5/ad``, no ambient cache, 2 runs by default),
measured on the side-lit room (24 sensors, Chicago TMY3): the mean occupied illuminance is
3,141 lux at ``-ab 8``, 3,153 at ``-ab 12`` and at ``-ab 16`` (``-lw`` at 0.5/ad makes
Russian roulette, so a deeper ``-ab`` costs nothing); the reference's noise (mean relative
error of the mean of 2 runs) is 0.80 % at ``-ad 65536`` (27 CPU s) and 0.63 % at 131072 (53 CPU
s), against 1.8 % at 16384 and 3.9 % at 4096. Hours checked against ``gendaylit`` + ``rtrace
-ab 12``: the room's mean within 0.2-2 %, the direct sun at every sensor within 0.02 %.

Sensors: ``--sensors CSV`` (the tool's ``grid.csv`` or any CSV with x,y,z,nx,ny,nz) or
``--grid HEIGHT,SPACING`` (``daylight.py``'s ``make_grid`` rule: a lattice over the faces of a
``floor`` material, facing up; points inside solids dropped).

Outputs in ``--out DIR``: ``radiance-illuminance.npy`` and ``radiance-direct-sun.npy`` (float32,
8760 hours x sensors, lux, 0 at night), ``radiance-illuminance-runs.npy`` (runs x hours x
sensors), ``radiance-hours.csv`` (``row,hour_of_year,month,day,hour``: hour_of_year counted from
0 at 1 Jan 0:00-1:00, hour the centre in local standard time, 0.5 .. 23.5), ``sensors.csv``
(x,y,z,nx,ny,nz in the model's frame, with DA300, ASE hours and UDI per sensor),
``report.json`` (settings, commands, CPU and wall seconds of every Radiance step, noise,
metrics), and the Radiance files (``weather.wea``, ``*.smx``, ``*.rad``, ``*.oct``).

**Comparison** (``--compare TOOL_DIR``): the tool's annual output, by contract
``TOOL_DIR/grid.csv`` (the sensors, in column order), ``TOOL_DIR/annual/hours.csv``
(``row,hour_of_year,month,day,hour``), ``TOOL_DIR/annual/illuminance.npy`` and
``TOOL_DIR/annual/direct_sun.npy`` (float32, rows = the hours listed, columns = sensors), its
CPU seconds from ``TOOL_DIR/summary.json`` (``cpu_seconds``: ``total``, or the sum of its
numbers) or ``--tool-cpu``. Rows are aligned by hour_of_year (checked against month, day and
hour; a 1-based hour_of_year is recognised), so a tool that lists only daylit hours compares:
the hours it leaves out count as 0 lux. Reported (``DIR/compare.json``, printed): hourly
illuminance relative error over the sensor-hours where the reference is above 100 lux (mean:
the bar, <= 5 %; median; aggregate sum |d| / sum ref, every sensor an equal area), sDA and ASE
differences in points of area (bars 2), the UDI bands' differences in points (bar 3), and both
CPU times. ``--as-tool DIR2`` writes a reference in the tool's layout (only its daylit hours),
to test the comparison on a second Radiance run (its errors are then Radiance's noise).

    PY=.venv-radiance/bin/python
    EPW=/work/shared/data/weather/USA_IL_Chicago-OHare.Intl.AP.725300_TMY3.epw
    $PY scripts/radiance/daylit.py --out out/daylit
    nice $PY scripts/radiance/annual.py out/daylit/sidelit.obj --weather $EPW \\
        --grid 0.8,1.0 --out out/annual/sidelit                    # the reference
    nice $PY scripts/radiance/annual.py out/daylit/sidelit.obj --weather $EPW \\
        --sensors out/annual/sidelit/sensors.csv --seed 7 --out out/annual/sidelit-b \\
        --as-tool out/annual/fake-tool                             # a second run as "the tool"
    $PY scripts/radiance/annual.py --out out/annual/sidelit --compare out/annual/fake-tool
    $PY scripts/radiance/annual.py --table out/annual/*/compare.json   # a Markdown table

Exit code 1 only when a step fails to run (the figures never make it fail).
"""

from __future__ import annotations

import argparse
import csv
import json
import math
import re
import shlex
import subprocess
import sys
import time
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import daylight  # noqa: E402
import objrad  # noqa: E402
from common import (BINARY_HELP, EFFICACY, PHOTOPIC, ROOT, children_cpu, oconv,  # noqa: E402
                    radiance_env, radiosity_binary, ray_lines)

HOURS_PER_YEAR = 8760
MONTH_DAYS = (31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31)
LIT_LUX = 100.0  # sensor-hours compared: the reference above this
BARS = {"hourly_mean_relative_error": 0.05, "sda_points": 2.0, "ase_points": 2.0,
        "udi_points": 3.0}
VERSION = "pyradiance 1.3.1 (RADIANCE 6.0a)"


# --------------------------------------------------------------------------------------------
# Running Radiance, timed.


@dataclass
class Step:
    """One Radiance process: its command, wall and CPU seconds."""

    name: str
    command: str
    wall_seconds: float
    cpu_seconds: float


@dataclass
class Runner:
    """Radiance's binaries and environment; every process it runs is timed into ``steps``."""

    workdir: Path
    bin: Path = field(init=False)
    env: dict = field(init=False)
    steps: list = field(default_factory=list)

    def __post_init__(self):
        self.bin, self.env = radiance_env()

    def __call__(self, name: str, cmd: list, stdin: bytes | None = None,
                 stdout_path: Path | None = None) -> bytes:
        """Run ``cmd`` (its first word a Radiance binary's name) in the work folder; its stdout
        as bytes (or into ``stdout_path``); stops with its stderr when it fails."""
        full = [str(self.bin / cmd[0]), *map(str, cmd[1:])]
        t0, c0 = time.perf_counter(), children_cpu()
        if stdout_path is not None:
            with open(stdout_path, "wb") as f:
                res = subprocess.run(full, input=stdin, stdout=f, stderr=subprocess.PIPE,
                                     env=self.env, cwd=self.workdir)
            out = b""
        else:
            res = subprocess.run(full, input=stdin, capture_output=True, env=self.env,
                                 cwd=self.workdir)
            out = res.stdout
        self.steps.append(Step(name, shlex.join(map(str, cmd)), time.perf_counter() - t0,
                               children_cpu() - c0))
        if res.returncode != 0:
            sys.exit(f"failed: {shlex.join(map(str, cmd))}\n{res.stderr.decode()}")
        return out

    def oconv(self, files: list, octree: Path) -> Path:
        """``common.oconv``, timed as a step."""
        t0, c0 = time.perf_counter(), children_cpu()
        oconv(self.bin, self.env, files, octree)
        self.steps.append(Step("oconv", f"oconv -f {' '.join(Path(f).name for f in files)} > "
                               f"{octree.name}", time.perf_counter() - t0, children_cpu() - c0))
        return octree

    def seconds(self) -> dict:
        """CPU and wall seconds per kind of step (the name up to a ``#``) and in total."""
        cpu, wall = {}, {}
        for s in self.steps:
            k = s.name.split("#")[0]
            cpu[k] = cpu.get(k, 0.0) + s.cpu_seconds
            wall[k] = wall.get(k, 0.0) + s.wall_seconds
        cpu["total"] = sum(s.cpu_seconds for s in self.steps)
        wall["total"] = sum(s.wall_seconds for s in self.steps)
        return {"cpu": cpu, "wall": wall}


def read_matrix(data: bytes) -> np.ndarray:
    """A Radiance matrix (header with NROWS, NCOLS, NCOMP, FORMAT=float) as (rows, cols, comp)."""
    end = data.find(b"\n\n")
    if not data.startswith(b"#?RADIANCE") or end < 0:
        sys.exit("not a Radiance matrix (no header)")
    head = data[:end].decode(errors="replace")
    kv = dict(re.findall(r"^(\w+)=\s*(\S+)", head, flags=re.MULTILINE))
    if kv.get("FORMAT") != "float":
        sys.exit(f"expected FORMAT=float, got {kv.get('FORMAT')}")
    shape = (int(kv["NROWS"]), int(kv["NCOLS"]), int(kv.get("NCOMP", 3)))
    vals = np.frombuffer(data[end + 2:], dtype="<f4")
    if vals.size != math.prod(shape):
        sys.exit(f"matrix holds {vals.size} numbers for {shape}")
    return vals.reshape(shape)


def write_matrix(path: Path, m: np.ndarray):
    """(rows, cols, 3) as a Radiance float matrix (dctimestep's input)."""
    head = (f"#?RADIANCE\nNROWS={m.shape[0]}\nNCOLS={m.shape[1]}\nNCOMP={m.shape[2]}\n"
            "BigEndian=0\nFORMAT=float\n\n")
    with open(path, "wb") as f:
        f.write(head.encode())
        f.write(np.ascontiguousarray(m, dtype="<f4").tobytes())


def to_lux(rgb: np.ndarray) -> np.ndarray:
    """Visible irradiance RGB (W/m^2, last axis) -> lux."""
    return EFFICACY * (rgb @ PHOTOPIC)


# --------------------------------------------------------------------------------------------
# Weather and hours.


@dataclass
class Weather:
    """A ``.wea``: its header and its rows (month, day, hour centre, DNI, DHI)."""

    path: Path
    header: dict
    rows: np.ndarray  # (n, 5)

    @property
    def hour_of_year(self) -> np.ndarray:
        return hour_of_year(self.rows[:, 0], self.rows[:, 1], self.rows[:, 2])


def hour_of_year(month, day, hour) -> np.ndarray:
    """0 for 1 Jan 0:00-1:00 ... 8759 (no leap day)."""
    starts = np.concatenate([[0], np.cumsum(MONTH_DAYS)[:-1]])
    m = np.asarray(month, dtype=int)
    doy = starts[m - 1] + np.asarray(day, dtype=int) - 1
    return (doy * 24 + np.floor(np.asarray(hour, dtype=float))).astype(int)


def year_hours():
    """(month, day, hour centre) of the 8,760 hours of a year without a leap day."""
    out = []
    for m, nd in enumerate(MONTH_DAYS, start=1):
        for d in range(1, nd + 1):
            for h in range(24):
                out.append((m, d, h + 0.5))
    return np.array(out)


def make_wea(weather: Path, run: Runner) -> Path:
    """``weather.wea`` in the work folder: ``epw2wea`` for an EPW, a copy of a ``.wea``."""
    dest = run.workdir / "weather.wea"
    if weather.suffix.lower() == ".epw":
        run("epw2wea", ["epw2wea", weather.resolve(), dest.name])
    else:
        dest.write_text(weather.read_text())
    return dest


def read_wea(path: Path) -> Weather:
    header, rows = {}, []
    for line in path.read_text().splitlines():
        parts = line.split()
        if not parts:
            continue
        if re.fullmatch(r"[A-Za-z_]+", parts[0]):
            header[parts[0]] = " ".join(parts[1:])
        else:
            rows.append([float(x) for x in parts[:5]])
    rows = np.array(rows)
    w = Weather(path, header, rows)
    hy = w.hour_of_year
    if ((rows[:, 0] == 2) & (rows[:, 1] == 29)).any():
        sys.exit(f"{path}: a leap day (29 Feb): not handled")
    if len(np.unique(hy)) != len(hy) or hy.min() < 0 or hy.max() >= HOURS_PER_YEAR:
        sys.exit(f"{path}: hours are not distinct hours of one year")
    if not np.allclose(rows[:, 2] % 1.0, 0.5):
        sys.exit(f"{path}: hours are not at the centre of the hour (x.5): hourly data only")
    return w


# --------------------------------------------------------------------------------------------
# Sensors.


def sensors_from_args(args, binary: Path, m: np.ndarray, workdir: Path):
    """(points, normals in the model frame, indoor mask, rule)."""
    if args.sensors:
        pts, nrm, _ = daylight.read_points_csv(args.sensors)
        indoor = np.ones(len(pts), dtype=bool)
        with open(args.sensors, newline="") as f:
            rows = list(csv.DictReader(f))
        if "indoor" in rows[0]:
            indoor = np.array([float(r["indoor"]) != 0 for r in rows])
        return pts, nrm, indoor, f"points from {args.sensors}"
    height, spacing = (float(x) for x in args.grid.split(","))
    model = objrad.read_obj(args.model.resolve(), binary)
    pts, nrm = daylight.make_grid(model, m, height, spacing, args.floor_material)
    # drop_inside wants a scene in the local frame and rtrace -os: a plain octree of the model.
    local = objrad.read_obj(args.model.resolve(), binary)
    normals = np.array([objrad.polygon_normal(local.vertices[f]) for f in local.faces])
    normals /= np.maximum(np.linalg.norm(normals, axis=1, keepdims=True), 1e-300)
    local.vertices = local.vertices @ m.T
    probe_dir = workdir / "probe"
    probe_dir.mkdir(exist_ok=True)
    objrad.write_rad(local, probe_dir / "scene.rad")
    bin_dir, env = radiance_env()
    octree = oconv(bin_dir, env, [probe_dir / "scene.rad"], probe_dir / "scene.oct")

    class Probe:
        def trace_names(self, octree, origins, dirs):
            res = subprocess.run([bin_dir / "rtrace", "-h", "-ab", "0", "-os", octree],
                                 input=ray_lines(origins, dirs), capture_output=True, text=True,
                                 env=env)
            if res.returncode != 0:
                sys.exit(f"rtrace failed: {res.stderr}")
            return [x.strip() for x in res.stdout.splitlines() if x.strip()]

    keep = daylight.drop_inside(Probe(), octree, local, pts @ m.T, normals @ m.T)
    rule = (f"work plane {height} m above faces of material /{args.floor_material}/ facing up, "
            f"lattice {spacing} m (daylight.py make_grid); {int((~keep).sum())} points inside "
            "solids dropped")
    return pts[keep], nrm[keep], np.ones(int(keep.sum()), dtype=bool), rule


def write_sensors(path: Path, pts, nrm, indoor, per_sensor: dict):
    cols = list(per_sensor)
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["x", "y", "z", "nx", "ny", "nz", "indoor", *cols])
        for i in range(len(pts)):
            w.writerow([f"{v:.6f}" for v in (*pts[i], *nrm[i])] + [int(indoor[i])]
                       + [f"{per_sensor[c][i]:.6g}" for c in cols])


# --------------------------------------------------------------------------------------------
# Radiance's annual run.


SKYGLOW = ("void glow skyglow\n0\n0\n4 1 1 1 0\n\n"
           "skyglow source skydome\n0\n0\n4 0 0 1 360\n")


def rcontrib_ambient(args, ab: int) -> list:
    lw = args.lw if args.lw is not None else 0.5 / args.ad
    return ["-ab", ab, "-ad", args.ad, "-as", 0, "-aa", 0, "-lr", -12, "-lw", f"{lw:.3g}",
            "-dt", 0, "-dc", 1, "-ds", 0.02, "-dj", 0, "-dr", 0]


def sky_coefficients(run: Runner, args, octree: Path, pts, nrm, ab: int, order, name: str):
    """(sensors, bins, 3) daylight coefficients: irradiance (W/m^2) per unit radiance of each
    patch (ground first), the sensors traced in ``order``."""
    cmd = ["rcontrib", "-h", "-faf", "-I+", "-n", args.procs, *rcontrib_ambient(args, ab),
           "-e", f"MF:{args.mf}", "-f", "reinhart.cal", "-b", "rbin", "-bn", "Nrbins",
           "-m", "skyglow", octree.name]
    out = run(name, cmd, stdin=ray_lines(pts[order], nrm[order]).encode())
    vals = np.frombuffer(out, dtype="<f4")
    nb = 144 * args.mf ** 2 + 2  # Reinhart's patches + the ground
    if vals.size != len(pts) * nb * 3:
        sys.exit(f"{name}: rcontrib gave {vals.size} numbers for {len(pts)} x {nb} x 3")
    dc = np.empty((len(pts), nb, 3), dtype=np.float32)
    dc[order] = vals.reshape(len(pts), nb, 3)
    return dc, " ".join(map(str, cmd))


def sun_positions(path: Path) -> dict:
    """``gendaymtx -D``'s suns: name -> (hour_of_year, radiance, direction)."""
    text = path.read_text()
    suns = {}
    for mt in re.finditer(r"void light (solar(\d+))\s+0\s+0\s+3 (\S+) \S+ \S+\s+"
                          r"\1 source \S+\s+0\s+0\s+4 (\S+) (\S+) (\S+) (\S+)", text):
        minutes = int(mt.group(2))
        suns[mt.group(1)] = (minutes // 60, float(mt.group(3)),
                             np.array([float(mt.group(k)) for k in (4, 5, 6)]))
    return suns


def direct_sun(run: Runner, args, model_rad: Path, pts, nrm, suns_rad: Path, mods: Path):
    """(hours, sensors) lux of the sun alone, seen directly (shadow rays, through glass), from
    every hour's own sun. Suns at or below the horizon are left out."""
    names = [x.strip() for x in mods.read_text().splitlines() if x.strip()]
    suns = sun_positions(suns_rad)
    if set(names) != set(suns):
        sys.exit(f"{suns_rad}: its suns and {mods} differ")
    up = [n for n in names if suns[n][2][2] > 0]
    kept = run.workdir / "suns-up.rad"
    with open(kept, "w") as f:
        for n in up:
            hour, rad, d = suns[n]
            f.write(f"void light {n}\n0\n0\n3 {rad:.6g} {rad:.6g} {rad:.6g}\n\n"
                    f"{n} source sun_{n}\n0\n0\n4 {d[0]:.9g} {d[1]:.9g} {d[2]:.9g} 0.5330\n\n")
    (run.workdir / "suns-up.txt").write_text("".join(n + "\n" for n in up))
    octree = run.oconv([kept, model_rad], run.workdir / "sun.oct")
    cmd = ["rcontrib", "-h", "-faf", "-I+", "-V+", "-n", args.procs, "-ab", 0, "-lr", -12,
           "-lw", "1e-9", "-dt", 0, "-dc", 1, "-ds", 0, "-dj", 0, "-dr", 0,
           "-M", run.workdir / "suns-up.txt", octree.name]
    out = run("rcontrib direct sun", cmd, stdin=ray_lines(pts, nrm).encode())
    vals = np.frombuffer(out, dtype="<f4")
    if vals.size != len(pts) * len(up) * 3:
        sys.exit(f"direct sun: rcontrib gave {vals.size} numbers for {len(pts)} x {len(up)} x 3")
    lux = to_lux(vals.reshape(len(pts), len(up), 3).astype(np.float64))  # (sensors, suns)
    hourly = np.zeros((HOURS_PER_YEAR, len(pts)))
    idx = np.array([suns[n][0] for n in up], dtype=int)
    if len(np.unique(idx)) != len(idx):
        sys.exit("gendaymtx -D: two suns in one hour")
    hourly[idx] = lux.T
    info = {"suns": len(names), "suns_above_horizon": len(up),
            "normal_illuminance_max_lux": float(max(
                (suns[n][1] for n in up), default=0.0) * sun_solid_angle() * EFFICACY),
            "rcontrib": " ".join(map(str, cmd))}
    return hourly, info


def sun_solid_angle() -> float:
    """gendaymtx's sun disc (0.533 degrees)."""
    return 2 * math.pi * (1 - math.cos(math.radians(0.533 / 2)))


def run_reference(args, out: Path):
    """Radiance's annual run; writes everything in ``out`` and returns the report."""
    binary = radiosity_binary(args.radiosity, must_exist=True)
    run = Runner(out)
    notes = []
    m = daylight.frame_matrix(daylight.parse_vec(args.zenith), daylight.parse_vec(args.north))

    wea_path = make_wea(args.weather, run)
    wea = read_wea(wea_path)
    if len(wea.rows) != HOURS_PER_YEAR:
        notes.append(f"the weather has {len(wea.rows)} hours: the others are 0 lux")
    g = f"{args.ground_reflectance:g}"
    sky_flags = ["-m", args.mf, "-c", 1, 1, 1, "-O0", "-g", g, g, g, "-of"]
    run("gendaymtx", ["gendaymtx", *sky_flags, wea_path.name], stdout_path=out / "sky.smx")
    run("gendaymtx", ["gendaymtx", *sky_flags, "-d", "-D", "suns.rad", "-M", "suns.txt",
                      wea_path.name], stdout_path=out / "sun.smx")
    sky = read_matrix((out / "sky.smx").read_bytes())
    if sky.shape[1] != len(wea.rows):
        sys.exit(f"gendaymtx gave {sky.shape[1]} hours for {len(wea.rows)} in the weather")

    pts, nrm, indoor, rule = sensors_from_args(args, binary, m, out)
    if len(pts) == 0:
        sys.exit("no sensors")
    pts_l, nrm_l = pts @ m.T, nrm @ m.T
    nrm_l /= np.linalg.norm(nrm_l, axis=1, keepdims=True)

    model = objrad.read_obj(args.model.resolve(), binary)
    model.vertices = model.vertices @ m.T
    notes += model.warnings
    model_rad = out / "model.rad"
    objrad.write_rad(model, model_rad)
    (out / "skyglow.rad").write_text(SKYGLOW)
    sky_oct = run.oconv([out / "skyglow.rad", model_rad], out / "sky.oct")

    # The direct sun: exact, no noise.
    sun_hourly, sun_info = direct_sun(run, args, model_rad, pts_l, nrm_l, out / "suns.rad",
                                      out / "suns.txt")

    rng = np.random.default_rng(args.seed)
    runs, cmds, through_patches = [], {}, []
    rows = wea.hour_of_year
    for k in range(args.repeat):
        order = rng.permutation(len(pts))
        dc, cmds["total"] = sky_coefficients(run, args, sky_oct, pts_l, nrm_l, args.ab, order,
                                             f"rcontrib total#{k}")
        dd, cmds["direct"] = sky_coefficients(run, args, sky_oct, pts_l, nrm_l, 1, order,
                                              f"rcontrib direct sky#{k}")
        write_matrix(out / f"dc-total-{k}.mtx", dc)
        write_matrix(out / f"dc-direct-{k}.mtx", dd)
        tot = read_matrix(run(f"dctimestep#{k}", ["dctimestep", "-of", f"dc-total-{k}.mtx",
                                                   "sky.smx"]))
        dsun = read_matrix(run(f"dctimestep#{k}", ["dctimestep", "-of", f"dc-direct-{k}.mtx",
                                                    "sun.smx"]))
        # dctimestep: rows are the sensors, columns the hours.
        lux_w = to_lux(tot.astype(np.float64) - dsun.astype(np.float64)).T  # (weather hours, s)
        full = np.zeros((HOURS_PER_YEAR, len(pts)))
        full[rows] = lux_w
        full += sun_hourly
        runs.append(full)
        patch_sun = np.zeros((HOURS_PER_YEAR, len(pts)))
        patch_sun[rows] = to_lux(dsun.astype(np.float64)).T
        through_patches.append(patch_sun)
    runs = np.array(runs)
    ref = runs.mean(axis=0)
    patch_sun = np.mean(through_patches, axis=0)

    hours = year_hours()
    occ = occupied(hours[:, 2], args.occupied)
    met = metrics(ref, sun_hourly, occ, indoor)
    met_runs = [metrics(r, sun_hourly, occ, indoor) for r in runs]

    np.save(out / "radiance-illuminance.npy", ref.astype(np.float32))
    np.save(out / "radiance-direct-sun.npy", sun_hourly.astype(np.float32))
    np.save(out / "radiance-illuminance-runs.npy", runs.astype(np.float32))
    write_hours(out / "radiance-hours.csv", hours, np.arange(HOURS_PER_YEAR))
    write_sensors(out / "sensors.csv", pts, nrm, indoor,
                  {"da300": met.pop("da300"), "ase_hours": met.pop("ase_hours"),
                   "udi_fell_short": met.pop("udi_fell_short_per_sensor"),
                   "udi_useful": met.pop("udi_useful_per_sensor"),
                   "udi_exceeded": met.pop("udi_exceeded_per_sensor"),
                   "mean_occupied_lux": met.pop("mean_occupied_lux_per_sensor")})
    for mr in met_runs:
        for key in [k for k in mr if isinstance(mr[k], np.ndarray)]:
            del mr[key]

    sun_sum = float(sun_hourly.sum())
    report = {
        "model": str(args.model),
        "weather": str(args.weather),
        "site": wea.header,
        "frame": {"zenith": list(map(float, daylight.parse_vec(args.zenith))),
                  "north": list(map(float, daylight.parse_vec(args.north))),
                  "matrix_rows_east_north_up": m.tolist()},
        "sensors": {"count": int(len(pts)), "in_metrics": int(indoor.sum()), "rule": rule,
                    "file": "sensors.csv"},
        "quantity": "illuminance, lux = 179 (0.265 R + 0.670 G + 0.065 B) of visible irradiance "
                    "(gendaymtx -O0, white sky -c 1 1 1)",
        "method": "two-phase: dctimestep(DC, sky.smx) - dctimestep(D, sun.smx) + direct sun per "
                  "hour (rcontrib -ab 0, gendaymtx -D suns); DC every bounce, D -ab 1",
        "sky": {"mf": args.mf, "patches": 144 * args.mf ** 2 + 1, "ground_reflectance":
                args.ground_reflectance, "gendaymtx": [s.command for s in run.steps
                                                        if s.name == "gendaymtx"]},
        "radiance": {"version": VERSION, "rcontrib_total": cmds["total"],
                     "rcontrib_direct_sky": cmds["direct"], "direct_sun": sun_info,
                     "repeat": args.repeat, "seed": args.seed, "procs": args.procs,
                     "ab": args.ab, "ad": args.ad},
        "hours": {"year": HOURS_PER_YEAR, "weather": int(len(wea.rows)),
                  "daylit": int((ref.max(axis=1) > 0).sum()),
                  "sun_up": sun_info["suns_above_horizon"], "occupied": int(occ.sum()),
                  "occupied_window": list(args.occupied),
                  "occupied_rule": f"centre in [{args.occupied[0]:g}, {args.occupied[1]:g}) "
                                   "local standard time, no daylight saving"},
        "seconds": run.seconds(),
        "steps": [asdict(s) for s in run.steps],
        "noise": noise(runs),
        "metrics": met,
        "metrics_runs": met_runs,
        "check_direct_sun_through_patches_over_exact": (float(patch_sun.sum()) / sun_sum
                                                        if sun_sum > 0 else None),
        "warnings": notes,
    }
    (out / "report.json").write_text(json.dumps(report, indent=1, default=float))
    return report


def write_hours(path: Path, hours: np.ndarray, hour_index: np.ndarray):
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["row", "hour_of_year", "month", "day", "hour"])
        for r, h in enumerate(hour_index):
            mo, d, hr = hours[h]
            w.writerow([r, int(h), int(mo), int(d), f"{hr:.1f}"])


# --------------------------------------------------------------------------------------------
# Figures.


def occupied(hour_centre: np.ndarray, window) -> np.ndarray:
    """Hours whose centre lies in [start, end) (local standard time)."""
    return (hour_centre >= window[0]) & (hour_centre < window[1])


def metrics(lux: np.ndarray, sun: np.ndarray, occ: np.ndarray, keep: np.ndarray) -> dict:
    """LM-83 / UDI metrics over the occupied hours of (hours, sensors) arrays; sensors ``keep``
    only, equal weights. Per-sensor arrays (DA300 %, ASE hours, UDI bands %) are included."""
    e = lux[occ][:, keep]
    s = sun[occ][:, keep]
    n_occ = max(int(occ.sum()), 1)
    da = 100.0 * (e >= 300.0).sum(axis=0) / n_occ
    ase_h = (s >= 1000.0).sum(axis=0)
    short = 100.0 * (e < 100.0).sum(axis=0) / n_occ
    exceed = 100.0 * (e > 3000.0).sum(axis=0) / n_occ
    useful = 100.0 - short - exceed
    full = lambda v: _scatter(v, keep)  # noqa: E731
    return {
        "occupied_hours": int(occ.sum()),
        "sensors": int(keep.sum()),
        "sda300_50": float(100.0 * np.mean(da >= 50.0)),
        "ase1000_250": float(100.0 * np.mean(ase_h > 250)),
        "da300_mean": float(da.mean()),
        "udi_fell_short": float(short.mean()),
        "udi_useful": float(useful.mean()),
        "udi_exceeded": float(exceed.mean()),
        "mean_occupied_lux": float(e.mean()),
        "da300": full(da),
        "ase_hours": full(ase_h.astype(float)),
        "udi_fell_short_per_sensor": full(short),
        "udi_useful_per_sensor": full(useful),
        "udi_exceeded_per_sensor": full(exceed),
        "mean_occupied_lux_per_sensor": full(e.mean(axis=0)),
    }


def _scatter(v, keep):
    out = np.full(len(keep), np.nan)
    out[keep] = v
    return out


def errors(test: np.ndarray, ref: np.ndarray, threshold: float = LIT_LUX) -> dict:
    """Relative errors of ``test`` against ``ref`` over the sensor-hours with ref > threshold:
    mean, median, 90th percentile, aggregate sum |d| / sum ref (every sensor an equal area:
    the area-weighted figure), signed aggregate."""
    lit = ref > threshold
    if not lit.any():
        return {"sensor_hours": 0}
    d, r = test[lit] - ref[lit], ref[lit]
    rel = np.abs(d) / r
    return {"sensor_hours": int(lit.sum()), "mean_relative_error": float(rel.mean()),
            "median_relative_error": float(np.median(rel)),
            "p90_relative_error": float(np.percentile(rel, 90)),
            "aggregate_relative_error": float(np.abs(d).sum() / r.sum()),
            "aggregate_signed_error": float(d.sum() / r.sum())}


def noise(runs: np.ndarray) -> dict:
    """Radiance's noise from its k runs (hours x sensors each), over the sensor-hours where the
    mean is above 100 lux, by leave-one-out as ``daylight.noise``: each run's error estimated
    as e_j = (x_j - mean of the others) sqrt((k - 1) / k); for one run the mean, median and
    aggregate |e_j| / mean (averaged over j), for the reference (their mean) the same / sqrt(k)."""
    k = len(runs)
    if k < 2:
        return {}
    mean = runs.mean(axis=0)
    lit = mean > LIT_LUX
    keys = ("mean_relative_error", "median_relative_error", "aggregate_relative_error")
    acc = {key: [] for key in keys}
    for j in range(k):
        others = np.delete(runs, j, axis=0).mean(axis=0)
        e = np.abs(runs[j] - others)[lit] * math.sqrt((k - 1) / k)
        rel = e / mean[lit]
        acc["mean_relative_error"].append(rel.mean())
        acc["median_relative_error"].append(np.median(rel))
        acc["aggregate_relative_error"].append(e.sum() / mean[lit].sum())
    out = {"runs": k, "sensor_hours": int(lit.sum())}
    for key in keys:
        v = float(np.mean(acc[key]))
        out["one_run_" + key] = v
        out[key] = v / math.sqrt(k)
    return out


# --------------------------------------------------------------------------------------------
# The tool's layout: reading it (comparison) and writing it (a stand-in for tests).


def read_hours_csv(path: Path) -> np.ndarray:
    """(rows, 4): hour_of_year, month, day, hour, in row order."""
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    if not rows:
        sys.exit(f"{path}: no rows")
    rows.sort(key=lambda r: int(r["row"]))
    if [int(r["row"]) for r in rows] != list(range(len(rows))):
        sys.exit(f"{path}: rows are not 0 .. n-1")
    return np.array([[float(r[c]) for c in ("hour_of_year", "month", "day", "hour")]
                     for r in rows])


def align_hours(tool_hours: np.ndarray, notes: list) -> np.ndarray:
    """The 0-based hour of the year of each of the tool's rows, checked against its month, day
    and hour (a 1-based hour_of_year is recognised and said)."""
    from_date = hour_of_year(tool_hours[:, 1], tool_hours[:, 2], tool_hours[:, 3])
    given = tool_hours[:, 0].astype(int)
    if np.array_equal(given, from_date):
        idx = given
    elif np.array_equal(given - 1, from_date):
        notes.append("the tool's hour_of_year is 1-based (1 = 1 Jan 0:00-1:00)")
        idx = from_date
    else:
        bad = int(np.argmax(given != from_date))
        sys.exit(f"the tool's hours.csv row {bad}: hour_of_year {given[bad]} is not "
                 f"{tool_hours[bad, 1]:.0f}/{tool_hours[bad, 2]:.0f} {tool_hours[bad, 3]} h "
                 f"(0-based {from_date[bad]})")
    if len(np.unique(idx)) != len(idx):
        sys.exit("the tool's hours.csv lists an hour twice")
    return idx


def read_tool(tool_dir: Path, notes: list):
    """The tool's annual output as full-year (8760, sensors) arrays, its sensors and CPU."""
    ann = tool_dir / "annual"
    pts, nrm, _ = daylight.read_points_csv(tool_dir / "grid.csv")
    th = read_hours_csv(ann / "hours.csv")
    idx = align_hours(th, notes)
    full = {}
    for name in ("illuminance", "direct_sun"):
        a = np.load(ann / f"{name}.npy")
        if a.shape != (len(th), len(pts)):
            sys.exit(f"{ann / name}.npy: shape {a.shape}, expected ({len(th)}, {len(pts)})")
        f = np.zeros((HOURS_PER_YEAR, len(pts)))
        f[idx] = a
        full[name] = f
    cpu = None
    summ = tool_dir / "summary.json"
    if summ.is_file():
        c = json.loads(summ.read_text()).get("cpu_seconds") or {}
        if isinstance(c, dict):
            cpu = c.get("total", sum(v for v in c.values() if isinstance(v, (int, float))) or None)
        elif isinstance(c, (int, float)):
            cpu = float(c)
    return full["illuminance"], full["direct_sun"], pts, nrm, idx, cpu


def write_as_tool(dest: Path, pts, nrm, indoor, lux, sun, cpu: float):
    """This run in the tool's layout (only the hours with light at some sensor listed)."""
    (dest / "annual").mkdir(parents=True, exist_ok=True)
    with open(dest / "grid.csv", "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["x", "y", "z", "nx", "ny", "nz", "lux", "df", "storey", "room", "indoor"])
        for i in range(len(pts)):
            w.writerow([f"{v:.6f}" for v in (*pts[i], *nrm[i])] + [0, 0, 0, 0, int(indoor[i])])
    lit = np.nonzero((lux.max(axis=1) > 0) | (sun.max(axis=1) > 0))[0]
    write_hours(dest / "annual" / "hours.csv", year_hours(), lit)
    np.save(dest / "annual" / "illuminance.npy", lux[lit].astype(np.float32))
    np.save(dest / "annual" / "direct_sun.npy", sun[lit].astype(np.float32))
    (dest / "summary.json").write_text(json.dumps({"cpu_seconds": {"total": cpu},
                                                   "note": "a Radiance run in the tool's "
                                                           "layout (annual.py --as-tool)"}))


def compare(ref_dir: Path, tool_dir: Path, args) -> dict:
    report = json.loads((ref_dir / "report.json").read_text())
    ref = np.load(ref_dir / "radiance-illuminance.npy").astype(np.float64)
    ref_sun = np.load(ref_dir / "radiance-direct-sun.npy").astype(np.float64)
    pts, nrm, _ = daylight.read_points_csv(ref_dir / "sensors.csv")
    with open(ref_dir / "sensors.csv", newline="") as f:
        indoor = np.array([float(r["indoor"]) != 0 for r in csv.DictReader(f)])
    notes = []
    lux, sun, tpts, _, idx, tool_cpu = read_tool(tool_dir, notes)
    if args.tool_cpu is not None:
        tool_cpu = args.tool_cpu
    if tpts.shape != pts.shape or not np.allclose(tpts, pts, atol=1e-4):
        sys.exit(f"{tool_dir / 'grid.csv'}: not the reference's sensors ({ref_dir / 'sensors.csv'}"
                 "); run the reference with --sensors TOOL_DIR/grid.csv")
    missing = np.setdiff1d(np.nonzero(ref.max(axis=1) > LIT_LUX)[0], idx)
    if len(missing):
        notes.append(f"{len(missing)} hours with the reference above {LIT_LUX:g} lux somewhere "
                     "are not in the tool's hours.csv (0 lux there)")
    hours = year_hours()
    occ_window = report["hours"].get("occupied_window", args.occupied)
    occ = occupied(hours[:, 2], occ_window)
    mt, mr = metrics(lux, sun, occ, indoor), metrics(ref, ref_sun, occ, indoor)
    scal = lambda d: {k: v for k, v in d.items() if not isinstance(v, np.ndarray)}  # noqa: E731
    diffs = {k: mt[k] - mr[k] for k in ("sda300_50", "ase1000_250", "da300_mean",
                                        "udi_fell_short", "udi_useful", "udi_exceeded")}
    hourly = errors(lux, ref)
    hourly_occ = errors(lux[occ], ref[occ])
    direct = errors(sun, ref_sun)
    rad_cpu = report["seconds"]["cpu"]["total"]
    udi_max = max(abs(diffs[k]) for k in ("udi_fell_short", "udi_useful", "udi_exceeded"))
    meets = {"hourly_mean_relative_error": (hourly.get("mean_relative_error", 0.0)
                                            <= BARS["hourly_mean_relative_error"]),
             "sda": abs(diffs["sda300_50"]) <= BARS["sda_points"],
             "ase": abs(diffs["ase1000_250"]) <= BARS["ase_points"],
             "udi": udi_max <= BARS["udi_points"]}
    out = {"reference": str(ref_dir), "tool": str(tool_dir), "model": report.get("model"),
           "label": args.label or Path(report.get("model") or ref_dir).stem,
           "sensors": int(len(pts)), "tool_hours_listed": int(len(idx)),
           "hourly": hourly, "hourly_occupied": hourly_occ, "direct_sun": direct,
           "metrics_tool": scal(mt), "metrics_radiance": scal(mr), "differences_points": diffs,
           "udi_max_difference_points": udi_max,
           "radiance_noise": report.get("noise"),
           "cpu_seconds": {"tool": tool_cpu, "radiance": rad_cpu,
                           "ratio": rad_cpu / tool_cpu if tool_cpu else None},
           "bars": BARS, "meets": meets, "warnings": notes}
    (ref_dir / "compare.json").write_text(json.dumps(out, indent=1, default=float))
    return out


# --------------------------------------------------------------------------------------------
# Printing.


def pct(x):
    return "-" if x is None else f"{100 * x:.2f} %"


def print_report(r: dict, out: Path):
    s, mt, nz = r["sensors"], r["metrics"], r["noise"]
    print(f"{Path(r['model']).name}: {s['count']} sensors, {r['hours']['occupied']} occupied "
          f"hours, {r['hours']['sun_up']} suns above the horizon, {r['radiance']['repeat']} runs")
    for w in r["warnings"]:
        print(f"  warning: {w}")
    print(f"  sDA300/50% {mt['sda300_50']:.1f} %, ASE1000,250h {mt['ase1000_250']:.1f} %, "
          f"DA300 mean {mt['da300_mean']:.1f} %, UDI <100 / 100-3000 / >3000: "
          f"{mt['udi_fell_short']:.1f} / {mt['udi_useful']:.1f} / {mt['udi_exceeded']:.1f} %, "
          f"mean occupied {mt['mean_occupied_lux']:.0f} lux")
    for k, m in enumerate(r["metrics_runs"]):
        print(f"    run {k + 1}: sDA {m['sda300_50']:.1f}, ASE {m['ase1000_250']:.1f}, DA300 "
              f"{m['da300_mean']:.2f}, UDI {m['udi_fell_short']:.2f} / {m['udi_useful']:.2f} / "
              f"{m['udi_exceeded']:.2f}")
    if nz:
        print(f"  noise over {nz['sensor_hours']} sensor-hours > {LIT_LUX:g} lux: one run mean "
              f"{pct(nz['one_run_mean_relative_error'])}, median "
              f"{pct(nz['one_run_median_relative_error'])}, aggregate "
              f"{pct(nz['one_run_aggregate_relative_error'])}; the reference (mean of "
              f"{nz['runs']}): {pct(nz['mean_relative_error'])} / "
              f"{pct(nz['median_relative_error'])} / {pct(nz['aggregate_relative_error'])}")
    sec = r["seconds"]
    print("  CPU seconds: " + ", ".join(f"{k} {v:.1f}" for k, v in sec["cpu"].items())
          + f" (wall {sec['wall']['total']:.1f} s)")
    ratio = r["check_direct_sun_through_patches_over_exact"]
    if ratio:
        print(f"  check: the direct sun through MF {r['sky']['mf']} patches / exact, over the "
              f"year: {ratio:.3f}")
    print(f"  {r['radiance']['rcontrib_total']}")
    print(f"  report: {out / 'report.json'}")


def print_compare(c: dict):
    h, ho, d = c["hourly"], c["hourly_occupied"], c["direct_sun"]
    print(f"{c['label']}: the tool ({c['tool']}) against Radiance ({c['reference']}), "
          f"{c['sensors']} sensors, {c['tool_hours_listed']} hours listed by the tool")
    for w in c["warnings"]:
        print(f"  warning: {w}")
    print(f"  hourly illuminance, {h.get('sensor_hours', 0)} sensor-hours > {LIT_LUX:g} lux: mean "
          f"{pct(h.get('mean_relative_error'))} (bar 5 %), median "
          f"{pct(h.get('median_relative_error'))}, aggregate "
          f"{pct(h.get('aggregate_relative_error'))} (signed "
          f"{pct(h.get('aggregate_signed_error'))}); occupied hours only: mean "
          f"{pct(ho.get('mean_relative_error'))}")
    print(f"  direct sun, {d.get('sensor_hours', 0)} sensor-hours > {LIT_LUX:g} lux: mean "
          f"{pct(d.get('mean_relative_error'))}, aggregate "
          f"{pct(d.get('aggregate_relative_error'))}")
    t, r, df = c["metrics_tool"], c["metrics_radiance"], c["differences_points"]
    print(f"  {'':<22}{'tool':>10}{'Radiance':>10}{'diff':>10}")
    for name, k in (("sDA300/50% %", "sda300_50"), ("ASE1000,250h %", "ase1000_250"),
                    ("DA300 mean %", "da300_mean"), ("UDI <100 %", "udi_fell_short"),
                    ("UDI 100-3000 %", "udi_useful"), ("UDI >3000 %", "udi_exceeded")):
        print(f"  {name:<22}{t[k]:>10.2f}{r[k]:>10.2f}{df[k]:>+10.2f}")
    cpu = c["cpu_seconds"]
    tool_cpu = f"{cpu['tool']:.1f} s" if cpu["tool"] else "-"
    print(f"  CPU: tool {tool_cpu}, Radiance {cpu['radiance']:.1f} s")
    print(f"  bars met (hourly MRE <= 5 %, sDA/ASE within 2 points, UDI within 3): {c['meets']}")


def print_markdown(paths):
    print("| model | sensors | hourly MRE (> 100 lux) | median | aggregate | sDA tool / Radiance "
          "| ASE tool / Radiance | UDI <100 / 100-3000 / >3000 diff (points) | Radiance noise "
          "(MRE of the reference) | CPU tool / Radiance | bars |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for p in paths:
        c = json.loads(Path(p).read_text())
        h, t, r, d = c["hourly"], c["metrics_tool"], c["metrics_radiance"], \
            c["differences_points"]
        nz = c.get("radiance_noise") or {}
        cpu = c["cpu_seconds"]
        tcpu = f"{cpu['tool']:.0f} s" if cpu["tool"] else "-"
        print(f"| {c['label']} | {c['sensors']} | {pct(h.get('mean_relative_error'))} | "
              f"{pct(h.get('median_relative_error'))} | "
              f"{pct(h.get('aggregate_relative_error'))} | "
              f"{t['sda300_50']:.1f} / {r['sda300_50']:.1f} | "
              f"{t['ase1000_250']:.1f} / {r['ase1000_250']:.1f} | "
              f"{d['udi_fell_short']:+.2f} / {d['udi_useful']:+.2f} / {d['udi_exceeded']:+.2f} | "
              f"{pct(nz.get('mean_relative_error'))} | {tcpu} / {cpu['radiance']:.0f} s | "
              f"{bars_cell(c['meets'])} |")


def bars_cell(meets: dict) -> str:
    missed = [k for k, v in meets.items() if not v]
    return "all met" if not missed else "missed: " + ", ".join(missed)


# --------------------------------------------------------------------------------------------
# Main.


def window(text: str):
    a, b = (float(x) for x in text.split(","))
    return (a, b)


def parse_args(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter,
                                 epilog=__doc__.split("\n\n", 1)[1])
    ap.add_argument("model", type=Path, nargs="?", help="OBJ file (its MTL beside it)")
    ap.add_argument("--weather", type=Path, help="EPW or .wea file")
    ap.add_argument("--out", type=Path, help="output folder (default out/annual/MODEL)")
    s = ap.add_argument_group("sensors (one of)")
    s.add_argument("--sensors", type=Path, help="CSV with x,y,z,nx,ny,nz (the tool's grid.csv, "
                   "or sensors.csv of an earlier run)")
    s.add_argument("--grid", help="HEIGHT,SPACING: a work plane made the way daylight.py "
                   "--points-only makes it")
    s.add_argument("--floor-material", default=r"^floor", help="--grid: regex of the floor "
                   "materials (default ^floor)")
    k = ap.add_argument_group("sky")
    k.add_argument("--ground-reflectance", type=float, default=0.2, help="gendaymtx -g")
    k.add_argument("--zenith", default="0,1,0", help="the model's up (default 0,1,0)")
    k.add_argument("--north", default="0,0,-1", help="the model's north (default 0,0,-1)")
    k.add_argument("--mf", type=int, default=1, help="Reinhart subdivision, gendaymtx -m "
                   "(default 1: Tregenza's 145 patches and the ground)")
    k.add_argument("--occupied", type=window, default=(8.0, 18.0),
                   help="START,END: occupied hours, their centre in [START, END) local standard "
                   "time (default 8,18)")
    r = ap.add_argument_group("rcontrib")
    r.add_argument("--ab", type=int, default=12, help="-ab of the total coefficients (default 12)")
    r.add_argument("--ad", type=int, default=65536, help="-ad (default 65536)")
    r.add_argument("--lw", type=float, help="-lw (default 0.5 / ad)")
    r.add_argument("--procs", type=int, default=2, help="rcontrib -n (default 2)")
    r.add_argument("--repeat", type=int, default=2, help="independent coefficient runs: the "
                   "reference is their mean, their spread its noise (default 2)")
    r.add_argument("--seed", type=int, default=1, help="seed of the sensors' orders")
    ap.add_argument("--radiosity", help=BINARY_HELP + "; for radiosity info --json")
    c = ap.add_argument_group("comparison")
    c.add_argument("--compare", type=Path, metavar="TOOL_DIR",
                   help="compare the tool's annual output in TOOL_DIR with the reference in --out "
                   "(made now, when a model is given, or earlier)")
    c.add_argument("--tool-cpu", type=float, help="the tool's CPU seconds (default from "
                   "TOOL_DIR/summary.json cpu_seconds)")
    c.add_argument("--label", help="the comparison's name in tables (default the model's)")
    c.add_argument("--as-tool", type=Path, metavar="DIR",
                   help="also write this run in the tool's layout (a stand-in tool)")
    ap.add_argument("--table", nargs="+", type=Path, metavar="COMPARE_JSON",
                    help="print a Markdown table of these compare.json files and stop")
    args = ap.parse_args(argv)
    if args.table is None:
        if args.model is None and not (args.compare and args.out):
            ap.error("a model (or --compare TOOL_DIR --out REFERENCE_DIR, or --table)")
        if args.model is not None:
            if args.weather is None:
                ap.error("--weather EPW|WEA")
            if (args.sensors is None) == (args.grid is None):
                ap.error("one of --sensors CSV or --grid HEIGHT,SPACING")
    return args


def main(argv=None):
    args = parse_args(argv)
    if args.table:
        print_markdown(args.table)
        return
    if args.model is not None:
        out = (args.out or ROOT / "out" / "annual" / args.model.stem).resolve()
        out.mkdir(parents=True, exist_ok=True)
        report = run_reference(args, out)
        print_report(report, out)
        if args.as_tool:
            pts, nrm, _ = daylight.read_points_csv(out / "sensors.csv")
            with open(out / "sensors.csv", newline="") as f:
                indoor = np.array([float(r["indoor"]) != 0 for r in csv.DictReader(f)])
            # One run, as a tool's would be: the first (not the mean).
            runs = np.load(out / "radiance-illuminance-runs.npy")
            write_as_tool(args.as_tool, pts, nrm, indoor, runs[0].astype(np.float64),
                          np.load(out / "radiance-direct-sun.npy").astype(np.float64),
                          report["seconds"]["cpu"]["total"] / max(args.repeat, 1))
            print(f"  in the tool's layout (run 1): {args.as_tool}")
    else:
        out = args.out.resolve()
    if args.compare:
        print_compare(compare(out, args.compare, args))


if __name__ == "__main__":
    main()
