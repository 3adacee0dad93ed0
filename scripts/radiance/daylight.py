#!/usr/bin/env python3
"""Check the tool's daylight (sky, sun, glazing, sensor grid) against Radiance: work-plane illuminance on a sensor grid.

1. The tool: ``radiosity solve MODEL --sky KIND [--sky-illuminance LUX] [--sun ALT,AZI | --sun
   off] --ground-reflectance G --zenith X,Y,Z --north X,Y,Z --grid HEIGHT,SPACING (or
   POINTS.csv) --out DIR/solve``; reads ``DIR/solve/grid.csv`` (x,y,z,nx,ny,nz,lux,df) and the
   ``sky`` and ``grid`` blocks of ``DIR/solve/summary.json``.
2. Radiance at exactly the same points and normals: the model written by ``objrad.py`` (glass as
   ``trans``, see there) and rotated into ``gensky``'s frame (x east, y north, z up), the sky from
   ``gensky -ang ALT AZI -c|-u|+s|-s -b ZENITH/179 -g G [-R SUN]`` with the tool's own zenith
   luminance and sun from its summary, plus the standard sky and ground glows; ``oconv``, then
   ``rtrace -I`` with no ambient cache, ``--repeat`` times (the points in a new random order each
   time, so each run's Monte Carlo is independent); lux = 179 (0.265 R + 0.670 G + 0.065 B).
3. Compared: area-averaged relative error sum |lux - lux_ref| / sum lux_ref (grid points stand
   for equal areas), median point relative error, min / mean / uniformity (min / mean) of both,
   Radiance's own noise (leave-one-out over its runs: :func:`noise`), the tool's solve time and
   Radiance's time for one run (:func:`speed`).

``--points-only`` (automatic when the binary does not know ``--sky``) runs only Radiance (the
materials still come from the tool's ``radiosity info --json``, so the binary must exist): the grid is made here (rule in :func:`make_grid`) or read from ``--grid POINTS.csv``,
and the sky's numbers are computed here the tool's way (:class:`SkySettings`). It writes
``DIR/radiance-grid.csv`` and ``DIR/report.json`` and reports Radiance's noise and time.

    PY=.venv-radiance/bin/python
    $PY scripts/radiance/daylit.py --out out/daylit
    $PY scripts/radiance/daylight.py out/daylit/sidelit.obj --sky overcast --grid 0.8,0.5 \\
        --out out/daylight/sidelit-overcast
    $PY scripts/radiance/daylight.py out/daylit/sidelit.obj --sky clear --sun 40,-20 \\
        --grid 0.8,0.5 --out out/daylight/sidelit-clear-sun --points-only
    $PY scripts/radiance/daylight.py --table out/daylight/*/report.json   # a Markdown table

Exit code 1 only when a step fails to run (the figures never make it fail).
"""

from __future__ import annotations

import argparse
import csv
import json
import math
import os
import re
import shlex
import subprocess
import sys
import time
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import objrad  # noqa: E402
from common import (BINARY_HELP, EFFICACY, PHOTOPIC, ROOT, children_cpu, oconv,  # noqa: E402
                    parse_emit, radiance_env, radiosity_binary, ray_lines, rtrace_rgb, run)

DEFAULT_SKY_ILLUMINANCE = 10_000.0  # lux, the tool's default for overcast (and uniform)
SUN_DIAMETER_RADIANCE = 0.5  # degrees, gensky's sun
BARS = {"area_averaged": 0.05, "median_point": 0.10, "speed": 10.0}


# --------------------------------------------------------------------------------------------
# The sky, the tool's way (src/sky: the conventions of gensky).


def clear_rel(mu, cos_gamma, sun_mu):
    """CIE clear sky, L / L_z = phi(gamma) f(theta) / (phi(Z) 0.274) (gensky's skybright.cal)."""
    def phi(c):
        c = np.clip(c, -1.0, 1.0)
        return 0.91 + 10.0 * np.exp(-3.0 * np.arccos(c)) + 0.45 * c * c
    f = 1.0 - np.exp(-0.32 / np.maximum(mu, 1e-12))
    return phi(cos_gamma) * f / (phi(sun_mu) * 0.274)


def sun_local(altitude, azimuth):
    """gensky's direction to the sun (x east, y north, z up), azimuth degrees west of south."""
    h, a = math.radians(altitude), math.radians(azimuth)
    return np.array([-math.sin(a) * math.cos(h), -math.cos(a) * math.cos(h), math.sin(h)])


def horizontal_ratio(kind: str, sun_dir=None, n=1024) -> float:
    """E_h / L_z (sr): pi (uniform), 7 pi / 9 (overcast), numerically for the clear sky
    (midpoint rule in mu and azimuth, n x 2n cells: within 4e-7 of n = 2048 at 35 and 80
    degrees). The overcast and uniform skies of src/sky/cie.rs in closed form."""
    if kind == "uniform":
        return math.pi
    if kind == "overcast":
        return 7.0 * math.pi / 9.0
    mu = (np.arange(n) + 0.5) / n
    ph = (np.arange(2 * n) + 0.5) / (2 * n) * 2 * math.pi
    m, p = np.meshgrid(mu, ph, indexing="ij")
    s = np.sqrt(1 - m * m)
    d = np.stack([s * np.cos(p), s * np.sin(p), m], axis=-1)
    rel = clear_rel(m, d @ sun_dir, sun_dir[2])
    return float(np.sum(rel * m) * (1.0 / n) * (2 * math.pi / (2 * n)))


def gensky_zenith_luminance(kind: str, altitude: float) -> float:
    """gensky's zenith luminance (cd/m^2) when none is given (turbidity 2.45 for the clear sky)."""
    h = math.radians(altitude)
    if kind in ("uniform", "overcast"):
        kcd = 8.6 * math.sin(h) + 0.123
    else:
        kcd = (1.376 * 2.45 - 1.81) * math.tan(min(h, math.radians(87.0))) + 0.38
    return max(1000.0 * kcd, 0.0)


def gensky_sun_normal_illuminance(altitude: float) -> float:
    """gensky's clear-sky sun, direct normal illuminance in lux (W/m^2 x 179)."""
    sin_h = math.sin(math.radians(altitude))
    return 1.5e9 / 208.0 * 6e-5 * (1.147 - 0.147 / max(sin_h, 0.16)) * EFFICACY


@dataclass
class SkySettings:
    """A sky as the tool's summary states it (or as this script computes it the tool's way)."""

    kind: str
    zenith_luminance: float  # cd/m^2, gensky -b x 179
    sky_illuminance: float  # lux, the sky alone on an unobstructed horizontal plane
    sun_altitude: float | None  # the sun's position (also for a clear sky without a sun)
    sun_azimuth: float | None
    sun_normal_illuminance: float | None  # lux; None: no sun
    ground_reflectance: float
    zenith: tuple
    north: tuple
    source: str  # "tool summary" or "computed here"

    @property
    def has_sun(self) -> bool:
        return self.sun_normal_illuminance is not None

    def sun_horizontal_illuminance(self) -> float:
        if not self.has_sun:
            return 0.0
        return self.sun_normal_illuminance * math.sin(math.radians(self.sun_altitude))


