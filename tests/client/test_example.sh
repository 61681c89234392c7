#!/usr/bin/env bash
# The embedding example (examples/vehicle_client) as a vehicle team uses it: install the "client"
# component into a temporary prefix, check that it carries the DDS profiles, build the example
# with find_package(pullout) against that prefix only, then run it against the real
# pullout_service on loopback (a DDS domain leased like the C++ tests do, by flock on
# /tmp/pullout-dds-domain-N.lock). Checks that
#   - without its approval the example does not depart (exit 4, never "executing"),
#   - with it, the vehicle is released ("executing") and follows both segments (reverse, then
#     shift out past a parked car) to "completed".
# usage: test_example.sh <cmake> <pullout build dir> <example source dir> <pullout_service> <config>
set -euo pipefail

cmake_bin=$1
build_dir=$2
example_src=$3
service_exe=$4
config=$5

work=$(mktemp -d)
service_pid=""
cleanup() {
  if [ -n "$service_pid" ] && kill -0 "$service_pid" 2>/dev/null; then
    kill -TERM "$service_pid" 2>/dev/null || true
    wait "$service_pid" 2>/dev/null || true
  fi
  rm -rf "$work"
}
trap cleanup EXIT
fail() {
  echo "test_example: FAIL: $*" >&2
  [ -f "$work/service.err" ] && { echo "--- service stderr ---" >&2; tail -n 30 "$work/service.err" >&2; }
  exit 1
}

prefix=$work/prefix
"$cmake_bin" --install "$build_dir" --component client --prefix "$prefix" >/dev/null
for f in share/pullout/dds/loopback.xml share/pullout/dds/network.xml; do
  [ -f "$prefix/$f" ] || fail "$f not installed"
done

generator=()
if command -v ninja >/dev/null 2>&1; then generator=(-G Ninja); fi
"$cmake_bin" -S "$example_src" -B "$work/build" "${generator[@]}" \
  -DCMAKE_PREFIX_PATH="$prefix" -DCMAKE_FIND_USE_PACKAGE_REGISTRY=OFF -DCMAKE_BUILD_TYPE=Release \
  >"$work/configure.log" 2>&1 || { cat "$work/configure.log" >&2; fail "example configure"; }
grep -q "DDS profiles in $prefix/share/pullout/dds" "$work/configure.log" \
  || { cat "$work/configure.log" >&2; fail "pullout_DDS_PROFILES_DIR is not the installed profiles folder"; }
"$cmake_bin" --build "$work/build" >"$work/build.log" 2>&1 || { cat "$work/build.log" >&2; fail "example build"; }
example=$work/build/pullout_vehicle_client

# Bad arguments are exit status 2 at once, before any DDS: a domain that is no number must not
# become domain 0 (atoi did that, and the example then waited 15 s for a service there).
for bad in "--domain abc" "--domain 5x" "--domain 999" "--domain -1" "--vehicle ''" "--domain"; do
  status=0
  eval timeout 10 "$example" "$bad" >"$work/bad.out" 2>&1 || status=$?
  [ "$status" -eq 2 ] || { cat "$work/bad.out" >&2; fail "'$bad' exited with $status (expected 2)"; }
  case "$bad" in
    "--domain "?*) grep -q -- "--domain" "$work/bad.out" || { cat "$work/bad.out" >&2; fail "'$bad': --domain not named"; } ;;
  esac
done

# --help prints the usage on stdout and is no error.
timeout 10 "$example" --help >"$work/help.out" 2>&1 || { cat "$work/help.out" >&2; fail "--help exited with an error"; }
grep -q "^usage: pullout_vehicle_client" "$work/help.out" || { cat "$work/help.out" >&2; fail "--help printed no usage"; }

# A DDS domain of our own (the lock is released when this shell exits).
domain=""
for i in $(seq 0 98); do
  d=$(( ($$ + i) % 99 + 1 ))
  exec {lock_fd}>"/tmp/pullout-dds-domain-$d.lock"
  if flock -n "$lock_fd"; then domain=$d; break; fi
  exec {lock_fd}>&-
done
[ -n "$domain" ] || fail "no free DDS domain"

"$service_exe" --config "$config" --domain "$domain" --log-level warn >"$work/service.out" 2>"$work/service.err" &
service_pid=$!

# Without approval: no departure.
status=0
timeout 60 "$example" --domain "$domain" --vehicle example-refused >"$work/refused.out" 2>&1 || status=$?
cat "$work/refused.out"
[ "$status" -eq 4 ] || fail "without --approve the example exited with $status (expected 4)"
if grep -q "^executing" "$work/refused.out"; then fail "departed without approval"; fi

# With approval: released, every segment followed, completed.
status=0
timeout 90 "$example" --domain "$domain" --vehicle example-approved --approve >"$work/approved.out" 2>&1 || status=$?
cat "$work/approved.out"
[ "$status" -eq 0 ] || fail "the example exited with $status"
grep -q "^executing$" "$work/approved.out" || fail "never executing"
grep -q "^segment 2/2" "$work/approved.out" || fail "the two segments (reverse, shift) were not followed"
grep -q "^completed$" "$work/approved.out" || fail "never completed"

kill -TERM "$service_pid"
status=0
wait "$service_pid" || status=$?
service_pid=""
[ "$status" -eq 0 ] || fail "the service exited with $status after SIGTERM"
echo "test_example: OK"
