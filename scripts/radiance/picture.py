#!/usr/bin/env python3
"""Compare a final-gather picture of the tool with Radiance's rpict of the same view, pixel by pixel.

1. ``radiosity solve MODEL --save`` (timed), then ``radiosity render SOLUTION --shading gather``
   and ``--shading gouraud`` to .hdr with the camera named explicitly (``--eye --target --up
   --fov``, ``--fov`` vertical), each timed.
2. The same OBJ/MTL as a Radiance scene (``objrad.py``; emitters that also reflect get the
   radiance Ke + rho H / pi, as in ``check.py``), ``oconv``, and ``rpict`` with the same view
   (``-vtv -vp -vd -vu -vv -vh``, ``-vh`` from the aspect) at ``--oversample`` times the
   resolution, one jittered ray per pixel (``-ps 1 -pt 0``), box-filtered down with
   ``pfilt -1``: the reference, at converged settings (``--rpict``). ``--matched`` runs
   rpict again at cheaper settings and measures their error against the reference, to find
   Radiance's time at the tool's error.
3. Compared on luminance Y = 0.2126 R + 0.7152 G + 0.0722 B per pixel, on the pixels both see
   with Y above ``--threshold`` times the reference's mean: the mean relative error
   |Y - Y_ref| / Y_ref (the bar aimed at: 5 %), its median, the signed mean, the share above
   10 %, and the same after a 3 x 3 box blur of both (what is left when pixel noise and edge
   aliasing are averaged out: the bias).

Units: rpict writes radiance L (W/sr/m^2); the tool's .hdr holds radiosity B = pi L (W/m^2),
or radiance where a later version writes it so. The script finds which from the median ratio of
the two pictures (close to pi or to 1) and says so.

    PY=.venv-radiance/bin/python
    $PY scripts/radiance/picture.py scenes/office.obj --eye 2.7,1.6,-0.4 --target 2.7,1.1,-5.6 \\
        --fov 60 --out out/picture/office

Writes DIR/report.json, the pictures (tool-gather.hdr, tool-gouraud.hdr, radiance.hdr, PNGs),
DIR/side-by-side.png (Radiance | final gather | Gouraud, one exposure) and DIR/error.png (relative error per pixel, black 0 to white 20 %+), and prints a short table.
Exit code 1 only when something fails to run.
"""

from __future__ import annotations

import argparse
import json
import math
import shlex
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import check  # noqa: E402
import objrad  # noqa: E402
from common import (BINARY_HELP, LUMA, ROOT, children_cpu, parse_emit, radiance_env,  # noqa: E402
                    radiosity_binary, run, vec)


def read_hdr(path: Path, env, binary: Path) -> np.ndarray:
    """A Radiance picture as an (h, w, 3) float array of its original values."""
    res = subprocess.run([binary / "pvalue", "-h", "-o", "-df", "-H", path],
                         capture_output=True, env=env)
    if res.returncode != 0:
        sys.exit(f"pvalue {path} failed: {res.stderr.decode()}")
    info = subprocess.run([binary / "getinfo", "-d", path], capture_output=True, text=True,
                          env=env).stdout.split()
    # "path: -Y h +X w"
    h, w = int(info[-3]), int(info[-1])
    data = np.frombuffer(res.stdout, dtype=np.float32)
    if data.size != h * w * 3:
        sys.exit(f"{path}: {data.size} values for {w}x{h} pixels")
    return data.reshape(h, w, 3).astype(np.float64)


def blur3(y: np.ndarray) -> np.ndarray:
    """3 x 3 box mean (edges: the mean of what is inside)."""
    p = np.pad(y, 1, mode="edge")
    h, w = y.shape
    return sum(p[i:i + h, j:j + w] for i in range(3) for j in range(3)) / 9.0


