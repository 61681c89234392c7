#!/usr/bin/env bash
# Installs the "client" component of a pullout build into a temporary prefix, then configures,
# builds and runs tests/client/consumer against it with find_package(pullout), checking that:
#   - the package is found in the temporary prefix (not elsewhere),
#   - the installed public headers include no DDS or generated header,
#   - the installed library exports no DDS / generated-type / conversion symbols,
#   - the consumer links and runs with nothing but the package.
# usage: test_package.sh <cmake> <pullout build dir> <consumer source dir>
set -euo pipefail

cmake_bin=$1
build_dir=$2
consumer_src=$3

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
prefix=$work/prefix

fail() { echo "test_package: FAIL: $*" >&2; exit 1; }

"$cmake_bin" --install "$build_dir" --component client --prefix "$prefix" >/dev/null

# The library directory depends on the build's CMAKE_INSTALL_LIBDIR (lib, lib/x86_64-linux-gnu).
config=$(find "$prefix" -name pulloutConfig.cmake | head -n 1)
[ -n "$config" ] || fail "pulloutConfig.cmake not installed"
cmake_dir=$(dirname "$config")
[ -f "$cmake_dir/pulloutConfigVersion.cmake" ] || fail "pulloutConfigVersion.cmake not installed"
case "$cmake_dir" in */cmake/pullout) ;; *) fail "unexpected package directory $cmake_dir" ;; esac
for f in include/pullout/client/client.hpp include/pullout/model/types.hpp include/pullout/model/names.hpp; do
  [ -f "$prefix/$f" ] || fail "$f not installed"
done
lib=$(find "$prefix" -name 'libpullout_client.so.*' -type f | head -n 1)
[ -n "$lib" ] || fail "libpullout_client.so not installed"

if grep -rlE '#include *[<"](fastdds|fastrtps|fastcdr|pullout/msg|pullout/idl)' "$prefix/include"; then
  fail "public headers include DDS or generated headers"
fi
leaked=$(nm -D --defined-only -C "$lib" | grep -E 'eprosima::|pullout::msg::|pullout::idl::|pullout::client_detail::' || true)
[ -z "$leaked" ] || fail "the library exports internal symbols:"$'\n'"$leaked"

generator=()
if command -v ninja >/dev/null 2>&1; then generator=(-G Ninja); fi
"$cmake_bin" -S "$consumer_src" -B "$work/build" "${generator[@]}" \
  -DCMAKE_PREFIX_PATH="$prefix" -DCMAKE_FIND_USE_PACKAGE_REGISTRY=OFF -DCMAKE_BUILD_TYPE=Release >"$work/configure.log" 2>&1 \
  || { cat "$work/configure.log" >&2; fail "consumer configure"; }
grep -q "pullout package: $cmake_dir" "$work/configure.log" \
  || { cat "$work/configure.log" >&2; fail "the package was not found in the temporary prefix"; }
"$cmake_bin" --build "$work/build" >"$work/build.log" 2>&1 || { cat "$work/build.log" >&2; fail "consumer build"; }

output=$("$work/build/pullout_consumer") || fail "consumer exited with $?"
echo "$output"
grep -q "planner name: shift" <<<"$output" || fail "unexpected consumer output"
grep -q "empty vehicle id rejected" <<<"$output" || fail "unexpected consumer output"
echo "test_package: OK"