def parse_sun(text: str | None):
    """``ALT,AZI`` -> (alt, azi); ``off`` or None -> None."""
    if text is None or text.strip().lower() == "off":
        return None
    alt, azi = (float(x) for x in text.split(","))
    return alt, azi


def sky_from_args(args) -> SkySettings:
    """The sky the tool would build from these flags (src/sky: Sky::new)."""
    sun = parse_sun(args.sun)
    if args.sky == "clear" and sun is None and args.sun_position is None:
        sys.exit("--sky clear needs the sun's position: --sun ALT,AZI (or --sun off "
                 "--sun-position ALT,AZI)")
    position = sun or (parse_sun(args.sun_position) if args.sun_position else None)
    alt, azi = position if position else (None, None)
    sun_dir = sun_local(alt, azi) if position else np.array([0.0, 0.0, 1.0])
    ratio = horizontal_ratio(args.sky, sun_dir)
    if args.sky_illuminance is not None:
        e_h = args.sky_illuminance
        lz = e_h / ratio
    elif args.sky in ("overcast", "uniform"):
        e_h = DEFAULT_SKY_ILLUMINANCE
        lz = e_h / ratio
    else:  # gensky's default zenith luminance from the sun's altitude
        lz = gensky_zenith_luminance(args.sky, alt)
        e_h = lz * ratio
    sun_n = None
    if sun is not None and alt > 0:
        sun_n = (args.sun_normal_illuminance if args.sun_normal_illuminance is not None
                 else gensky_sun_normal_illuminance(alt))
    return SkySettings(args.sky, lz, e_h, alt, azi, sun_n, args.ground_reflectance,
                       tuple(parse_vec(args.zenith)), tuple(parse_vec(args.north)),
                       "computed here")


def sky_from_summary(block: dict, fallback: SkySettings) -> SkySettings:
    """The sky from the tool's summary.json ``sky`` block (the sun's position from the
    fallback when the summary gives no sun, e.g. a clear sky with --sun off)."""
    sun = block.get("sun")
    alt = sun["altitude"] if sun else fallback.sun_altitude
    azi = sun["azimuth"] if sun else fallback.sun_azimuth
    return SkySettings(block["kind"], float(block["zenith_luminance"]),
                       float(block["sky_illuminance"]), alt, azi,
                       float(sun["normal_illuminance"]) if sun else None,
                       float(block["ground_reflectance"]), tuple(block["zenith"]),
                       tuple(block["north"]), "tool summary")


def compare_skies(tool: SkySettings, here: SkySettings) -> list:
    """Differences above 0.5 % between the tool's sky and the one computed here (warnings)."""
    out = []
    pairs = [("zenith_luminance", tool.zenith_luminance, here.zenith_luminance),
             ("sky_illuminance", tool.sky_illuminance, here.sky_illuminance),
             ("ground_reflectance", tool.ground_reflectance, here.ground_reflectance)]
    if tool.has_sun and here.has_sun:
        pairs.append(("sun normal_illuminance", tool.sun_normal_illuminance,
                      here.sun_normal_illuminance))
    for name, a, b in pairs:
        if abs(a - b) > 5e-3 * max(abs(b), 1e-9):
            out.append(f"sky {name}: tool {a:.6g}, computed here {b:.6g}")
    if tool.has_sun != here.has_sun:
        out.append(f"sun: tool {'on' if tool.has_sun else 'off'}, asked "
                   f"{'on' if here.has_sun else 'off'}")
    if tool.kind != here.kind:
        out.append(f"sky kind: tool {tool.kind}, asked {here.kind}")
    return out


# --------------------------------------------------------------------------------------------
# The frame: the model's (zenith, north) -> gensky's (x east, y north, z up).


def parse_vec(text) -> np.ndarray:
    if isinstance(text, (list, tuple, np.ndarray)):
        return np.array(text, dtype=np.float64)
    return np.array([float(x) for x in text.split(",")], dtype=np.float64)


def frame_matrix(zenith, north) -> np.ndarray:
    """Rows east, north, up (unit), as src/sky/frame.rs: north made horizontal, east = north x up.
    ``M @ p`` takes a model point or direction into gensky's frame; a rotation (det +1), so
    windings and one-sidedness are kept."""
    up = np.asarray(zenith, float) / np.linalg.norm(zenith)
    n = np.asarray(north, float) / np.linalg.norm(north)
    n = n - (n @ up) * up
    n /= np.linalg.norm(n)
    east = np.cross(n, up)
    return np.array([east, n, up])


# --------------------------------------------------------------------------------------------
# The grid (points-only mode).


def point_in_polygon(pts2, poly2) -> np.ndarray:
    """Crossing-number test of 2D points against one 2D polygon (boundary points go to one
    side consistently, so a point on an edge shared by two polygons is in exactly one)."""
    x, y = pts2[:, 0], pts2[:, 1]
    inside = np.zeros(len(pts2), dtype=bool)
    j = len(poly2) - 1
    for i in range(len(poly2)):
        xi, yi = poly2[i]
        xj, yj = poly2[j]
        cross = (yi > y) != (yj > y)
        with np.errstate(divide="ignore", invalid="ignore"):
            xc = (xj - xi) * (y - yi) / (yj - yi) + xi
        inside ^= cross & (x < xc)
        j = i
    return inside


