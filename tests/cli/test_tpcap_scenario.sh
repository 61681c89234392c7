#!/usr/bin/env bash
# A TPCAP case (../shared/benchmarks/tpcap, never committed) turned into a scenario file by
# bench/tpcap_to_scenario plans through `pullout plan`: case 1, case 13 (one of the three lying
# ~5e9 m out, re-centred) and case 7 (parallel parking into a slot barely longer than the car:
# solved only against the true polygons, which the file gives as objects; as grid cells the slot
# is closed and the search times out) and case 20 (a maze of L-shaped walls: the published path
# must not be cut short against their convex hulls, which cover its start). Skipped (exit 77)
# when the shared cases are not here.
#   test_tpcap_scenario.sh TPCAP_TO_SCENARIO PULLOUT CASES_DIR
set -euo pipefail
convert="$1" pullout="$2" cases="$3"
if [ ! -f "$cases/Case1.csv" ]; then
  echo "SKIP: no TPCAP cases in $cases"
  exit 77
fi
dir="$(mktemp -d)"
trap 'rm -rf "$dir"' EXIT
for n in 1 13 7 20; do
  "$convert" "$cases/Case$n.csv" "$dir/case$n.yaml"
  grep -q "^grid:" "$dir/case$n.yaml"
  grep -q "^objects:" "$dir/case$n.yaml"
  out="$("$pullout" plan "$dir/case$n.yaml" --json)"
  if ! grep -q '"found": true' <<<"$out" || ! grep -q '"planner": "freespace"' <<<"$out"; then
    echo "case $n: not planned: $out" >&2
    exit 1
  fi
  # The whole path is published: no stop before an object (a cut says "stops ... before object").
  if grep -q 'stops [0-9.]* m before object' <<<"$out"; then
    echo "case $n: the published path is cut: $out" >&2
    exit 1
  fi
  # Re-centred: the start's rear axle is the origin.
  grep -q "^start: {x: 0, y: 0," "$dir/case$n.yaml"
done
echo "TPCAP cases 1, 13, 7 and 20 plan as scenario files, their paths published whole"
