"""What every script of the Radiance harness shares: where the tool and Radiance are, running
them, reading the tool's outputs, and the photometric constants.

- :func:`radiosity_binary`, :func:`run`, :func:`children_cpu`: the tool's binary (``--radiosity``,
  else ``$RADIOSITY``, else ``$CARGO_TARGET_DIR`` or ``target``, ``/release/radiosity``), a
  command run to completion (stops the script with its stderr when it fails), and the CPU
  seconds of the finished children (the tool's threads and Radiance's processes alike).
- :func:`radiance_env`, :func:`oconv`, :func:`rtrace_rgb`: the pyradiance wheel's Radiance
  (``scripts/radiance/setup.sh`` installs it), an octree frozen from scene files, and the
  three numbers per line of an ``rtrace`` run.
- :func:`tool_info`: ``radiosity info --json``, the tool's own account of a model, whose
  ``materials`` are the materials exactly as the tool's loader made them (rho after the clamp
  and its source, Ke after ``--emit``, the glazing's transmittance per channel): the scripts
  take materials from there and never read an MTL themselves.
- :func:`parse_emit`, :func:`read_patches`, :func:`vec`, :func:`r6`: ``--emit`` among a solve's
  flags, the tool's ``patches.csv``, an ``X,Y,Z`` argument, and a coordinate rounded to the
  micrometre.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import shlex
import subprocess
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
# Rec. 709 luminance weights (luminance-weighted irradiance Y, per patch and per pixel).
LUMA = np.array([0.2126, 0.7152, 0.0722])
# Radiance's RGB -> luminance weights and white-light efficacy (lux), as the tool's.
PHOTOPIC = np.array([0.265, 0.670, 0.065])
EFFICACY = 179.0  # lm/W

BINARY_HELP = ("the radiosity binary (default $RADIOSITY, else $CARGO_TARGET_DIR or target, "
               "/release/radiosity)")


# --------------------------------------------------------------------------------------------
# Running things.


def run(cmd, **kw):
    """Run a command; on failure print its stderr and stop with exit code 1."""
    res = subprocess.run(cmd, capture_output=True, text=True, **kw)
    if res.returncode != 0:
        sys.stderr.write(f"failed: {shlex.join(map(str, cmd))}\n{res.stderr}\n")
        sys.exit(1)
    return res


def children_cpu() -> float:
    """CPU seconds (user + system) of this script's finished children: the tool's threads,
    ``rtrace``/``rpict`` and the processes they fork. A busy machine leaves these as they are
    (wall seconds it does not), so speed ratios are judged on them."""
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


# --------------------------------------------------------------------------------------------
# The tool.


def radiosity_binary(arg: str | None, must_exist: bool = False) -> Path:
    """The tool's binary: ``arg`` (``--radiosity``), else ``$RADIOSITY``, else the release build."""
    if arg:
        path = Path(arg)
    elif os.environ.get("RADIOSITY"):
        path = Path(os.environ["RADIOSITY"])
    else:
        path = Path(os.environ.get("CARGO_TARGET_DIR", ROOT / "target")) / "release" / "radiosity"
    if must_exist and not path.is_file():
        sys.exit(f"no radiosity binary at {path} (cargo build --release, or --radiosity)")
    return path


def parse_emit(solve_args) -> dict:
    """``--emit MATERIAL=R,G,B`` flags among a solve's arguments, by material."""
    emit = {}
    for i, a in enumerate(solve_args):
        if a == "--emit" and i + 1 < len(solve_args):
            name, _, val = solve_args[i + 1].rpartition("=")
            emit[name] = tuple(float(x) for x in val.split(","))
        elif a.startswith("--emit="):
            name, _, val = a[len("--emit="):].rpartition("=")
            emit[name] = tuple(float(x) for x in val.split(","))
    return emit


def tool_info(binary: Path, model: Path, emit: dict | None = None) -> dict:
    """``radiosity info --json MODEL [--emit NAME=R,G,B ...]``: the model as the tool loads it."""
    flags = []
    for name, ke in (emit or {}).items():
        flags += ["--emit", f"{name}=" + ",".join(f"{k:.9g}" for k in ke)]
    return json.loads(run([binary, "info", "--json", model, *flags]).stdout)


def read_patches(path: Path):
    """The tool's ``patches.csv`` (or ``elements.csv``) as a structured array by column name."""
    return np.genfromtxt(path, delimiter=",", names=True)


# --------------------------------------------------------------------------------------------
# Radiance.


def radiance_env():
    """(bin folder, environment with RAYPATH) of the pyradiance wheel's Radiance."""
    import pyradiance

    pkg = Path(pyradiance.__file__).parent
    env = dict(os.environ)
    env["RAYPATH"] = str(pkg / "lib")
    env["PATH"] = str(pkg / "bin") + os.pathsep + env.get("PATH", "")
    return pkg / "bin", env


def oconv(bin_dir: Path, env: dict, scene_files, octree: Path) -> Path:
    """``oconv -f FILES > OCTREE`` (frozen, so the octree stands alone); stops on failure."""
    with open(octree, "wb") as f:
        res = subprocess.run([bin_dir / "oconv", "-f", *scene_files], stdout=f,
                             stderr=subprocess.PIPE, env=env)
    if res.returncode != 0:
        sys.exit(f"oconv failed: {res.stderr.decode()}")
    return octree


def ray_lines(origins: np.ndarray, dirs: np.ndarray) -> str:
    """rtrace's input: one ``x y z dx dy dz`` line per ray."""
    return "".join(f"{o[0]:.9g} {o[1]:.9g} {o[2]:.9g} {d[0]:.9g} {d[1]:.9g} {d[2]:.9g}\n"
                   for o, d in zip(origins, dirs))


def rtrace_rgb(stdout: str, expected: int) -> np.ndarray:
    """The first three numbers of each output line of ``rtrace -h`` (RGB), checked in number."""
    vals = np.array([[float(x) for x in line.split()[:3]]
                     for line in stdout.splitlines() if line.strip()])
    if len(vals) != expected:
        sys.exit(f"rtrace gave {len(vals)} values for {expected} points")
    return vals


# --------------------------------------------------------------------------------------------
# Arguments.


def r6(x: float) -> float:
    """A coordinate rounded to the micrometre, so faces meant to touch have equal coordinates
    (the scene writers, ``furnished.py`` and ``daylit.py``)."""
    return round(float(x), 6) + 0.0


def vec(text: str) -> np.ndarray:
    """An ``X,Y,Z`` argument."""
    v = np.array([float(x) for x in text.split(",")])
    if v.shape != (3,):
        raise argparse.ArgumentTypeError(f"expected X,Y,Z, got {text!r}")
    return v