def make_grid(model, m: np.ndarray, height: float, spacing: float, floor_re: str,
              levels=None):
    """The work plane, this script's rule: floors are faces whose material name matches
    ``floor_re`` (case-insensitive) and whose normal is within 8 degrees of the zenith; they
    are grouped into levels by height (1 cm); each level gets a square lattice in (east, north)
    at ``spacing``, starting half a spacing in from the level's bounding box, and keeps the
    lattice points that fall on one of its floor faces, lifted ``height`` along the zenith;
    sensors face the zenith. ``levels``: indices of the levels kept (0 the lowest; None all).
    Returns model-frame points and normals (points inside solids are removed later by
    :func:`drop_inside`)."""
    up = m[2]
    rx = re.compile(floor_re, re.IGNORECASE)
    levels_kept, levels = levels, {}
    for face, mi in zip(model.faces, model.face_material):
        if not rx.search(model.materials[mi].name):
            continue
        p = model.vertices[face]
        n = objrad.polygon_normal(p)
        if np.linalg.norm(n) == 0 or (n / np.linalg.norm(n)) @ up < math.cos(math.radians(8)):
            continue
        h = round(float(p.mean(axis=0) @ up), 2)
        levels.setdefault(h, []).append(p @ m[:2].T)  # 2D (east, north)
    pts, nrm = [], []
    heights = sorted(levels)
    if levels_kept is not None:
        heights = [h for k, h in enumerate(heights) if k in levels_kept]
    for h in heights:
        polys = levels[h]
        allp = np.concatenate(polys)
        lo, hi = allp.min(axis=0), allp.max(axis=0)
        ne = max(int(math.floor((hi[0] - lo[0]) / spacing + 1e-9)), 1)
        nn = max(int(math.floor((hi[1] - lo[1]) / spacing + 1e-9)), 1)
        e = lo[0] + (np.arange(ne) + 0.5) * spacing
        n = lo[1] + (np.arange(nn) + 0.5) * spacing
        ee, nn_ = np.meshgrid(e, n, indexing="ij")
        cand = np.stack([ee.ravel(), nn_.ravel()], axis=1)
        keep = np.zeros(len(cand), dtype=bool)
        for poly in polys:
            keep |= point_in_polygon(cand, poly)
        local = np.column_stack([cand[keep], np.full(keep.sum(), h + height)])
        pts.append(local @ m)  # back to the model frame (m is orthonormal)
        nrm.append(np.repeat(up[None], keep.sum(), axis=0))
    if not pts:
        sys.exit(f"no floor faces (material matching {floor_re!r}, facing up): no grid")
    return np.concatenate(pts), np.concatenate(nrm)


def drop_inside(rad, octree, model, pts_local, m_normals) -> np.ndarray:
    """Mask of points not inside a solid: five rays (+-east, +-north, up) from each; a point
    whose first hit is the back of a face for three or more of them is inside something."""
    dirs = np.array([[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1]], float)
    org = np.repeat(pts_local, len(dirs), axis=0)
    dd = np.tile(dirs, (len(pts_local), 1))
    names = rad.trace_names(octree, org, dd)
    back = np.zeros(len(org), dtype=bool)
    for k, name in enumerate(names):
        mt = re.fullmatch(r"f(\d+)_\d+", name)
        if mt:
            back[k] = dd[k] @ m_normals[int(mt.group(1))] > 0
    return back.reshape(len(pts_local), len(dirs)).sum(axis=1) < 3


def read_points_csv(path: Path):
    """Points and normals from a CSV with at least x,y,z,nx,ny,nz columns (plus, from the
    tool's grid.csv, lux and df)."""
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    if not rows:
        sys.exit(f"{path}: no rows")
    pts = np.array([[float(r[c]) for c in ("x", "y", "z")] for r in rows])
    nrm = np.array([[float(r[c]) for c in ("nx", "ny", "nz")] for r in rows])
    extra = {}
    for c in ("lux", "df"):
        if c in rows[0]:
            extra[c] = np.array([float(r[c]) for r in rows])
    return pts, nrm, extra


# --------------------------------------------------------------------------------------------
# Radiance.


def sky_rad(sky: SkySettings) -> str:
    """Radiance's sky for these settings: gensky's output (zenith parameter -b = L_z / 179 as the
    tool's; the sun's horizontal irradiance -R so its normal illuminance is the tool's exactly
    whatever gensky's solid angle), then the sky and ground glows. In gensky's frame."""
    bin_dir, env = radiance_env()
    alt = sky.sun_altitude if sky.sun_altitude is not None else 45.0
    azi = sky.sun_azimuth if sky.sun_azimuth is not None else 0.0
    cmd = [str(bin_dir / "gensky"), "-ang", f"{alt:.9g}", f"{azi:.9g}"]
    extra_sun = ""
    if sky.kind == "clear":
        cmd.append("+s" if sky.has_sun else "-s")
    else:
        cmd.append("-c" if sky.kind == "overcast" else "-u")
    cmd += ["-b", f"{sky.zenith_luminance / EFFICACY:.9g}", "-g", f"{sky.ground_reflectance:.9g}"]
    if sky.has_sun and sky.kind == "clear":
        cmd += ["-R", f"{sky.sun_horizontal_illuminance() / EFFICACY:.9g}"]
    res = run(cmd, env=env)
    text = res.stdout
    if sky.has_sun and sky.kind != "clear":
        # gensky draws no sun with -c / -u: add one (0.5 degrees, as gensky's) and put its
        # share into the ground's brightness (the skyfunc's third real argument).
        half = math.radians(SUN_DIAMETER_RADIANCE / 2)
        omega = 2 * math.pi * (1 - math.cos(half))
        lsun = sky.sun_normal_illuminance / EFFICACY / omega
        d = sun_local(sky.sun_altitude, sky.sun_azimuth)
        extra_sun = (f"void light solar\n0\n0\n3 {lsun:.9g} {lsun:.9g} {lsun:.9g}\n\n"
                     f"solar source sun\n0\n0\n4 {d[0]:.9g} {d[1]:.9g} {d[2]:.9g} "
                     f"{SUN_DIAMETER_RADIANCE}\n\n")
        ground = sky.ground_reflectance * (sky.sky_illuminance
                                           + sky.sun_horizontal_illuminance()) / EFFICACY / math.pi
        text = re.sub(r"^3 (\d) (\S+) (\S+)$", lambda mt: f"3 {mt.group(1)} {mt.group(2)} "
                      f"{ground:.9g}", text, flags=re.MULTILINE)
    glows = ("\nskyfunc glow sky_glow\n0\n0\n4 1 1 1 0\n\n"
             "sky_glow source sky\n0\n0\n4 0 0 1 180\n\n"
             "skyfunc glow ground_glow\n0\n0\n4 1 1 1 0\n\n"
             "ground_glow source ground\n0\n0\n4 0 0 -1 180\n")
    return extra_sun + text + glows


