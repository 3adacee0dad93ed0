#!/usr/bin/env bash
# Checks that a change leaves the results bit-identical: a default solve of every scene in
# scenes/ (and of the built-in Cornell box) writes byte-identical patches.csv and elements.csv,
# and so do a few other paths through the tool (a final-gather picture and a saved solution, a
# sunlit solve with a sensor grid, render and relight of the saved file, the matrix method and
# the uniform hemi-cube).
#
#   scripts/same_outputs.sh record DIR [BINARY]   run every case with BINARY into DIR
#   scripts/same_outputs.sh check DIR [BINARY]    run again and compare with DIR (exit 1 if any differs)
#
# BINARY defaults to target/release/radiosity (build it first: cargo build --release). Record
# with the commit before a reshape, check with the one after. Every file a case writes is
# compared but summary.json and trace.csv, which hold times.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
root=$(pwd)
mode=${1:?usage: same_outputs.sh record|check DIR [BINARY]}
dir=${2:?usage: same_outputs.sh record|check DIR [BINARY]}
bin=${3:-target/release/radiosity}
[ -x "$bin" ] || { echo "same_outputs: no binary at $bin (cargo build --release)" >&2; exit 2; }
bin=$(cd "$(dirname "$bin")" && pwd)/$(basename "$bin")
case "$mode" in record | check) ;; *) echo "same_outputs: unknown mode '$mode' (record, check)" >&2; exit 2 ;; esac
mkdir -p "$dir"
dir=$(cd "$dir" && pwd)

# name|arguments (run in the case's own folder; $S is scenes/)
S="$root/scenes"
cases=("default|solve --out . --quiet")
for s in "$S"/*.obj; do cases+=("$(basename "$s" .obj)|solve $s --out . --quiet"); done
cases+=(
  "office-gather-saved|solve $S/office.obj --out . --quiet --shading gather --width 160 --height 120 --per-light --save s.rad"
  "office-sun-grid|solve $S/office.obj --out . --quiet --sky clear --sun 45,30 --grid 0.8,0.5"
  "office-render|render ../office-gather-saved/s.rad --out r.png --width 160 --height 120"
  "office-relight|relight ../office-gather-saved/s.rad --weight light_front=2 --out rl.png --width 160 --height 120"
  "blocks-matrix|solve $S/blocks.obj --method gathering --out . --quiet"
  "blocks-hemicube|solve $S/blocks.obj --method hemicube --out . --quiet"
)

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fail=0
for c in "${cases[@]}"; do
  name=${c%%|*}
  args=${c#*|}
  if [ "$mode" = record ]; then out="$dir/$name"; else out="$work/$name"; fi
  rm -rf "$out" && mkdir -p "$out"
  # The render and relight cases read the saved solution of the run they follow.
  args=${args//..\/office-gather-saved/$( [ "$mode" = record ] && echo "$dir" || echo "$work")/office-gather-saved}
  # shellcheck disable=SC2086
  (cd "$out" && "$bin" $args >/dev/null 2>"$out/.stderr") || { echo "FAILED $name: $(tail -1 "$out/.stderr")"; fail=1; continue; }
  rm -f "$out/.stderr"
  if [ "$mode" = record ]; then echo "recorded $name"; continue; fi
  for f in $(cd "$dir/$name" && ls) $(cd "$out" && ls); do
    case "$f" in summary.json | trace.csv) continue ;; esac
    echo "$f"
  done | sort -u | while read -r f; do
    if cmp -s "$dir/$name/$f" "$out/$f"; then echo "same   $name/$f"; else echo "DIFFER $name/$f"; fi
  done | tee "$work/.result"
  grep -q DIFFER "$work/.result" && fail=1
done
exit $fail
