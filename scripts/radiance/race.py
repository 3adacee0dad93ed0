#!/usr/bin/env python3
"""The race: the tool against Radiance at equal error, on the project's own rooms, in one run.

Three races, each the tool's default against Radiance (the ``pyradiance`` wheel) *at the
tool's own accuracy*, in CPU seconds (the tool's threads and Radiance's processes alike: a busy
machine leaves these as they are, wall seconds it does not):

1. **Patch solution** (``check.py --match``): the furnished office + library
   (``furnished.py``, ``furnished-plain.obj``), a default solve's luminance-weighted irradiance
   on sampled patches against a Radiance reference at points spread over each; Radiance's time
   at the tool's area-weighted error measured by single ``rtrace`` runs at a lower ``-ad``.
2. **Picture** (``picture.py --matched``): the same room from the README's view, ``render
   --shading gather`` against an ``rtrace`` reference per pixel; Radiance's time at the tool's
   mean relative error per pixel read off its ``rpict`` runs at three settings (log–log
   between the two that bracket it, or the nearest two).
3. **Daylight grid** (``daylight.py``): the side-lit room of ``daylit.py`` under an overcast
   sky, the default grid's lux against ``rtrace -I``; Radiance's time at the tool's
   area-averaged error measured as ``daylight.py`` does.

Writes ``--results`` (default ``docs/results/race-DATE.md``): the date, the machine, the
commit, every command, and one table of error, CPU seconds and the ratio per race, against the
bar of 20× less CPU than Radiance. The working files go to ``--work`` (default ``out/race``).
``--quick`` runs small versions of each (fewer patches, a smaller picture, one reference run):
a smoke test of the harness, not figures to report.

    PY=.venv-radiance/bin/python
    $PY scripts/radiance/race.py                 # about an hour on the 2-core machine
    $PY scripts/radiance/race.py --quick --results /tmp/race.md
"""

from __future__ import annotations

import argparse
import datetime
import json
import math
import os
import platform
import shlex
import subprocess
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from common import BINARY_HELP, ROOT, radiosity_binary  # noqa: E402

HERE = Path(__file__).resolve().parent
# The bar (CPU seconds, Radiance's at the tool's accuracy over the tool's).
BAR = 20.0
# The picture's view of the furnished room (README, "The commands behind each results page").
VIEW = ["--eye", "0.6,1.6,-0.4", "--target", "6,0.7,-4.6", "--fov", "60"]
# The picture's reference and Radiance's three matched settings (as final-gather-pictures.md).
RT = "-ab 12 -ad 512 -as 0 -aa 0 -lr -12 -lw 1e-4 -dt 0 -dc 1 -ds 0.02 -dj 0 -dr 0"
MATCHED = ["-ab 4 -ad 256 -as 128 -aa 0.15 -ar 128 -lr -8 -lw 5e-4",
           "-ab 5 -ad 256 -as 128 -aa 0.12 -ar 128 -lr -8 -lw 5e-4",
           "-ab 6 -ad 512 -as 256 -aa 0.1 -ar 256 -lr -8 -lw 5e-4"]


def step(cmd: list, log) -> None:
    """Runs one script of the harness, its output to the log and the terminal; stops on failure."""
    line = shlex.join(map(str, cmd))
    print(f"\n$ {line}", flush=True)
    log.write(f"\n$ {line}\n")
    log.flush()
    res = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                         cwd=ROOT)
    print(res.stdout, end="", flush=True)
    log.write(res.stdout)
    if res.returncode != 0:
        sys.exit(f"race: failed ({res.returncode}): {line}")


def loglog_at(points: list[tuple[float, float]], error: float) -> float | None:
    """CPU seconds at `error` from (error, CPU seconds) runs: log-log between the two runs that
    bracket it, else through the two nearest (an extrapolation, said as such by the caller)."""
    pts = sorted((e, c) for e, c in points if e and e > 0 and c and c > 0)
    if len(pts) < 2 or error <= 0:
        return None
    pair = None
    for a, b in zip(pts, pts[1:]):
        if a[0] <= error <= b[0]:
            pair = (a, b)
    if pair is None:
        pair = tuple(sorted(pts, key=lambda p: abs(math.log(p[0] / error)))[:2])
    (e0, c0), (e1, c1) = pair
    if e0 == e1:
        return None
    slope = math.log(c1 / c0) / math.log(e1 / e0)
    return c0 * (error / e0) ** slope


def bracketed(points: list[tuple[float, float]], error: float) -> bool:
    es = [e for e, _ in points if e]
    return bool(es) and min(es) <= error <= max(es)


def common_flags(args) -> list:
    """The flags every race's script takes from ours."""
    return (["--radiosity", args.radiosity] if args.radiosity else []) + \
        (["--reuse"] if args.reuse else [])