class Radiance:
    """oconv and rtrace in one folder with fixed settings."""

    def __init__(self, args, workdir: Path):
        self.bin, self.env = radiance_env()
        self.workdir = workdir
        lw = args.lw if args.lw is not None else 0.5 / args.ad
        self.opts = ["-h", "-I+", "-n", str(args.procs), "-ab", str(args.ab), "-ad", str(args.ad),
                     "-as", str(args.as_), "-aa", str(args.aa), "-lr", str(args.lr), "-lw",
                     f"{lw:.3g}", "-dt", "0", "-dc", "1", "-ds", "0.02", "-dj", f"{args.dj:g}", "-dr", "0",
                     "-u+"]
        if args.ar is not None:
            self.opts[-1:-1] = ["-ar", str(args.ar)]
        self.run_seconds = []
        self.run_cpu = []
        self.last_cpu = 0.0

    def octree(self, model, sky: SkySettings, name="scene") -> Path:
        """The model (already in gensky's frame) and the sky, frozen (-f)."""
        scene = self.workdir / f"{name}.rad"
        objrad.write_rad(model, scene)
        skyfile = self.workdir / "sky.rad"
        skyfile.write_text(sky_rad(sky))
        return oconv(self.bin, self.env, [skyfile, scene], self.workdir / f"{name}.oct")

    def _rtrace(self, opts, octree, origins, dirs):
        text = ray_lines(origins, dirs)
        t0, c0 = time.perf_counter(), children_cpu()
        res = subprocess.run([self.bin / "rtrace", *opts, octree], input=text,
                             capture_output=True, text=True, env=self.env)
        seconds = time.perf_counter() - t0
        self.last_cpu = children_cpu() - c0
        if res.returncode != 0:
            sys.exit(f"rtrace failed: {res.stderr}")
        return res.stdout, seconds

    def irradiance(self, octree, origins, dirs) -> np.ndarray:
        """RGB irradiance (W/m^2) at each origin on a surface facing dirs; one timed run."""
        out, seconds = self._rtrace(self.opts, octree, origins, dirs)
        self.run_seconds.append(seconds)
        self.run_cpu.append(self.last_cpu)
        return rtrace_rgb(out, len(origins))

    def trace_names(self, octree, origins, dirs) -> list:
        """The name of the first surface each ray meets (sky or ground when none)."""
        out, _ = self._rtrace(["-h", "-ab", "0", "-os"], octree, origins, dirs)
        names = [line.strip() for line in out.splitlines() if line.strip()]
        if len(names) != len(origins):
            sys.exit(f"rtrace gave {len(names)} names for {len(origins)} rays")
        return names


def radiance_lux(rad: Radiance, octree, pts_local, nrm_local, repeat: int, seed: int):
    """Lux at the points from ``repeat`` runs (points shuffled each run: independent Monte
    Carlo per point, as rtrace's random sequence runs on from point to point), (runs x points)."""
    rng = np.random.default_rng(seed)
    runs = []
    for _ in range(repeat):
        order = rng.permutation(len(pts_local))
        h = rad.irradiance(octree, pts_local[order], nrm_local[order])
        lux = np.empty(len(order))
        lux[order] = EFFICACY * (h @ PHOTOPIC)
        runs.append(lux)
    return np.array(runs)


def match_accuracy(args, workdir, octree, pts_local, nrm_local, ref, target, one_run_noise,
                   seed, tries=3):
    """Radiance's time at the tool's accuracy, measured: single runs at a smaller (or larger)
    ``-ad``, each compared with the reference ``ref`` (area-averaged relative error, which holds
    the reference's own noise just as the tool's error does), the ``-ad`` of the next run from
    a power law error ~ ad^slope through the runs so far (slope -0.5 until two runs give one,
    kept within [-1, -0.25]), until a run's error is within 15 % of ``target`` or ``tries``
    runs are done. The time at ``target`` is then read off the same law (time ~ ad) from the
    run closest to it. Returns the runs and that estimate."""
    import types
    runs = []
    ad = args.ad * (one_run_noise / target) ** 2
    slope = -0.5
    for k in range(tries):
        ad = int(min(max(round(ad), 16), 65536))
        sub = types.SimpleNamespace(**{**vars(args), "ad": ad, "lw": 0.5 / ad})
        rad = Radiance(sub, workdir)
        lux = radiance_lux(rad, octree, pts_local, nrm_local, 1, seed + 1000 + k)[0]
        err = float(np.abs(lux - ref).sum() / ref.sum())
        runs.append({"ad": ad, "area_averaged_error": err, "seconds": rad.run_seconds[0],
                     "cpu_seconds": rad.run_cpu[0], "rtrace": " ".join(rad.opts)})
        if abs(err / target - 1) < 0.15:
            break
        if len(runs) >= 2:
            a, b = runs[-2], runs[-1]
            if a["ad"] != b["ad"] and a["area_averaged_error"] > 0 and err > 0:
                fit = (math.log(err / a["area_averaged_error"]) / math.log(b["ad"] / a["ad"]))
                slope = min(max(fit, -1.0), -0.25)
        ad = ad * (target / err) ** (1 / slope)
    best = min(runs, key=lambda r: abs(math.log(r["area_averaged_error"] / target)))
    ad_at = best["ad"] * (target / best["area_averaged_error"]) ** (1 / slope)
    return {"runs": runs, "slope": slope, "ad_at_tool_accuracy": ad_at,
            "seconds_at_tool_accuracy": best["seconds"] * ad_at / best["ad"],
            "cpu_seconds_at_tool_accuracy": best["cpu_seconds"] * ad_at / best["ad"]}


# --------------------------------------------------------------------------------------------
# Figures.


def stats(lux, df):
    mean = float(lux.mean())
    return {"mean_lux": mean, "min_lux": float(lux.min()), "max_lux": float(lux.max()),
            "uniformity": float(lux.min() / mean) if mean > 0 else None,
            "mean_df": float(df.mean())}


def comparison(tool_lux, ref_lux):
    """Area-averaged and median point relative errors of the tool against the reference."""
    lit = ref_lux > 0
    rel = np.abs(tool_lux[lit] - ref_lux[lit]) / ref_lux[lit]
    return {"area_averaged_relative_error": float(np.sum(np.abs(tool_lux - ref_lux))
                                                  / np.sum(ref_lux)),
            "area_averaged_signed_error": float(np.sum(tool_lux - ref_lux) / np.sum(ref_lux)),
            "median_point_relative_error": float(np.median(rel)) if lit.any() else None,
            "p90_point_relative_error": float(np.percentile(rel, 90)) if lit.any() else None,
            "points_compared": int(lit.sum())}


def noise(runs):
    """Radiance's own noise, from its ``k`` independent runs, as the errors it puts into the
    comparison's figures. Each run's error at a point is estimated by leave-one-out:
    e_j = (x_j - mean of the other runs) sqrt((k - 1) / k) (for k = 2: (x_1 - x_2) / sqrt 2),
    which has the variance of one run's error; then, for one run,

    - ``one_run_area_averaged``: sum |e_j| / sum lux, averaged over j;
    - ``one_run_median_point``: the median over the points of |e_j| / lux, averaged over j;
    - ``one_run_point_rms``: the root mean square over the points of s / lux (s the sample
      standard deviation of the runs: unbiased in its square);

    and for the reference (the mean of the k runs) the same divided by sqrt(k): ``area_averaged``,
    ``median_point``, ``point_rms``. No normal distribution is assumed (the error at a point
    is skewed where a few ambient rays find a small bright opening)."""
    k = len(runs)
    if k < 2:
        return {}
    mean = runs.mean(axis=0)
    lit = mean > 0
    area, med = [], []
    for j in range(k):
        others = np.delete(runs, j, axis=0).mean(axis=0)
        e = np.abs(runs[j] - others) * math.sqrt((k - 1) / k)
        area.append(e.sum() / mean.sum())
        med.append(float(np.median(e[lit] / mean[lit])))
    s = runs.std(axis=0, ddof=1)
    one = {"one_run_area_averaged": float(np.mean(area)),
           "one_run_median_point": float(np.mean(med)),
           "one_run_point_rms": float(np.sqrt(np.mean((s[lit] / mean[lit]) ** 2)))}
    out = {"runs": k}
    for key, v in one.items():
        out[key.replace("one_run_", "")] = v / math.sqrt(k)
    out.update(one)
    return out