def figures(y_tool: np.ndarray, y_ref: np.ndarray, threshold: float) -> dict:
    lit_level = threshold * float(y_ref.mean())
    both = (y_ref > lit_level) & (y_tool > lit_level)
    rel = np.abs(y_tool[both] - y_ref[both]) / y_ref[both]
    signed = (y_tool[both] - y_ref[both]) / y_ref[both]
    return {
        "pixels_compared": int(both.sum()),
        "pixels_lit_in_reference_only": int(((y_ref > lit_level) & ~both).sum()),
        "mean_relative_error": float(rel.mean()) if rel.size else None,
        "median_relative_error": float(np.median(rel)) if rel.size else None,
        "signed_mean_error": float(signed.mean()) if rel.size else None,
        "share_above_10_percent": float((rel > 0.10).mean()) if rel.size else None,
        "luminance_ratio_tool_over_reference": float(y_tool[both].sum() / y_ref[both].sum())
        if rel.size else None,
    }


def smooth_mask(y_ref: np.ndarray, spread: float = 0.2) -> np.ndarray:
    """Pixels away from edges: the reference's 3 x 3 neighbourhood within +-spread of the pixel.

    At an edge a pixel's value is its coverage, which the reference's few samples per pixel
    (2 x 2 by default) quantise to quarters: there the reference itself is off by up to 25 %
    of the contrast, so the figures on the other pixels say what the lighting's error is."""
    p = np.pad(y_ref, 1, mode="edge")
    h, w = y_ref.shape
    around = np.stack([p[i:i + h, j:j + w] for i in range(3) for j in range(3)])
    lo, hi = around.min(axis=0), around.max(axis=0)
    return (hi - lo) <= spread * np.maximum(y_ref, 1e-30)


def compare(y_tool, y_ref, threshold):
    smooth = smooth_mask(y_ref)
    away = figures(np.where(smooth, y_tool, 0.0), np.where(smooth, y_ref, 0.0), threshold)
    away["share_of_pixels"] = float(smooth.mean())
    return {"pixels": figures(y_tool, y_ref, threshold),
            "blurred_3x3": figures(blur3(y_tool), blur3(y_ref), threshold),
            "away_from_edges": away}


