#!/usr/bin/env bash
# Several hosts without multicast: the service and a client on two "hosts" (network namespaces
# joined by a veth pair, each with its own /dev/shm so that shared memory cannot carry DDS between
# them) with multicast dropped by nftables on both. Checks, each with a real request answered by
# a path:
#   1. discovery server: fast-discovery-server (`fastdds discovery`) beside the service, both participants its clients
#      (config/dds/discovery_client.xml, ROS_DISCOVERY_SERVER);
#   2. initial peers: the client lists the service's address (config/dds/initial_peers.xml with
#      the placeholder filled in), the service runs the plain network profile;
#   3. negative control: the plain network profile on both sides (multicast discovery) finds no
#      service across the link (and, before multicast is blocked, it does: 0. positive control).
# Root only (namespaces, nft): exits 77 (ctest: skipped) with the reason otherwise. Everything it
# creates (namespaces, processes, files) is removed on exit, whatever happens.
#
#   test_multi_host.sh PULLOUT_SERVICE PULLOUT_CLI SOURCE_DIR
set -euo pipefail
service_exe="$1"
cli_exe="$2"
src="$3"

skip() {
  echo "SKIPPED: $*"
  exit 77
}
[ "$(id -u)" -eq 0 ] || skip "needs root (creates network namespaces)"
ip netns list >/dev/null 2>&1 || skip "no 'ip netns' (iproute2)"
command -v nft >/dev/null || skip "no nft (Debian package nftables, in scripts/setup)"
command -v fast-discovery-server >/dev/null || skip "no fast-discovery-server (Debian package fastdds-tools, in scripts/setup)"
command -v unshare >/dev/null || skip "no unshare (util-linux)"

tag="pomh$$"
ns_a="$tag-a"  # the service's host (and the discovery server's)
ns_b="$tag-b"  # the vehicle's host
addr_a=10.231.7.1
addr_b=10.231.7.2
work="$(mktemp -d /tmp/pullout-multi-host.XXXXXX)"
pids=()

cleanup() {
  local rc=$?
  set +e
  for pid in "${pids[@]}"; do kill -TERM "$pid" 2>/dev/null; done
  for pid in "${pids[@]}"; do
    for _ in $(seq 50); do kill -0 "$pid" 2>/dev/null || break; sleep 0.1; done
    kill -KILL "$pid" 2>/dev/null
    wait "$pid" 2>/dev/null
  done
  ip netns del "$ns_a" 2>/dev/null
  ip netns del "$ns_b" 2>/dev/null
  rm -rf "$work"
  exit $rc
}
trap cleanup EXIT
trap 'exit 130' INT TERM