def speed(tool_seconds: dict, rad: dict, fig: dict, matched: dict | None) -> dict:
    """Times side by side. The tool's time is its solve (plus the grid's gather when the
    summary gives it apart). ``speed_ratio`` = Radiance's time for one run at the reference's
    settings / the tool's; but the bar asks for Radiance *at the tool's accuracy*, which one run
    at the reference's settings far exceeds. So ``radiance_seconds_at_tool_accuracy`` is
    Radiance's time at the ``-ad`` whose single run is as far from the reference as the tool is:
    measured by :func:`match_accuracy` (``matched``), or, with ``--no-match``, scaled from the
    reference's one-run noise by noise ~ 1 / sqrt(-ad) ("scaled": Radiance's noise falls faster
    than that, so going down in -ad this underestimates its time, against the tool).
    ``speed_meets``: that time / the tool's >= 10."""
    t_tool = (tool_seconds.get("solve") or 0.0) + (tool_seconds.get("grid") or 0.0)
    t_rad = rad["seconds_one_run"]
    out = {"tool_seconds": t_tool, "radiance_seconds_one_run": t_rad,
           "speed_ratio": t_rad / t_tool if t_tool > 0 else None,
           "speed_meets": None, "radiance_seconds_at_tool_accuracy": None,
           "radiance_ad_at_tool_accuracy": None, "speed_ratio_at_tool_accuracy": None,
           "at_tool_accuracy_by": None}
    err = fig["area_averaged_relative_error"]
    if matched is not None:
        out["radiance_seconds_at_tool_accuracy"] = matched["seconds_at_tool_accuracy"]
        out["radiance_ad_at_tool_accuracy"] = matched["ad_at_tool_accuracy"]
        out["at_tool_accuracy_by"] = "measured"
    else:
        nz = rad["noise"].get("one_run_area_averaged")
        if nz is not None and err > 0:
            scale = (nz / err) ** 2
            out["radiance_seconds_at_tool_accuracy"] = t_rad * scale
            out["radiance_ad_at_tool_accuracy"] = rad["ad"] * scale
            out["at_tool_accuracy_by"] = "scaled"
    if out["radiance_seconds_at_tool_accuracy"] is not None and t_tool > 0:
        out["speed_ratio_at_tool_accuracy"] = out["radiance_seconds_at_tool_accuracy"] / t_tool
        out["speed_meets"] = out["speed_ratio_at_tool_accuracy"] >= BARS["speed"]
    # The same in CPU seconds (both sides' processes, all threads): what a busy machine leaves
    # alone. Judged on these when both are known.
    c_tool = (tool_seconds.get("cpu_solve") or 0.0) + (tool_seconds.get("cpu_grid") or 0.0)
    c_rad = rad.get("cpu_seconds_one_run")
    out["tool_cpu_seconds"] = c_tool or None
    out["radiance_cpu_seconds_one_run"] = c_rad
    c_at = None
    if matched is not None and "cpu_seconds_at_tool_accuracy" in matched:
        c_at = matched["cpu_seconds_at_tool_accuracy"]
    elif c_rad is not None and math.isfinite(c_rad) and out["radiance_seconds_at_tool_accuracy"]:
        c_at = c_rad * out["radiance_seconds_at_tool_accuracy"] / t_rad
    out["radiance_cpu_seconds_at_tool_accuracy"] = c_at
    out["cpu_ratio_at_tool_accuracy"] = c_at / c_tool if c_at and c_tool > 0 else None
    if out["cpu_ratio_at_tool_accuracy"] is not None:
        out["speed_meets"] = out["cpu_ratio_at_tool_accuracy"] >= BARS["speed"]
    return out


# --------------------------------------------------------------------------------------------
# The tool.


def tool_knows_sky(binary: Path) -> bool:
    """Whether ``radiosity solve --help`` lists --sky."""
    if not binary.is_file():
        return False
    res = subprocess.run([binary, "solve", "--help"], capture_output=True, text=True)
    return "--sky" in res.stdout + res.stderr


def tool_args(args) -> list:
    """The tool's sky and grid flags from ours (the flags of `radiosity solve`: --sky, --sun, --grid …)."""
    out = ["--sky", args.sky]
    if args.sky_illuminance is not None:
        out += ["--sky-illuminance", f"{args.sky_illuminance:g}"]
    out += ["--sun", args.sun or "off"]
    out += ["--ground-reflectance", f"{args.ground_reflectance:g}",
            "--zenith", args.zenith, "--north", args.north, "--grid", args.grid]
    return out


def run_tool(binary, model_path, out: Path, args):
    sdir = out / "solve"
    sdir.mkdir(parents=True, exist_ok=True)
    cmd = [binary, "solve", model_path, *tool_args(args), "--out", sdir, "--quiet",
           *shlex.split(args.solve_args)]
    t0 = time.perf_counter()
    run(cmd)
    wall = time.perf_counter() - t0
    summary = json.loads((sdir / "summary.json").read_text())
    pts, nrm, extra = read_points_csv(sdir / "grid.csv")
    return cmd, summary, wall, pts, nrm, extra


def tool_seconds(summary) -> dict:
    """The tool's times from its summary: solve, and the grid's gather if it reports one."""
    sec = summary.get("seconds", {})
    out = {"solve": sec.get("solve"), "total": sec.get("total")}
    cpu = summary.get("cpu_seconds") or {}
    if cpu:
        out["cpu_solve"], out["cpu_grid"] = cpu.get("solve"), cpu.get("grid")
    for k in ("grid", "gather_grid", "sensors"):
        if k in sec:
            out["grid"] = sec[k]
    return out


# --------------------------------------------------------------------------------------------
# Main.


def write_grid_csv(path: Path, pts, nrm, lux_runs, sky_illuminance):
    mean = lux_runs.mean(axis=0)
    se = (lux_runs.std(axis=0, ddof=1) / math.sqrt(len(lux_runs)) if len(lux_runs) > 1
          else np.zeros(len(mean)))
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["x", "y", "z", "nx", "ny", "nz", "lux", "df", "lux_se"]
                   + [f"lux_run{k + 1}" for k in range(len(lux_runs))])
        for i in range(len(mean)):
            w.writerow([f"{v:.6g}" for v in (*pts[i], *nrm[i], mean[i],
                                             100 * mean[i] / sky_illuminance, se[i],
                                             *lux_runs[:, i])])


