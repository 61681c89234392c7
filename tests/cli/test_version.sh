#!/usr/bin/env bash
# `<program> --version` exits 0 and prints exactly one line: "<name> <project version>", optionally
# followed by " (git <describe>)".
# usage: test_version.sh <executable> <name> <project version>
set -euo pipefail
exe=$1
name=$2
version=$3
status=0
output=$("$exe" --version) || status=$?
[ "$status" -eq 0 ] || { echo "test_version: $exe --version exited with $status" >&2; exit 1; }
lines=$(printf '%s\n' "$output" | wc -l)
[ "$lines" -eq 1 ] || { echo "test_version: expected one line, got $lines:"$'\n'"$output" >&2; exit 1; }
escaped=${version//./\\.}
if ! grep -Eq "^${name} ${escaped}( \(git [^()]+\))?$" <<<"$output"; then
  echo "test_version: unexpected output: $output" >&2
  exit 1
fi
echo "test_version: OK: $output"