fail() {
  echo "FAILED: $*" >&2
  for f in "$work"/*.err; do
    [ -s "$f" ] && { echo "--- $f" >&2; tail -n 20 "$f" >&2; }
  done
  exit 1
}

ip netns add "$ns_a"
ip netns add "$ns_b"
ip link add "$tag-va" type veth peer name "$tag-vb"
ip link set "$tag-va" netns "$ns_a"
ip link set "$tag-vb" netns "$ns_b"
ip -n "$ns_a" addr add "$addr_a/24" dev "$tag-va"
ip -n "$ns_b" addr add "$addr_b/24" dev "$tag-vb"
for ns in "$ns_a" "$ns_b"; do ip -n "$ns" link set lo up; done
ip -n "$ns_a" link set "$tag-va" up
ip -n "$ns_b" link set "$tag-vb" up

# A command prefix that runs a command on a host: in its namespace, with a /dev/shm of its own.
# Every step execs the next, so a background job's $! is the PID of the command itself.
host_a=(ip netns exec "$ns_a" unshare --mount --propagation private
  sh -c 'mount -t tmpfs -o size=64m tmpfs /dev/shm && exec "$@"' sh)
host_b=(ip netns exec "$ns_b" unshare --mount --propagation private
  sh -c 'mount -t tmpfs -o size=64m tmpfs /dev/shm && exec "$@"' sh)

# Starts the service on host A with the given environment; its PID goes to $service_pid.
start_service() {
  local name="$1"
  shift
  "${host_a[@]}" env "$@" "$service_exe" --config "$work/pullout.yaml" >"$work/$name.service.out" \
    2>"$work/$name.service.err" &
  service_pid=$!
  pids+=("$service_pid")
  # Ready: its DDS entities exist (the line it logs once they do).
  for _ in $(seq 150); do
    grep -q "pullout_service ready" "$work/$name.service.err" 2>/dev/null && return 0
    kill -0 "$service_pid" 2>/dev/null || fail "$name: the service exited at start-up"
    sleep 0.1
  done
  fail "$name: the service did not get ready within 15 s"
}

# SIGTERM to the service; it must exit with status 0.
stop_service() {
  local name="$1" rc=0
  kill -TERM "$service_pid"
  wait "$service_pid" || rc=$?
  [ "$rc" -eq 0 ] || fail "$name: the service exited with status $rc after SIGTERM"
}

# The client on host B plans the demo scenario; prints its exit status, the reply in $work/$name.json.
request() {
  local name="$1" profile="$2" timeout_s="$3"
  shift 3
  local rc=0
  "${host_b[@]}" env "$@" "$cli_exe" request "$src/tests/scenarios/straight_shoulder.yaml" --json \
    --profiles "$profile" --timeout "$timeout_s" >"$work/$name.json" 2>"$work/$name.client.err" || rc=$?
  echo "$rc"
}

# A found path with at least one segment of at least two points.
check_path() {
  local name="$1"
  grep -q '"found": *true' "$work/$name.json" || fail "$name: no path in the reply: $(head -c 300 "$work/$name.json")"
  grep -q '"points": *[2-9]' "$work/$name.json" || grep -q '"points": *[1-9][0-9]' "$work/$name.json" ||
    fail "$name: a segment with fewer than 2 points"
}

printf 'service: {worker_threads: 1}\n' >"$work/pullout.yaml"
cp -r "$src/config/dds" "$work/dds"
sed "s/PULLOUT_PEER_ADDRESS/$addr_a/" "$src/config/dds/initial_peers.xml" >"$work/peers.xml"
! grep -q PULLOUT_PEER_ADDRESS "$work/peers.xml" || fail "placeholder left in peers.xml"

# --- 0. positive control: before multicast is blocked, multicast discovery crosses the link ---
start_service open PULLOUT_DDS_PROFILE=network
rc="$(request open "$work/dds/network.xml" 30)"
[ "$rc" -eq 0 ] || fail "multicast, not blocked: the client exited with status $rc"
check_path open
stop_service open
echo "ok: multicast discovery works across the link while multicast is not blocked"

# Multicast does not cross this network from now on: dropped on the way out and on the way in.
for ns in "$ns_a" "$ns_b"; do
  ip netns exec "$ns" nft -f - <<'EOF'
table inet pullout_no_multicast {
  chain out { type filter hook output priority 0; ip daddr 224.0.0.0/4 drop; }
  chain in { type filter hook input priority 0; ip daddr 224.0.0.0/4 drop; }
}
EOF
done

# --- 1. discovery server ---
# fast-discovery-server is what `fastdds discovery` (a Python wrapper) runs; started directly so
# that its PID is the server's.
"${host_a[@]}" fast-discovery-server -i 0 -l "$addr_a" -p 11811 >"$work/server.out" 2>"$work/server.err" &
server_pid=$!
pids+=("$server_pid")
server="$addr_a:11811"
start_service discovery PULLOUT_DDS_PROFILE=discovery_client ROS_DISCOVERY_SERVER="$server"
rc="$(request discovery "$work/dds/discovery_client.xml" 30 ROS_DISCOVERY_SERVER="$server")"
[ "$rc" -eq 0 ] || fail "discovery server: the client exited with status $rc"
check_path discovery
stop_service discovery
echo "ok: discovery server ($server): path received, service stopped cleanly"

# --- 2. initial peers ---
start_service peers PULLOUT_DDS_PROFILE=network
rc="$(request peers "$work/peers.xml" 30)"
[ "$rc" -eq 0 ] || fail "initial peers: the client exited with status $rc"
check_path peers
stop_service peers
echo "ok: initial peers ($addr_a): path received, service stopped cleanly"

# --- 3. negative control: multicast discovery does not cross the link ---
start_service multicast PULLOUT_DDS_PROFILE=network
rc="$(request multicast "$work/dds/network.xml" 8)"
[ "$rc" -eq 3 ] || fail "multicast only: the client exited with status $rc, expected 3 (no service found)"
grep -q "no pullout service found" "$work/multicast.client.err" ||
  fail "multicast only: expected 'no pullout service found', got: $(head -c 300 "$work/multicast.client.err")"
kill -0 "$service_pid" 2>/dev/null || fail "multicast only: the service is not running (so the control proves nothing)"
stop_service multicast
echo "ok: multicast discovery finds no service across the link (client exit status 3)"