def parse_args(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter,
                                 epilog=__doc__.split("\n\n", 1)[1])
    ap.add_argument("model", type=Path, nargs="?", help="OBJ file (its MTL beside it)")
    ap.add_argument("--table", nargs="+", type=Path, metavar="REPORT",
                    help="print a Markdown table of these report.json files and stop")
    ap.add_argument("--out", type=Path, help="output folder (default out/daylight/MODEL-SKY)")
    g = ap.add_argument_group("sky (passed to the tool as they are)")
    g.add_argument("--sky", choices=("overcast", "clear", "uniform"), default="overcast")
    g.add_argument("--sky-illuminance", type=float,
                   help="the sky's unobstructed horizontal illuminance, lux (default 10000 for "
                   "overcast and uniform; gensky's from the sun's altitude for clear)")
    g.add_argument("--sun", help="ALT,AZI (degrees, azimuth west of south) or off (default)")
    g.add_argument("--sun-position", help="ALT,AZI for a clear sky with --sun off (its "
                   "distribution needs one; the tool is asked as --sun off)")
    g.add_argument("--sun-normal-illuminance", type=float,
                   help="points-only: the sun's direct normal lux (default gensky's)")
    g.add_argument("--ground-reflectance", type=float, default=0.2)
    g.add_argument("--zenith", default="0,1,0")
    g.add_argument("--north", default="0,0,-1")
    g.add_argument("--grid", default="0.8,0.5",
                   help="HEIGHT,SPACING (m) or POINTS.csv (default 0.8,0.5)")
    ap.add_argument("--floor-material", default=r"^floor",
                    help="points-only grid: regex of the floor materials (default ^floor)")
    ap.add_argument("--levels", help="points-only grid: the floor levels kept, as indices "
                    "from the lowest (0), comma-separated (default all)")
    ap.add_argument("--points-only", action="store_true",
                    help="run Radiance alone on a grid made here (automatic when the tool does "
                    "not know --sky)")
    ap.add_argument("--radiosity", help=BINARY_HELP)
    ap.add_argument("--solve-args", default="", help="extra flags for radiosity solve, quoted")
    ap.add_argument("--repeat", type=int, default=2,
                    help="Radiance runs (their spread is its noise; the reference is their "
                    "mean); default 2")
    ap.add_argument("--seed", type=int, default=1, help="seed of the points' orders")
    r = ap.add_argument_group("rtrace settings")
    r.add_argument("--ab", type=int, default=12, help="-ab (default 12)")
    r.add_argument("--ad", type=int, default=4096, help="-ad (default 4096)")
    r.add_argument("--as", dest="as_", type=int, default=0, help="-as (default 0)")
    r.add_argument("--aa", type=float, default=0.0, help="-aa (default 0: no cache)")
    r.add_argument("--ar", type=int, help="-ar (only with --aa above 0; Radiance's default)")
    r.add_argument("--lr", type=int, default=-12, help="-lr (default -12)")
    r.add_argument("--lw", type=float, help="-lw (default 0.5 / ad, so first-bounce rays are "
                   "not cut short)")
    r.add_argument("--dj", type=float, default=1.0,
                   help="-dj (default 1: shadow rays sample the whole solar disc, as the tool "
                   "does; -dj 0 takes the sun as a point, so a row of sensors on a penumbra is "
                   "fully lit or fully shadowed where the disc is partly hidden)")
    r.add_argument("--procs", type=int, default=os.cpu_count() or 1, help="rtrace -n")
    ap.add_argument("--reference", type=Path, metavar="CSV",
                    help="also compare this Radiance run (e.g. cheaper settings) with another's "
                    "radiance-grid.csv on the same points: Radiance's own accuracy for its time")
    ap.add_argument("--no-match", action="store_true",
                    help="do not measure Radiance at the tool's accuracy (single runs at a "
                    "smaller -ad against the reference); scale its time instead")
    ap.add_argument("--reuse", action="store_true",
                    help="reuse Radiance's result saved in --out when made for the same model, "
                    "points, sky and settings")
    args = ap.parse_args(argv)
    if args.table is None and args.model is None:
        ap.error("a model (or --table)")
    return args


