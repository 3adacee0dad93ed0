#!/usr/bin/env bash
# Times two builds of the tool against each other on one model, both started at once with one
# thread each (each on its own core of a 2-core machine), so a drift in the machine's speed
# between runs (seen up to 25 % here) falls on both alike; the ratio of their stage seconds is
# the comparison. Prints the stage seconds of each from its summary.json.
#
#   scripts/side_by_side.sh MODEL BINARY_A BINARY_B [solve flags...]
#
# The solve is `solve MODEL --elements off --error off --threads 1 --quiet` plus the flags
# given (e.g. --tolerance 0.2 to shorten the shooting of a large model). Alternate A and B
# between rounds (run it again with the two swapped) and take the ratio over rounds.
set -euo pipefail
model=${1:?usage: side_by_side.sh MODEL BINARY_A BINARY_B [solve flags...]}
a=${2:?usage: side_by_side.sh MODEL BINARY_A BINARY_B [solve flags...]}
b=${3:?usage: side_by_side.sh MODEL BINARY_A BINARY_B [solve flags...]}
shift 3
for bin in "$a" "$b"; do
  [ -x "$bin" ] || { echo "side_by_side: no binary at $bin" >&2; exit 2; }
done
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
run() { "$1" solve "$model" --out "$2" --elements off --error off --threads 1 --quiet "${@:3}" >"$2.log" 2>&1; }
run "$a" "$work/a" "$@" &
pa=$!
run "$b" "$work/b" "$@" &
pb=$!
wait "$pa" || { echo "side_by_side: $a failed (see its log below)" >&2; cat "$work/a.log" >&2; exit 1; }
wait "$pb" || { echo "side_by_side: $b failed (see its log below)" >&2; cat "$work/b.log" >&2; exit 1; }
for side in a b; do
  bin=$a
  [ "$side" = b ] && bin=$b
  python3 - "$work/$side/summary.json" "$bin" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
sec, fg = s["seconds"], s.get("final_gather") or {}
print(f"{sys.argv[2]}: gather {fg.get('seconds', 0.0):.2f} s, solve {sec['solve']:.2f} s, "
      f"sides {sec['sides']:.2f} s, total {sec['total']:.2f} s, CPU {s['cpu_seconds']['total']:.2f} s")
PY
done
