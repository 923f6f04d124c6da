#!/usr/bin/env bash
# Across hosts on this machine's own kernel: network namespaces joined by a bridge make two
# aircraft mission computers, a ground station and a discovery-server host. These are the
# checks of issue 13 that need no netem (the impaired-link checks run in the VM: lab.sh):
#
#   two_vehicles      uav1 and uav2 (same bus and address) on one ground network: every
#                     sample attributed to its vehicle, a command executed only by its vehicle
#   unicast_peers     multicast dropped by nftables on every host: a multicast set-up finds
#                     nothing (the control), unicast peers on both sides work
#   discovery_server  multicast still dropped: service and ground are clients of
#                     `fastdds discovery` on a third host, and work
#   security          DDS-Security on across hosts: the ground-station identity commands, the
#                     mission-computer identity reads but cannot command, a participant
#                     without a certificate sees nothing
#
#   hosts_netns.sh --build-dir DIR [--check NAME]...
#
# Prints "RESULT <name> PASS|FAIL <seconds>s <detail>" per check; exit 0 when all passed,
# 1 when one failed, 77 (skipped) when this machine cannot make namespaces (not root) or
# lacks nft or fastdds (scripts/setup.sh installs nftables and fastdds-tools).
set -uo pipefail

root=$(cd "$(dirname "$0")/../.." && pwd)
build_dir="$root/build/release"
checks=()
while [ $# -gt 0 ]; do
  case "$1" in
    --build-dir) build_dir=$2; shift 2 ;;
    --check) checks+=("$2"); shift 2 ;;
    -h|--help) sed -n '2,22p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "hosts_netns.sh: unknown argument '$1'" >&2; exit 2 ;;
  esac