def write_png(path: Path, y: np.ndarray, scale: float):
    from PIL import Image
    v = np.clip(y * scale, 0, 1) ** (1 / 2.2)
    Image.fromarray((v * 255 + 0.5).astype(np.uint8)).save(path)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter,
                                 epilog=__doc__.split("\n\n", 1)[1])
    ap.add_argument("model", type=Path, help="OBJ file (its MTL beside it)")
    ap.add_argument("--out", type=Path, help="output folder (default out/picture/MODEL)")
    ap.add_argument("--eye", type=vec, required=True)
    ap.add_argument("--target", type=vec, required=True)
    ap.add_argument("--up", type=vec, default=vec("0,1,0"))
    ap.add_argument("--fov", type=float, default=60.0, help="vertical field of view, degrees")
    ap.add_argument("--width", type=int, default=640)
    ap.add_argument("--height", type=int, default=480)
    ap.add_argument("--solve-args", default="", help="extra flags for radiosity solve, quoted")
    ap.add_argument("--render-args", default="",
                    help="extra flags for radiosity render --shading gather, quoted "
                         "(e.g. --pixel-rays 32 --supersample 4)")
    ap.add_argument("--radiosity", help=BINARY_HELP)
    ap.add_argument("--rpict", default="-ab 8 -ad 4096 -as 2048 -aa 0.05 -ar 1024 -lr -12 "
                    "-lw 1e-5 -dj 0 -ds 0.02 -dt 0 -dc 1",
                    help="rpict settings of the reference (default: converged, see the README)")
    ap.add_argument("--reference", choices=["rtrace", "rpict"], default="rtrace",
                    help="how the reference is made: rtrace with Monte Carlo ambient, no cache "
                         "(default), or rpict with --rpict's settings")
    ap.add_argument("--rtrace", default="-ab 12 -ad 256 -as 0 -aa 0 -lr -12 -lw 1e-4 -dt 0 "
                    "-dc 1 -ds 0.02 -dj 0 -dr 0",
                    help="rtrace settings of the reference (--reference rtrace)")
    ap.add_argument("--matched", action="append", default=[], metavar="SETTINGS",
                    help="rpict settings of a cheaper run measured against the reference "
                         "(its time at its error); repeatable")
    ap.add_argument("--oversample", type=int, default=2,
                    help="rpict renders at this many times the resolution, then pfilt (2)")
    ap.add_argument("--threshold", type=float, default=0.01,
                    help="pixels compared: both above this fraction of the reference's mean Y")
    ap.add_argument("--light-passes", type=int, default=3)
    ap.add_argument("--reuse", action="store_true",
                    help="reuse the reference in --out when made for the same view and settings")
    args = ap.parse_args()

    model_path = args.model.resolve()
    out = (args.out or ROOT / "out" / "picture" / model_path.stem).resolve()
    out.mkdir(parents=True, exist_ok=True)
    binary = radiosity_binary(args.radiosity, must_exist=True)
    rbin, env = radiance_env()
    w, h = args.width, args.height
    cam = ["--eye", ",".join(f"{x:.9g}" for x in args.eye),
           "--target", ",".join(f"{x:.9g}" for x in args.target),
           "--up", ",".join(f"{x:.9g}" for x in args.up),
           "--fov", f"{args.fov:.9g}", "--width", str(w), "--height", str(h)]

    # The tool.
    solve_args = shlex.split(args.solve_args)
    sdir = out / "solve"
    sdir.mkdir(exist_ok=True)
    sol = sdir / "solution.rad"
    t0, c0 = time.perf_counter(), children_cpu()
    run([binary, "solve", model_path, "--out", sdir, "--save", sol, "--quiet",
               "--shading", "gouraud", *solve_args])
    solve_seconds = time.perf_counter() - t0
    times = {"solve": solve_seconds}
    cpu = {"solve": children_cpu() - c0}
    reports = {}
    for shading, extra in (("gather", shlex.split(args.render_args)), ("gouraud", [])):
        t0, c0 = time.perf_counter(), children_cpu()
        res = run([binary, "render", sol, "--out", out / f"tool-{shading}.hdr",
                         "--shading", shading, "--json", *cam, *extra])
        times[shading] = time.perf_counter() - t0
        cpu[shading] = children_cpu() - c0
        reports[shading] = json.loads(res.stdout)

    # Radiance.
    fwd = args.target - args.eye
    vh = 2 * math.degrees(math.atan(math.tan(math.radians(args.fov) / 2) * w / h))
    view = ["-vtv", "-vp", *map(str, args.eye), "-vd", *map(str, fwd), "-vu",
            *map(str, args.up), "-vv", str(args.fov), "-vh", f"{vh:.9g}"]
    key = {"model": str(model_path), "mtime": model_path.stat().st_mtime, "view": view,
           "size": [w, h], "reference": args.reference,
           "settings": args.rtrace if args.reference == "rtrace" else args.rpict,
           "oversample": args.oversample,
           "emit": parse_emit(solve_args), "light_passes": args.light_passes}
    saved = out / "radiance.json"
    ref_path = out / "radiance.hdr"
    model = objrad.read_obj(model_path, binary, parse_emit(solve_args))
    octree = None

    def octree_once():
        nonlocal octree
        if octree is None:
            ns = argparse.Namespace(procs=2, ab=12, ad=512, as_=0, aa=0.0, lr=-12, lw=1e-4)
            rad = check.Radiance(ns, out)
            lights, _ = check.light_iteration(model, rad, args.light_passes, 16, 1001)
            octree = rad.octree(model, "scene", lights)
        return octree

    def rpict(settings: str, path: Path) -> tuple[float, float]:
        """Renders, filters down; returns (wall seconds, CPU seconds)."""
        big = path.with_suffix(".big.hdr")
        os_ = args.oversample
        cmd = [rbin / "rpict", *view, "-x", str(w * os_), "-y", str(h * os_), "-pa", "0",
               "-ps", "1", "-pt", "0", "-pj", "0.9", "-i-", *shlex.split(settings),
               octree_once()]
        octree_once()
        t0, c0 = time.perf_counter(), children_cpu()
        with open(big, "wb") as f:
            r = subprocess.run(cmd, stdout=f, stderr=subprocess.PIPE, env=env)
        if r.returncode != 0:
            sys.exit(f"rpict failed: {r.stderr.decode()}")
        with open(path, "wb") as f:
            r = subprocess.run([rbin / "pfilt", "-1", "-e", "1", "-x", f"/{os_}", "-y",
                                f"/{os_}", big], stdout=f, stderr=subprocess.PIPE, env=env)
        if r.returncode != 0:
            sys.exit(f"pfilt failed: {r.stderr.decode()}")
        seconds = time.perf_counter() - t0
        big.unlink()
        return seconds, children_cpu() - c0

    def rtrace(settings: str, path: Path) -> tuple[float, float]:
        """The reference without rpict's irradiance cache (whose interpolation is a bias no
        setting removes quickly): ``vwrays`` (``--oversample``² jittered rays per pixel) into
        ``rtrace -n 2`` with Monte Carlo ambient sampling (``-aa 0``), box-filtered down, written
        as a picture by ``pvalue -r``. Returns (wall seconds, CPU seconds)."""
        os_ = args.oversample
        bw, bh = w * os_, h * os_
        octree_once()
        t0, c0 = time.perf_counter(), children_cpu()
        rays = subprocess.run([rbin / "vwrays", "-ff", *view, "-x", str(bw), "-y", str(bh),
                               "-pa", "0", "-pj", "0.9"], capture_output=True, env=env)
        if rays.returncode != 0:
            sys.exit(f"vwrays failed: {rays.stderr.decode()}")
        r = subprocess.run([rbin / "rtrace", "-h", "-ff", "-n", "2", *shlex.split(settings),
                            octree_once()], input=rays.stdout, capture_output=True, env=env)
        if r.returncode != 0:
            sys.exit(f"rtrace failed: {r.stderr.decode()}")
        px = np.frombuffer(r.stdout, dtype=np.float32).astype(np.float64)
        if px.size != bw * bh * 3:
            sys.exit(f"rtrace gave {px.size} values for {bw}x{bh} rays")
        big = px.reshape(bh, bw, 3)
        small = big.reshape(h, os_, w, os_, 3).mean(axis=(1, 3))
        res = subprocess.run([rbin / "pvalue", "-r", "-h", "-df", "-Y", str(h), "+X", str(w)],
                             input=small.astype(np.float32).tobytes(), capture_output=True,
                             env=env)
        if res.returncode != 0:
            sys.exit(f"pvalue -r failed: {res.stderr.decode()}")
        path.write_bytes(res.stdout)
        return time.perf_counter() - t0, children_cpu() - c0

    cached = json.loads(saved.read_text()) if args.reuse and saved.is_file() else None
    if cached is None or cached.get("key") != key or not ref_path.is_file():
        make = rtrace if args.reference == "rtrace" else rpict
        ref_seconds, ref_cpu = make(args.rpict if args.reference == "rpict" else args.rtrace,
                                    ref_path)
        saved.write_text(json.dumps({"key": key, "seconds": ref_seconds, "cpu": ref_cpu}))
    else:
        ref_seconds, ref_cpu = cached["seconds"], cached.get("cpu", cached["seconds"])
        print(f"Radiance's reference reused from {ref_path} (--reuse)")

    ref = read_hdr(ref_path, env, rbin)
    y_ref = ref @ LUMA
    results = {}
    unit = None
    panels = {}
    for shading in ("gather", "gouraud"):
        img = read_hdr(out / f"tool-{shading}.hdr", env, rbin)
        if img.shape != ref.shape:
            sys.exit(f"tool picture {img.shape} and Radiance's {ref.shape} differ in size")
        y = img @ LUMA
        if unit is None:
            ok = (y > 0) & (y_ref > 0.01 * y_ref.mean())
            ratio = float(np.median(y[ok] / y_ref[ok])) if ok.any() else 1.0
            unit = "radiosity B (W/m^2): divided by pi" if abs(ratio / math.pi - 1) < abs(
                ratio - 1) else "radiance (W/sr/m^2)"
        if unit.startswith("radiosity"):
            y = y / math.pi
            img = img / math.pi
        panels[shading] = img
        results[shading] = compare(y, y_ref, args.threshold)
        if shading == "gather":
            scale = 0.9 / max(float(np.percentile(y_ref, 97)), 1e-30)
            write_png(out / "tool-gather.png", np.repeat(y[..., None], 3, -1), scale)
            write_png(out / "radiance.png", np.repeat(y_ref[..., None], 3, -1), scale)
            lit = (y_ref > args.threshold * y_ref.mean()) & (y > args.threshold * y_ref.mean())
            err = np.where(lit, np.abs(y - y_ref) / np.maximum(y_ref, 1e-30), 0.0)
            write_png(out / "error.png", np.repeat(err[..., None], 3, -1), 5.0)

    # Side by side, one exposure for all (the reference's 97th percentile of Y at 0.9):
    # Radiance | the tool's final gather | its Gouraud preview, 8 px apart.
    scale = 0.9 / max(float(np.percentile(y_ref, 97)), 1e-30)
    gap = np.ones((ref.shape[0], 8, 3)) / scale
    write_png(out / "side-by-side.png",
              np.concatenate([ref, gap, panels["gather"], gap, panels["gouraud"]], axis=1), scale)

    matched = []
    for k, settings in enumerate(args.matched):
        p = out / f"radiance-matched{k + 1}.hdr"
        secs, c = rpict(settings, p)
        y = read_hdr(p, env, rbin) @ LUMA
        matched.append({"rpict": settings, "seconds": secs, "cpu_seconds": c,
                        **compare(y, y_ref, args.threshold)})

    report = {
        "model": str(args.model),
        "view": {"eye": args.eye.tolist(), "target": args.target.tolist(),
                 "up": args.up.tolist(), "fov_vertical": args.fov, "fov_horizontal": vh,
                 "width": w, "height": h},
        "quantity": "luminance Y = 0.2126 R + 0.7152 G + 0.0722 B per pixel",
        "tool_unit": unit,
        "threshold": args.threshold,
        "tool": {"solve_args": solve_args, "render_args": shlex.split(args.render_args),
                 "seconds": times, "cpu_seconds": cpu, "render_reports": reports, "figures": results},
        "radiance": {"reference": args.reference,
                     "settings": args.rtrace if args.reference == "rtrace" else args.rpict,
                     "oversample": args.oversample,
                     "seconds": ref_seconds, "cpu_seconds": ref_cpu, "version": "pyradiance 1.3.1 (RADIANCE 6.0a)"},
        "matched": matched,
    }
    (out / "report.json").write_text(json.dumps(report, indent=1))

    g = results["gather"]["pixels"]
    print(f"{args.model}: {w}x{h}, tool picture in {unit}")
    print(f"{'picture':<34} {'wall s':>8} {'CPU s':>8} {'mean rel':>9} {'median':>8} "
          f"{'signed':>8} {'>10 %':>7} {'blurred':>8} {'no edges':>9}")

    def row(name, secs, c, r):
        p, b, a = r["pixels"], r["blurred_3x3"], r["away_from_edges"]
        print(f"{name:<34} {secs:>8.2f} {c:>8.2f} {100 * p['mean_relative_error']:>8.2f}% "
              f"{100 * p['median_relative_error']:>7.2f}% {100 * p['signed_mean_error']:>+7.2f}% "
              f"{100 * p['share_above_10_percent']:>6.1f}% {100 * b['mean_relative_error']:>7.2f}% "
              f"{100 * a['mean_relative_error']:>8.2f}%")

    row("tool --shading gather (render)", times["gather"], cpu["gather"], results["gather"])
    row("tool --shading gouraud (render)", times["gouraud"], cpu["gouraud"], results["gouraud"])
    print(f"{'tool solve':<34} {solve_seconds:>8.2f} {cpu['solve']:>8.2f}")
    print(f"{args.reference + ' reference':<34} {ref_seconds:>8.2f} {ref_cpu:>8.2f}")
    for m in matched:
        row(f"rpict {m['rpict']}"[:34], m["seconds"], m["cpu_seconds"], m)
    tool_cpu = cpu["solve"] + cpu["gather"]
    print(f"gather: {g['pixels_compared']} pixels compared; tool solve + gather {tool_cpu:.1f} CPU s"
          f" (reference {ref_cpu / tool_cpu:.1f}x that); report in {out / 'report.json'}")
    for m in matched:
        print(f"  rpict {m['rpict']}: {m['cpu_seconds'] / tool_cpu:.1f}x the tool's CPU s at "
              f"{100 * m['pixels']['mean_relative_error']:.2f} % mean relative error")


if __name__ == "__main__":
    main()