def main(argv=None):
    args = parse_args(argv)
    if args.table:
        print_markdown(args.table)
        return
    model_path = args.model.resolve()
    label = f"{model_path.stem}-{args.sky}" + ("-sun" if parse_sun(args.sun) else "")
    out = (args.out or ROOT / "out" / "daylight" / label).resolve()
    out.mkdir(parents=True, exist_ok=True)
    binary = radiosity_binary(args.radiosity)
    notes = []

    here_sky = sky_from_args(args)
    points_only = args.points_only
    if not points_only and not tool_knows_sky(binary):
        points_only = True
        notes.append(f"{binary}: missing or without --sky: Radiance only (--points-only)")
        print(notes[-1])

    # The tool, or the points and sky made here.
    tool = None
    if not points_only:
        cmd, summary, wall, pts, nrm, extra = run_tool(binary, model_path, out, args)
        if "sky" not in summary:
            sys.exit("the tool's summary.json has no 'sky' block")
        sky = sky_from_summary(summary["sky"], here_sky)
        notes += compare_skies(sky, here_sky)
        tool = {"command": shlex.join(map(str, cmd)), "summary_sky": summary["sky"],
                "summary_grid": summary.get("grid"), "seconds": tool_seconds(summary),
                "wall_seconds": wall, "lux": extra.get("lux"), "df": extra.get("df")}
        if tool["lux"] is None:
            sys.exit("the tool's grid.csv has no lux column")
        sg = summary.get("grid") or {}
        if sg.get("mean_lux") and abs(sg["mean_lux"] - tool["lux"].mean()) > 1e-3 * sg["mean_lux"]:
            notes.append(f"summary.json grid mean_lux {sg['mean_lux']:.6g} is not the mean of "
                         f"grid.csv's lux ({tool['lux'].mean():.6g})")
        if sg.get("points") is not None and sg["points"] != len(tool["lux"]):
            notes.append(f"summary.json grid points {sg['points']}, grid.csv {len(tool['lux'])}")
    else:
        sky = here_sky

    m = frame_matrix(sky.zenith, sky.north)
    emit = parse_emit(shlex.split(args.solve_args))
    model = objrad.read_obj(model_path, binary, emit)
    normals = []
    for face in model.faces:
        n = objrad.polygon_normal(model.vertices[face])
        ln = np.linalg.norm(n)
        normals.append(n / ln if ln > 0 else n)
    model.vertices = model.vertices @ m.T  # into gensky's frame
    normals_local = np.array(normals) @ m.T
    glazing = [(mt.name, mt.rho, mt.transmittance) for mt in model.materials if mt.transmits]

    rad = Radiance(args, out)
    octree = rad.octree(model, sky)
    if points_only:
        if re.fullmatch(r"[0-9.eE+-]+,[0-9.eE+-]+", args.grid):
            height, spacing = (float(x) for x in args.grid.split(","))
            kept = [int(x) for x in args.levels.split(",")] if args.levels else None
            pts, nrm = make_grid(objrad.read_obj(model_path, binary, emit), m, height,
                                 spacing, args.floor_material, kept)
            keep = drop_inside(rad, octree, model, pts @ m.T, normals_local)
            if (~keep).any():
                notes.append(f"{int((~keep).sum())} grid points inside solids dropped")
            pts, nrm = pts[keep], nrm[keep]
            grid_rule = (f"work plane {height} m above faces of material /{args.floor_material}/"
                         f" facing up, lattice {spacing} m (daylight.py make_grid)"
                         + (f", levels {args.levels}" if args.levels else ""))
        else:
            pts, nrm, _ = read_points_csv(Path(args.grid))
            grid_rule = f"points from {args.grid}"
    else:
        grid_rule = "the tool's grid.csv"
    pts_local, nrm_local = pts @ m.T, nrm @ m.T
    nrm_local /= np.linalg.norm(nrm_local, axis=1, keepdims=True)

    key = {"model": str(model_path), "bytes": model_path.stat().st_size,
           "mtime": model_path.stat().st_mtime, "rtrace": " ".join(rad.opts),
           "sky": asdict(sky), "points": np.round(pts, 6).tolist(),
           "normals": np.round(nrm, 6).tolist(), "repeat": args.repeat, "seed": args.seed}
    saved = out / "radiance.json"
    cached = None
    if args.reuse and saved.is_file():
        cached = json.loads(saved.read_text())
        if cached.get("key") != json.loads(json.dumps(key)):  # as JSON reads it back
            print(f"{saved}: made for other points, sky or settings; running Radiance")
            cached = None
    if cached is None:
        runs = radiance_lux(rad, octree, pts_local, nrm_local, args.repeat, args.seed)
        cached = {"key": key, "runs": runs.tolist(), "run_seconds": rad.run_seconds,
                  "run_cpu": rad.run_cpu}
        saved.write_text(json.dumps(cached))
    else:
        print(f"Radiance's result reused from {saved} (--reuse)")
    runs = np.array(cached["runs"])
    run_seconds = cached["run_seconds"]
    run_cpu = cached.get("run_cpu") or [float("nan")]
    ref = runs.mean(axis=0)
    write_grid_csv(out / "radiance-grid.csv", pts, nrm, runs, sky.sky_illuminance)

    report = {
        "model": str(args.model),
        "label": label,
        "mode": "points-only" if points_only else "tool vs Radiance",
        "quantity": "illuminance, lux = 179 x irradiance (W/m^2); Radiance: "
                    "179 (0.265 R + 0.670 G + 0.065 B)",
        "sky": asdict(sky),
        "sky_computed_here": asdict(here_sky),
        "grid_rule": grid_rule,
        "points": int(len(pts)),
        "glazing": [{"material": n, "rho": list(r), "transmittance": list(t)}
                    for n, r, t in glazing],
        "warnings": model.warnings + notes,
        "radiance": {"rtrace": " ".join(rad.opts), "ad": args.ad,
                     "version": "pyradiance 1.3.1 (RADIANCE 6.0a)",
                     "sky_rad": (out / "sky.rad").read_text(), "repeat": args.repeat,
                     "run_seconds": run_seconds,
                     "seconds_one_run": float(np.mean(run_seconds)),
                     "cpu_seconds_one_run": float(np.mean(run_cpu)),
                     "noise": noise(runs),
                     "grid": stats(ref, 100 * ref / sky.sky_illuminance)},
        "bars": BARS,
    }
    if args.reference:
        rp, _, rx = read_points_csv(args.reference)
        if rp.shape != pts.shape or not np.allclose(rp, pts, atol=1e-5):
            sys.exit(f"--reference {args.reference}: not the same points")
        fig_r = comparison(ref, rx["lux"])
        fig_r["reference"] = str(args.reference)
        report["radiance_vs_reference"] = fig_r
    if tool is not None:
        lux_t, df_t = tool["lux"], tool["df"]
        if len(lux_t) != len(ref):
            sys.exit("the tool's grid and Radiance's differ in length")
        fig = comparison(lux_t, ref)
        matched = None
        nz = report["radiance"]["noise"]
        if not args.no_match and nz and fig["area_averaged_relative_error"] > 0:
            if fig["area_averaged_relative_error"] <= 1.5 * nz["area_averaged"]:
                notes.append("the tool's error is within 1.5x the reference's own noise: "
                             "Radiance's time at the tool's accuracy not measured (scaled)")
            else:
                matched = match_accuracy(args, out, octree, pts_local, nrm_local, ref,
                                         fig["area_averaged_relative_error"],
                                         nz["one_run_area_averaged"], args.seed)
                report["radiance"]["matched"] = matched
        fig.update(speed(tool["seconds"], report["radiance"], fig, matched))
        fig["meets"] = {
            "area_averaged": fig["area_averaged_relative_error"] <= BARS["area_averaged"],
            "median_point": (fig["median_point_relative_error"] or 0) <= BARS["median_point"],
            "speed": fig["speed_meets"]}
        report["tool"] = {k: v for k, v in tool.items() if k not in ("lux", "df")}
        report["tool"]["grid"] = stats(lux_t, df_t if df_t is not None
                                       else 100 * lux_t / sky.sky_illuminance)
        report["figures"] = fig
        worst = np.argsort(-np.abs(lux_t - ref))[:10]
        report["worst_points"] = [{"i": int(i), "xyz": pts[i].tolist(), "tool_lux": float(lux_t[i]),
                                   "radiance_lux": float(ref[i])} for i in worst]
        report["points_table"] = {"tool_lux": lux_t.tolist(), "radiance_lux": ref.tolist()}
    (out / "report.json").write_text(json.dumps(report, indent=1))
    print_table(report, out)