def patch_race(py, args, work, log) -> dict:
    model = work / "furnished" / "furnished-plain.obj"
    out = work / "check"
    cmd = [py, HERE / "check.py", model, "--out", out, "--match",
           "--samples", "60" if args.quick else str(args.samples),
           "--repeat", "2", "--procs", str(args.procs)]
    cmd += common_flags(args)
    step(cmd, log)
    r = json.loads((out / "report.json").read_text())
    s = r["solves"][0]
    m = r["radiance"].get("matched")
    # Radiance computed the sampled patches only, the tool every patch: Radiance's time for
    # the whole model is the sampled patches' times the patches over the sampled (its points
    # are spread the same way over every patch).
    scale = r["patches"] / max(r["sampled"], 1)
    return {"race": "patch solution (furnished office + library)",
            "measure": "area-weighted error over sampled patches",
            "tool_error": s["figures"]["area_weighted_relative_error"],
            "tool_cpu": s["times"].get("tool_cpu_seconds"),
            "radiance_cpu": m["cpu_seconds_at_tool_accuracy"] * scale if m else None,
            "how": (f"a bound, not a time: Radiance's cheapest run (-ad "
                    f"{m['ad_at_tool_accuracy']:.0f}, {m['cpu_seconds_at_tool_accuracy']:.1f} s "
                    f"on {r['sampled']} patches) is already more accurate, so the ratio is at most "
                    f"this" if m.get("by") == "bound" else
                    f"measured on {r['sampled']} sampled patches ({len(m['runs'])} single runs, "
                    f"-ad {m['ad_at_tool_accuracy']:.0f}: {m['cpu_seconds_at_tool_accuracy']:.1f} s)")
            + f", × {r['patches']:,} / {r['sampled']} for the whole model"
            if m else "; ".join(r.get("warnings", [])) or "not measured",
            "bound": bool(m and m.get("by") == "bound"),
            "reference_noise": r["radiance"]["noise"]["area_weighted"]}


def picture_race(py, args, work, log) -> dict:
    model = work / "furnished" / "furnished-plain.obj"
    out = work / "picture"
    size = ["--width", "120", "--height", "90"] if args.quick else ["--width", "240",
                                                                    "--height", "180"]
    rt = RT.replace("-ad 512", "-ad 128") if args.quick else RT
    cmd = [py, HERE / "picture.py", model, "--out", out, *VIEW, *size, "--rtrace", rt]
    for m in MATCHED:
        cmd += ["--matched", m]
    cmd += common_flags(args)
    step(cmd, log)
    r = json.loads((out / "report.json").read_text())
    t = r["tool"]
    err = t["figures"]["gather"]["pixels"]["mean_relative_error"]
    cpu = t["cpu_seconds"]["solve"] + t["cpu_seconds"]["gather"]
    runs = [(m["pixels"]["mean_relative_error"], m["cpu_seconds"]) for m in r["matched"]]
    at = loglog_at(runs, err)
    how = ("log-log between the rpict runs that bracket it" if bracketed(runs, err)
           else "extrapolated log-log from the two nearest rpict runs")
    return {"race": "picture (furnished room, render --shading gather)",
            "measure": "mean relative error per pixel",
            "tool_error": err, "tool_cpu": cpu, "radiance_cpu": at,
            "how": f"{how}: " + ", ".join(f"{100 * e:.2f} % in {c:.0f} s" for e, c in runs),
            "reference_noise": None}


def daylight_race(py, args, work, log) -> dict:
    model = work / "daylit" / "sidelit.obj"
    out = work / "daylight"
    cmd = [py, HERE / "daylight.py", model, "--sky", "overcast", "--out", out,
           "--repeat", str(2 if args.quick else args.daylight_repeat), "--procs", str(args.procs)]
    if args.quick:
        cmd += ["--ad", "1024"]
    cmd += common_flags(args)
    step(cmd, log)
    r = json.loads((out / "report.json").read_text())
    f = r["figures"]
    return {"race": "daylight grid (side-lit room, overcast sky)",
            "measure": "area-averaged error of the grid's lux",
            "tool_error": f["area_averaged_relative_error"],
            "tool_cpu": f.get("tool_cpu_seconds"),
            "radiance_cpu": f.get("radiance_cpu_seconds_at_tool_accuracy"),
            "how": f"{f.get('at_tool_accuracy_by') or 'not'} "
                   f"(-ad {f.get('radiance_ad_at_tool_accuracy') or 0:.0f})",
            "reference_noise": (r["radiance"].get("noise") or {}).get("area_averaged")}


def machine() -> str:
    cpu = "unknown processor"
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    mem = os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES") / 2**30
    return f"{platform.platform()}, {os.cpu_count()} cores ({cpu}), {mem:.0f} GiB"


def commit() -> str:
    res = subprocess.run(["git", "describe", "--always", "--dirty"], capture_output=True,
                         text=True, cwd=ROOT)
    return res.stdout.strip() or "unknown"


def pct(x) -> str:
    return "—" if x is None else f"{100 * x:.2f} %"


def secs(x) -> str:
    return "—" if x is None else f"{x:.1f}"


