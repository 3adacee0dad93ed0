#!/usr/bin/env bash
# Checks that a change leaves the results bit-identical: a default solve of every scene in
# scenes/ (and of the built-in Cornell box) writes byte-identical patches.csv and elements.csv.
#
#   scripts/same_outputs.sh record DIR [BINARY]   solve every scene with BINARY into DIR
#   scripts/same_outputs.sh check DIR [BINARY]    solve again and compare with DIR (exit 1 if any differs)
#
# BINARY defaults to target/release/radiosity (build it first: cargo build --release). Record
# with the commit before a reshape, check with the one after; summary.json and trace.csv hold
# times and are not compared.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
mode=${1:?usage: same_outputs.sh record|check DIR [BINARY]}
dir=${2:?usage: same_outputs.sh record|check DIR [BINARY]}
bin=${3:-target/release/radiosity}
[ -x "$bin" ] || { echo "same_outputs: no binary at $bin (cargo build --release)" >&2; exit 2; }

scenes=(default scenes/*.obj)
fail=0
for s in "${scenes[@]}"; do
  name=$(basename "$s" .obj)
  case "$mode" in
    record) out="$dir/$name" ;;
    check) out=$(mktemp -d) ;;
    *) echo "same_outputs: unknown mode '$mode' (record, check)" >&2; exit 2 ;;
  esac
  mkdir -p "$out"
  if [ "$s" = default ]; then
    "$bin" solve --out "$out" --quiet
  else
    "$bin" solve "$s" --out "$out" --quiet
  fi
  if [ "$mode" = check ]; then
    for f in patches.csv elements.csv; do
      if [ -e "$dir/$name/$f" ] || [ -e "$out/$f" ]; then
        if cmp -s "$dir/$name/$f" "$out/$f"; then
          echo "same   $name/$f"
        else
          echo "DIFFER $name/$f"
          fail=1
        fi
      fi
    done
    rm -rf "$out"
  else
    echo "recorded $name"
  fi
done
exit $fail