def print_table(r, out):
    """The short table for one scene and sky."""
    rad = r["radiance"]
    print(f"{r['label']} ({r['mode']}): {r['points']} points, {rad['repeat']} Radiance runs")
    for w in r["warnings"]:
        print(f"  warning: {w}")
    sky = r["sky"]
    sun = (f", sun {sky['sun_altitude']:g}/{sky['sun_azimuth']:g} deg, "
           f"{sky['sun_normal_illuminance']:.0f} lux normal" if sky["sun_normal_illuminance"]
           else ", no sun")
    print(f"  sky {sky['kind']} ({sky['source']}): L_z {sky['zenith_luminance']:.1f} cd/m2, "
          f"E_h {sky['sky_illuminance']:.0f} lux{sun}, ground {sky['ground_reflectance']:g}")
    cols = [("Radiance", rad["grid"])] + ([("tool", r["tool"]["grid"])] if "tool" in r else [])
    print(f"  {'':<24}" + "".join(f"{c:>12}" for c, _ in cols))
    for name, k, fmt in (("mean lux", "mean_lux", "{:.1f}"), ("min lux", "min_lux", "{:.1f}"),
                         ("max lux", "max_lux", "{:.1f}"),
                         ("uniformity min/mean", "uniformity", "{:.3f}"),
                         ("mean DF %", "mean_df", "{:.3f}")):
        print(f"  {name:<24}" + "".join(f"{fmt.format(g[k]) if g[k] is not None else '-':>12}"
                                        for _, g in cols))
    if rad["noise"]:
        nz = rad["noise"]
        print(f"  Radiance noise (its mean of {rad['repeat']}): "
              f"{100 * nz['area_averaged']:.2f} % area-averaged, {100 * nz['median_point']:.2f} % "
              f"median point, {100 * nz['point_rms']:.2f} % rms point; one run: "
              f"{100 * nz['one_run_area_averaged']:.2f} % / "
              f"{100 * nz['one_run_median_point']:.2f} % / {100 * nz['one_run_point_rms']:.2f} %")
    print(f"  Radiance time: {rad['seconds_one_run']:.1f} s per run ({rad['rtrace']})")
    if "radiance_vs_reference" in r:
        f = r["radiance_vs_reference"]
        print(f"  this Radiance (mean of {rad['repeat']}) against {f['reference']}: "
              f"area-averaged {100 * f['area_averaged_relative_error']:.2f} % (signed "
              f"{100 * f['area_averaged_signed_error']:+.2f} %), median point "
              f"{100 * f['median_point_relative_error']:.2f} %")
    if "figures" in r:
        f = r["figures"]
        t = r["tool"]["seconds"]
        print(f"  area-averaged error {100 * f['area_averaged_relative_error']:.2f} % "
              f"(signed {100 * f['area_averaged_signed_error']:+.2f} %), median point "
              f"{100 * f['median_point_relative_error']:.2f} %, 90th percentile "
              f"{100 * f['p90_point_relative_error']:.2f} %")
        ratio = f"{f['speed_ratio']:.1f}x" if f["speed_ratio"] else "-"
        eq = (f"{f['radiance_seconds_at_tool_accuracy']:.2f} s (-ad "
              f"{f['radiance_ad_at_tool_accuracy']:.0f}, {f['at_tool_accuracy_by']}), "
              f"{f['speed_ratio_at_tool_accuracy']:.1f}x the tool's"
              if f["speed_ratio_at_tool_accuracy"] else "-")
        print(f"  tool solve {t['solve']} s (grid {t.get('grid', '-')} s); Radiance one run / "
              f"tool = {ratio}; Radiance at the tool's accuracy: {eq}")
        if f.get("cpu_ratio_at_tool_accuracy"):
            print(f"  CPU seconds: tool {f['tool_cpu_seconds']:.3f} s, Radiance one run "
                  f"{f['radiance_cpu_seconds_one_run']:.2f} s, at the tool's accuracy "
                  f"{f['radiance_cpu_seconds_at_tool_accuracy']:.2f} s: "
                  f"{f['cpu_ratio_at_tool_accuracy']:.1f}x")
        for m in rad.get("matched", {}).get("runs", []):
            print(f"    Radiance -ad {m['ad']}: {100 * m['area_averaged_error']:.2f} % "
                  f"area-averaged against the reference, {m['seconds']:.2f} s")
        print(f"  bars met (area-averaged <= 5 %, median point <= 10 %, >= 10x faster): "
              f"{f['meets']}")
    print(f"  report: {out / 'report.json'}; Radiance's grid: {out / 'radiance-grid.csv'}")


def print_markdown(paths):
    """Markdown tables of report.json files: one row per scene and sky (Radiance's reference,
    and the tool against it when there is one); then, for reports made with --reference, a
    row per Radiance setting with its accuracy against the reference and its time."""
    reports = [(p, json.loads(Path(p).read_text())) for p in paths]
    main_rows = [r for _, r in reports if "radiance_vs_reference" not in r]
    ref_rows = [r for _, r in reports if "radiance_vs_reference" in r]
    if main_rows:
        print("| scene, sky | points | Radiance mean / min lux, U | tool mean / min lux, U | "
              "area-averaged | median point | Radiance one-run noise (area / median) | tool | "
              "Radiance one run | ratio at the tool's accuracy |")
        print("|---|---|---|---|---|---|---|---|---|---|")
    for r in main_rows:
        rg = r["radiance"]["grid"]
        nz = r["radiance"]["noise"]
        noise_s = (f"{100 * nz['one_run_area_averaged']:.2f} % / "
                   f"{100 * nz['one_run_median_point']:.2f} %" if nz else "-")
        rcell = f"{rg['mean_lux']:.0f} / {rg['min_lux']:.0f}, {rg['uniformity']:.2f}"
        if "figures" in r:
            tg, f = r["tool"]["grid"], r["figures"]
            tcell = f"{tg['mean_lux']:.0f} / {tg['min_lux']:.0f}, {tg['uniformity']:.2f}"
            cells = [tcell, f"{100 * f['area_averaged_relative_error']:.2f} %",
                     f"{100 * f['median_point_relative_error']:.2f} %", noise_s,
                     f"{f['tool_seconds']:.2f} s" + (f" ({f['tool_cpu_seconds']:.2f} s CPU)"
                                                     if f.get("tool_cpu_seconds") else ""),
                     f"{r['radiance']['seconds_one_run']:.1f} s",
                     (f"{f['speed_ratio_at_tool_accuracy']:.1f}x"
                      if f["speed_ratio_at_tool_accuracy"] else "-")
                     + (f" (CPU {f['cpu_ratio_at_tool_accuracy']:.1f}x)"
                        if f.get("cpu_ratio_at_tool_accuracy") else "")]
        else:
            cells = ["-", "-", "-", noise_s, "-", f"{r['radiance']['seconds_one_run']:.1f} s",
                     "-"]
        print(f"| {r['label']} | {r['points']} | {rcell} | " + " | ".join(cells) + " |")
    if ref_rows:
        if main_rows:
            print()
        print("| scene, sky | rtrace settings | against the reference: area-averaged | "
              "median point | Radiance one run |")
        print("|---|---|---|---|---|")
    for r in ref_rows:
        f = r["radiance_vs_reference"]
        opts = r["radiance"]["rtrace"].split()
        keep = []
        for flag in ("-ab", "-ad", "-as", "-aa", "-ar"):
            if flag in opts:
                keep.append(f"{flag} {opts[opts.index(flag) + 1]}")
        print(f"| {r['label']} | `{' '.join(keep)}` | "
              f"{100 * f['area_averaged_relative_error']:.2f} % | "
              f"{100 * f['median_point_relative_error']:.2f} % | "
              f"{r['radiance']['seconds_one_run']:.2f} s |")


if __name__ == "__main__":
    main()