def write_results(path: Path, rows: list[dict], cmds: list[str], args) -> None:
    today = datetime.date.today().isoformat()
    lines = [f"# The race against Radiance ({today})", "",
             f"- **Machine:** {machine()}.",
             f"- **Commit:** `{commit()}`; Radiance 6.0a from `pyradiance` 1.3.1.",
             "- **Command:** `" + shlex.join(["scripts/radiance/race.py", *sys.argv[1:]]) + "`"
             + (" (**quick**: a smoke test of the harness, not figures to report)"
                if args.quick else ""),
             "- **Rule:** the tool's defaults against Radiance at the tool's own accuracy, in "
             "CPU seconds (both sides' processes); the bar is "
             f"{BAR:.0f}× less CPU than Radiance.", "",
             "| race | measure | tool's error | tool CPU s | Radiance CPU s at that error | "
             "ratio | how Radiance's time was found | reference's own noise |",
             "|---|---|---:|---:|---:|---:|---|---:|"]
    for r in rows:
        ratio = (r["radiance_cpu"] / r["tool_cpu"]
                 if r["radiance_cpu"] and r["tool_cpu"] else None)
        mark = "" if ratio is None else (" (meets)" if ratio >= BAR else " (under the bar)")
        if ratio is not None and r.get("bound"):
            mark = " at most (no figure)"
        lines.append(f"| {r['race']} | {r['measure']} | {pct(r['tool_error'])} | "
                     f"{secs(r['tool_cpu'])} | {secs(r['radiance_cpu'])} | "
                     f"{'—' if ratio is None else f'{ratio:.1f}×'}{mark} | {r['how']} | "
                     f"{pct(r['reference_noise'])} |")
    lines += ["", "The commands the race ran (from the repository root):", "", "```sh",
              *cmds, "```", ""]
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text("\n".join(lines))
    print(f"\nrace: results in {path}")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter,
                                 epilog=__doc__.split("\n\n", 1)[1])
    ap.add_argument("--work", type=Path, default=ROOT / "out" / "race",
                    help="working folder (default out/race)")
    ap.add_argument("--results", type=Path,
                    help="the results page (default docs/results/race-DATE.md)")
    ap.add_argument("--quick", action="store_true", help="small races: a smoke test")
    ap.add_argument("--samples", type=int, default=200,
                    help="patches sampled by the patch race (default 200)")
    ap.add_argument("--procs", type=int, default=os.cpu_count() or 1, help="rtrace -n")
    ap.add_argument("--daylight-repeat", type=int, default=8,
                    help="rtrace runs averaged into the daylight grid's reference (default 8: "
                    "with 2, the reference's own noise, 0.85 %%, was most of the 1.14 %% the "
                    "tool was measured at, and the race charged it to the tool)")
    ap.add_argument("--only", choices=("patches", "picture", "daylight"), action="append",
                    help="run only these races (repeatable)")
    ap.add_argument("--reuse", action="store_true",
                    help="keep Radiance's references already in --work when made for the same "
                    "model and settings (the tool is run again)")
    ap.add_argument("--radiosity", help=BINARY_HELP)
    args = ap.parse_args()
    binary = radiosity_binary(args.radiosity)
    if not Path(binary).is_file():
        sys.exit(f"race: no tool binary at {binary} (cargo build --release first)")
    py = sys.executable
    work = args.work.resolve()
    work.mkdir(parents=True, exist_ok=True)
    results = args.results or ROOT / "docs" / "results" / \
        f"race-{datetime.date.today().isoformat()}.md"
    only = set(args.only or ("patches", "picture", "daylight"))
    with open(work / "race.log", "w") as log:
        # With --reuse the models already written are kept: the scripts' references are keyed
        # on the model file's time as well as its contents.
        def keep(path: Path) -> bool:
            return args.reuse and path.is_file()

        if only & {"patches", "picture"} and not keep(work / "furnished" / "furnished-plain.obj"):
            step([py, HERE / "furnished.py", "--out", work / "furnished", "--variant", "plain"], log)
        if "daylight" in only and not keep(work / "daylit" / "sidelit.obj"):
            step([py, HERE / "daylit.py", "--out", work / "daylit", "--scene", "sidelit"], log)
        rows = []
        # The picture last: its Radiance runs (single-process rpict) take longest. The page is
        # written after each race, so a run cut short keeps what it finished.
        for name, race in (("patches", patch_race), ("daylight", daylight_race),
                           ("picture", picture_race)):
            if name in only:
                rows.append(race(py, args, work, log))
                log.flush()
                write_results(results, rows, commands(work), args)


def commands(work: Path) -> list:
    """Every command the race ran so far, as step() logged it, relative to the repository."""
    raced = [line[2:] for line in (work / "race.log").read_text().splitlines()
             if line.startswith("$ ")]
    return [c.replace(str(ROOT) + "/", "").replace(sys.executable, "$PY") for c in raced]


if __name__ == "__main__":
    main()