done
[ ${#checks[@]} -gt 0 ] || checks=(two_vehicles unicast_peers discovery_server security)

skip() { echo "hosts_netns.sh: SKIP: $*" >&2; exit 77; }
[ "$(id -u)" = 0 ] || skip "needs root for network namespaces"
command -v nft >/dev/null || skip "nft not found (scripts/setup.sh installs nftables)"
command -v fast-discovery-server >/dev/null || skip "fast-discovery-server not found (scripts/setup.sh installs fastdds-tools)"
svc=$(find "$build_dir" -type f -name pmu-service -perm -u+x | head -n1)
ctl=$(find "$build_dir" -type f -name pmuctl -perm -u+x | head -n1)
[ -x "$svc" ] && [ -x "$ctl" ] || { echo "hosts_netns.sh: build pmu-service and pmuctl in $build_dir first" >&2; exit 2; }

. "$root/tests/support/dds_domain.sh"
pmu_test_dds_domain || exit 1
domain=$PMU_TEST_DDS_DOMAIN
export PMU_QOS_FILE="$root/deploy/qos.xml"

tag=$$
sw=pmu-sw-$tag
declare -A addr=([air1]=10.78.0.1 [air2]=10.78.0.2 [gnd]=10.78.0.3 [ds]=10.78.0.4)
work=$(mktemp -d /tmp/pmu-hosts.XXXXXX)
pids=()
ns() { echo "pmu-$1-$tag"; }

# Everything still running in a host's namespace (ip netns pids), killed and waited for.
kill_in() {  # HOST [SIGNAL]
  local p
  for p in $(ip netns pids "$(ns "$1")" 2>/dev/null); do kill "-${2:-TERM}" "$p" 2>/dev/null || true; done
  for _ in $(seq 50); do [ -z "$(ip netns pids "$(ns "$1")" 2>/dev/null)" ] && return 0; sleep 0.1; done
  for p in $(ip netns pids "$(ns "$1")" 2>/dev/null); do kill -KILL "$p" 2>/dev/null || true; done
}
cleanup() {
  for h in "${!addr[@]}"; do kill_in "$h"; done
  for p in "${pids[@]}"; do kill "$p" 2>/dev/null || true; done
  wait 2>/dev/null || true
  for h in "${!addr[@]}"; do ip netns del "$(ns "$h")" 2>/dev/null || true; done
  ip netns del "$sw" 2>/dev/null || true
  rm -rf "$work"
}
trap cleanup EXIT

# ---- the network: one bridge in a namespace of its own, one veth per host ------------------
ip netns add "$sw" 2>/dev/null || skip "cannot create network namespaces here"
ip -n "$sw" link add br0 type bridge mcast_snooping 0
ip -n "$sw" link set br0 up
i=0
for h in air1 air2 gnd ds; do
  ip netns add "$(ns "$h")"
  ip link add "p$i" netns "$sw" type veth peer name eth0 netns "$(ns "$h")"
  ip -n "$sw" link set "p$i" master br0 up
  ip -n "$(ns "$h")" addr add "${addr[$h]}/24" dev eth0
  ip -n "$(ns "$h")" link set lo up
  ip -n "$(ns "$h")" link set eth0 up
  ip -n "$(ns "$h")" route add 224.0.0.0/4 dev eth0
  i=$((i + 1))
done

on() { local h=$1; shift; ip netns exec "$(ns "$h")" "$@"; }
pmuctl_on() { local h=$1; shift; on "$h" "$ctl" --domain "$domain" "$@"; }

# Multicast out of every host dropped (the routed network or radio that carries none).
drop_multicast() {
  for h in air1 air2 gnd ds; do
    on "$h" nft -f - <<'EOF'
table inet pmu_lab {
  chain out { type filter hook output priority 0; policy accept; ip daddr 224.0.0.0/4 counter drop; }
}
EOF
  done
}
allow_multicast() { for h in air1 air2 gnd ds; do on "$h" nft delete table inet pmu_lab 2>/dev/null || true; done; }
multicast_dropped() {  # packets the rules dropped on HOST
  on "$1" nft list table inet pmu_lab | sed -n 's/.*counter packets \([0-9]*\).*/\1/p' | head -n1
}

# pmu-service on HOST for VEHICLE, with extra top-level config lines from stdin.
start_service() {  # HOST VEHICLE
  local h=$1 v=$2 cfg="$work/$1.yaml"
  { echo "domain: $domain"; echo "vehicle: $v"; echo "qos_file: $PMU_QOS_FILE"; echo "dds_transport: udp"
    echo "log_level: info"; cat
    printf 'buses:\n  - interface: sim\n    name: can0\n    devices:\n      - address: 1\n        period: 0.5\n'; } > "$cfg"
  # ip netns exec execs the program: $! is the service itself.
  ip netns exec "$(ns "$h")" "$svc" --config "$cfg" > "$work/$h.log" 2>&1 &
  pids+=($!)
}
stop_services() { kill_in air1; kill_in air2; }  # kill_in waits until each namespace is empty

result() {  # NAME START FAILURES DETAIL
  local t; t=$(( $(date +%s) - $2 ))
  if [ "$3" -eq 0 ]; then echo "RESULT $1 PASS ${t}s $4"; else echo "RESULT $1 FAIL ${t}s $4"; failed=1; fi
}
fail() { echo "  [$check] FAIL: $*" >&2; failures=$((failures + 1)); }
jq_py() { python3 -c "import json,sys
lines=[json.loads(l) for l in sys.stdin if l.strip().startswith('{')]
$1"; }

# ---- the checks ------------------------------------------------------------------------------
check_two_vehicles() {
  start_service air1 uav1 </dev/null
  start_service air2 uav2 </dev/null
  local seen="" t0 out
  t0=$(date +%s)
  while [ $(( $(date +%s) - t0 )) -lt 40 ]; do
    seen=$(pmuctl_on gnd --timeout 10 --json list 2>/dev/null | jq_py 'print(" ".join(sorted({l["vehicle"] for l in lines if l["bus"]=="can0" and l["address"]==1})))')
    [ "$seen" = "uav1 uav2" ] && break
  done
  [ "$seen" = "uav1 uav2" ] || fail "the ground station sees vehicles '$seen', expected 'uav1 uav2'"
  out=$(pmuctl_on gnd --vehicle uav1 --json watch --count 20 --timeout 20 2>&1)
  local other; other=$(echo "$out" | jq_py 'print(sum(1 for l in lines if l["vehicle"] != "uav1"), len(lines))')
  [ "$other" = "0 20" ] || fail "watch --vehicle uav1: (samples of another vehicle, samples) = $other"
  out=$(pmuctl_on gnd --vehicle uav1 --timeout 20 --json config set payload_voltage 23 2>&1)
  echo "$out" | grep -q '"result":"COMPLETED"' && echo "$out" | grep -q '"vehicle":"uav1"' || fail "uav1's command: $out"
  out=$(pmuctl_on gnd --vehicle uav2 --timeout 10 config get payload_voltage 2>&1)
  echo "$out" | grep -q '^uav2/can0/1 payload_voltage = ' || fail "uav2's config: $out"
  echo "$out" | grep -q 'payload_voltage = 23.0' && fail "uav2 executed uav1's command: $out"
  out=$(pmuctl_on gnd --vehicle uav1 --timeout 10 config get payload_voltage 2>&1)
  echo "$out" | grep -q '^uav1/can0/1 payload_voltage = 23.0' || fail "uav1's config after its command: $out"
  grep -q 'audit: command .*payload_voltage=23 .*COMPLETED' "$work/air2.log" && fail "uav2's audit trail has the command"
  grep -q 'audit: command .*payload_voltage=23 .*COMPLETED' "$work/air1.log" || fail "uav1's audit trail lacks the command"
  detail="vehicles seen: $seen; command on uav1 only"
  stop_services
}

check_unicast_peers() {
  drop_multicast
  # Control: multicast discovery cannot work any more, so what follows proves the peers.
  start_service air1 uav1 </dev/null
  local out
  out=$(pmuctl_on gnd --vehicle uav1 --json watch --count 1 --timeout 8 2>&1)
  echo "$out" | grep -q '"topic"' && fail "with multicast dropped, multicast discovery still found the service: the drop is not working"
  local dropped; dropped=$(multicast_dropped air1)
  [ "${dropped:-0}" -gt 0 ] || fail "no multicast packet was dropped on air1 (the control proves nothing)"
  stop_services
  start_service air1 uav1 <<EOF
discovery:
  mode: unicast
  peers: [${addr[gnd]}]
EOF
  out=$(pmuctl_on gnd --peer "${addr[air1]}" --vehicle uav1 --json watch --count 10 --timeout 30 2>&1)
  [ "$(echo "$out" | grep -c '"topic"')" -eq 10 ] || fail "unicast peers: telemetry: $out"
  out=$(pmuctl_on gnd --peer "${addr[air1]}" --vehicle uav1 --timeout 20 --json config set payload_voltage 22 2>&1)
  echo "$out" | grep -q '"result":"COMPLETED"' || fail "unicast peers: command: $out"
  detail="multicast dropped ($dropped packets in the control), unicast telemetry and command work"
  stop_services
  allow_multicast
}

check_discovery_server() {
  drop_multicast
  # The server itself (`fastdds discovery` is a wrapper that outlives a signal); SIGINT stops it.
  ip netns exec "$(ns ds)" fast-discovery-server -i 0 -l "${addr[ds]}" -p 11811 > "$work/ds.log" 2>&1 &
  pids+=($!)
  start_service air1 uav1 <<EOF
discovery:
  mode: server
  servers: ["${addr[ds]}:11811"]
EOF
  local out
  out=$(pmuctl_on gnd --discovery-server "${addr[ds]}:11811" --vehicle uav1 --json watch --count 10 --timeout 30 2>&1)
  [ "$(echo "$out" | grep -c '"topic"')" -eq 10 ] || fail "discovery server: telemetry: $out"
  out=$(pmuctl_on gnd --discovery-server "${addr[ds]}:11811" --vehicle uav1 --timeout 20 --json config set payload_voltage 21 2>&1)
  echo "$out" | grep -q '"result":"COMPLETED"' || fail "discovery server: command: $out"
  detail="multicast dropped; service and ground found each other through fastdds discovery on ${addr[ds]}"
  stop_services
  kill_in ds INT
  allow_multicast
}

check_security() {
  local pki="$work/pki"
  "$root/deploy/security/make_pki.sh" "$pki" --domain "$domain" --days 2 > "$work/pki.log" 2>&1 || { fail "make_pki.sh: $(tail -3 "$work/pki.log")"; return; }
  start_service air1 uav1 <<EOF
security:
  identity_ca: $pki/identity_ca.pem
  identity_certificate: $pki/pmu-service/cert.pem
  private_key: $pki/pmu-service/key.pem
  permissions_ca: $pki/permissions_ca.pem
  governance: $pki/governance.p7s
  permissions: $pki/pmu-service/permissions.p7s
EOF
  local out
  out=$(pmuctl_on gnd --security-dir "$pki" --identity ground-station --vehicle uav1 --timeout 30 --json config set payload_voltage 20 2>&1)
  # One more participant if the first met no service: once in a loaded full run the secure
  # handshake had not completed within 30 s (seen once, not reproduced alone). What is checked
  # is that the command gets through at all, and once.
  echo "$out" | grep -q '"result":"COMPLETED"' ||
    out=$(pmuctl_on gnd --security-dir "$pki" --identity ground-station --vehicle uav1 --timeout 30 --json config set payload_voltage 20 2>&1)
  echo "$out" | grep -q '"result":"COMPLETED"' || fail "ground-station identity: command: $(echo "$out" | tail -3)"
  out=$(pmuctl_on gnd --security-dir "$pki" --identity mission-computer --vehicle uav1 --json watch --count 5 --timeout 30 2>&1)
  [ "$(echo "$out" | grep -c '"topic"')" -eq 5 ] || fail "mission-computer identity: telemetry: $(echo "$out" | tail -3)"
  out=$(pmuctl_on gnd --security-dir "$pki" --identity mission-computer --vehicle uav1 --timeout 10 config set payload_voltage 21 2>&1)
  echo "$out" | grep -q 'COMPLETED' && fail "the mission-computer identity commanded: $out"
  out=$(pmuctl_on gnd --vehicle uav1 --json watch --count 1 --timeout 8 2>&1)
  echo "$out" | grep -q '"topic"' && fail "a participant without a certificate received telemetry: $(echo "$out" | head -2)"
  grep -q 'audit: command .*payload_voltage=21' "$work/air1.log" && fail "the audit trail has the mission computer's command"
  detail="ground-station commands across hosts; mission-computer reads only; no certificate, no data"
  stop_services
}

failed=0
for check in "${checks[@]}"; do
  declare -F "check_$check" >/dev/null || { echo "hosts_netns.sh: unknown check '$check'" >&2; exit 2; }
  failures=0
  detail=""
  start=$(date +%s)
  "check_$check"
  stop_services
  allow_multicast
  result "$check" "$start" "$failures" "$detail"
  if [ "$failures" -gt 0 ]; then
    for h in air1 air2; do [ -f "$work/$h.log" ] && sed "s/^/  [$check $h] /" "$work/$h.log" | tail -15 >&2; done
  fi
done
exit "$failed"
