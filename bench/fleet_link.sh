#!/usr/bin/env bash
# A fleet over a radio link: what N aircraft cost a 250 kbit/s ground link, and whether the
# ground station still sees and commands them all.
#
#   bench/fleet_link.sh [--aircraft "1 4 8"] [--rate 250kbit] [--build-dir DIR] [--qos FILE]
#                       [--pmuctl BIN] [--service BIN] [--discovery-server [--server-xml FILE|none]]
#                       [--json FILE]
#
# Two network namespaces joined by one veth pair, shaped by tbf to RATE each way (a radio
# modem's queue of about 2 s; no delay or loss: the VM lab adds those): in `air`, N pmu-service
# (vehicles uav1..uavN, UDP only on the veth, one simulated PMU each, packets every 0.5 s); in
# `gnd`, the ground station's pmuctl. For each N, after a 20 s warm-up:
#   idle     10 s with no ground participant: discovery announcements alone
#   list     one `pmuctl --json list`: bytes over the link, seconds, vehicles listed of N
#   command  one `pmuctl --vehicle uavN config set payload_voltage 13.0`: bytes, seconds, result
#   low      10 s of `pmuctl watch --low-rate` (started 15 s before): the steady cost of watching
# Bytes are the ground interface's received + sent IP bytes; drops are the tbf queues'.
# --qos, --pmuctl and --service measure another qos.xml, pmuctl or pmu-service (a before and
# after, one run each). --discovery-server: Fast DDS's Discovery Server (fast-discovery-server)
# runs on the ground host with the shipped deploy/discovery-server.xml (--server-xml: another
# file, or none for the program's own defaults), and the services and pmuctl are its clients. Needs root (ip netns); exit status 77 when namespaces cannot be made.
set -euo pipefail

root=$(cd "$(dirname "$0")/.." && pwd)
build_dir="$root/build/release"
aircraft="1 4 8"
rate=250kbit
qos="$root/deploy/qos.xml"
ctl=""
json_out=""
ds=0
svc=""
server_xml="$root/deploy/discovery-server.xml"
while [ $# -gt 0 ]; do
  case "$1" in
    --aircraft) aircraft=$2; shift 2 ;;
    --rate) rate=$2; shift 2 ;;
    --build-dir) build_dir=$2; shift 2 ;;
    --qos) qos=$(realpath "$2"); shift 2 ;;
    --pmuctl) ctl=$(realpath "$2"); shift 2 ;;
    --json) json_out=$2; shift 2 ;;
    --service) svc=$(realpath "$2"); shift 2 ;;
    --discovery-server) ds=1; shift ;;
    --server-xml) server_xml=$2; [ "$2" = none ] || server_xml=$(realpath "$2"); shift 2 ;;
    -h|--help) sed -n '2,21p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "fleet_link.sh: unknown argument '$1'" >&2; exit 2 ;;
  esac
done
[ -n "$svc" ] || svc=$(find "$build_dir" -type f -name pmu-service -perm -u+x | head -n1)
[ -n "$ctl" ] || ctl=$(find "$build_dir" -type f -name pmuctl -perm -u+x | head -n1)
[ -x "$svc" ] && [ -x "$ctl" ] || { echo "fleet_link.sh: build pmu-service and pmuctl in $build_dir first" >&2; exit 2; }
[ -r "$qos" ] || { echo "fleet_link.sh: cannot read $qos" >&2; exit 2; }
[ "$(id -u)" = 0 ] || { echo "fleet_link.sh: SKIP: needs root for network namespaces" >&2; exit 77; }

. "$root/tests/support/dds_domain.sh"
pmu_test_dds_domain || exit 1
domain=$PMU_TEST_DDS_DOMAIN
air=pmu-fleet-air-$$
gnd=pmu-fleet-gnd-$$
work=$(mktemp -d /tmp/pmu-fleet-link.XXXXXX)
stop_all() { for p in $(ip netns pids "$air" 2>/dev/null) $(ip netns pids "$gnd" 2>/dev/null); do kill "$p" 2>/dev/null || true; done; }
cleanup() {
  stop_all
  sleep 1
  ip netns del "$air" 2>/dev/null || true
  ip netns del "$gnd" 2>/dev/null || true
  rm -rf "$work"
}
trap cleanup EXIT

# The link, made anew for every fleet size so that no queue or discovery state carries over.
link_up() {
  ip netns del "$air" 2>/dev/null || true
  ip netns del "$gnd" 2>/dev/null || true
  ip netns add "$air" && ip netns add "$gnd" || { echo "fleet_link.sh: SKIP: cannot create network namespaces here" >&2; exit 77; }
  ip link add air0 netns "$air" type veth peer name gnd0 netns "$gnd"
  ip -n "$air" addr add 10.79.0.1/24 dev air0
  ip -n "$gnd" addr add 10.79.0.2/24 dev gnd0
  local ns dev
  for ns in "$air" "$gnd"; do
    dev=air0; [ "$ns" = "$gnd" ] && dev=gnd0
    ip -n "$ns" link set lo up
    ip -n "$ns" link set "$dev" up
    ip -n "$ns" route add default dev "$dev"  # SPDP multicast leaves here
    # A radio modem's queue: about 2 s at 250 kbit/s.
    ip netns exec "$ns" tc qdisc add dev "$dev" root tbf rate "$rate" burst 3000 limit 64000
  done
}
link_bytes() {
  ip -n "$gnd" -j -s link show gnd0 | python3 -c 'import json,sys; s=json.load(sys.stdin)[0]["stats64"]; print(s["rx"]["bytes"] + s["tx"]["bytes"])'
}
link_drops() {
  echo $(( $(ip netns exec "$air" tc -s -j qdisc show dev air0 | python3 -c 'import json,sys; print(json.load(sys.stdin)[0]["drops"])') +
           $(ip netns exec "$gnd" tc -s -j qdisc show dev gnd0 | python3 -c 'import json,sys; print(json.load(sys.stdin)[0]["drops"])') ))
}
ds_option=()
[ "$ds" = 1 ] && ds_option=(--discovery-server 10.79.0.2)
pmuctl_gnd() { PMU_QOS_FILE="$qos" ip netns exec "$gnd" "$ctl" --domain "$domain" --interface gnd0 "${ds_option[@]}" --json "$@"; }
now() { date +%s.%N; }

rows=()
for n in $aircraft; do
  link_up
  ds_yaml=""
  if [ "$ds" = 1 ]; then
    command -v fast-discovery-server >/dev/null || { echo "fleet_link.sh: fast-discovery-server not found (fastdds-tools)" >&2; exit 2; }
    xml_option=()
    [ "$server_xml" = none ] || xml_option=(-x "$server_xml")
    ip netns exec "$gnd" fast-discovery-server -i 0 -l 10.79.0.2 -p 11811 "${xml_option[@]}" >"$work/server.log" 2>&1 &
    ds_yaml="discovery: {mode: server, servers: [10.79.0.2]}"
  fi
  for i in $(seq 1 "$n"); do
    cat >"$work/uav$i.yaml" <<EOF
domain: $domain
vehicle: uav$i
qos_file: $qos
dds_transport: udp
interfaces: [air0]
log_level: warn
$ds_yaml
buses:
  - interface: sim
    name: sim0
    devices:
      - address: 1
        period: 0.5
EOF
    ip netns exec "$air" "$svc" --config "$work/uav$i.yaml" >"$work/uav$i.log" 2>&1 &
  done
  sleep 20
  b0=$(link_bytes); sleep 10; b1=$(link_bytes)
  idle=$(( (b1 - b0) / 10 ))

  d0=$(link_drops); b0=$(link_bytes); t0=$(now)
  pmuctl_gnd --timeout 20 list >"$work/list.out" 2>"$work/list.err" || true
  t1=$(now); b1=$(link_bytes)
  listed=$(sed -n 's/.*"vehicle":"\([^"]*\)".*/\1/p' "$work/list.out" | sort -u | wc -l)
  list_bytes=$((b1 - b0)); list_s=$(python3 -c "print(round($t1 - $t0, 2))")
  sleep 5

  b0=$(link_bytes); t0=$(now)
  pmuctl_gnd --vehicle "uav$n" --timeout 30 config set payload_voltage 13.0 >"$work/cmd.out" 2>"$work/cmd.err" || true
  t1=$(now); b1=$(link_bytes)
  result=$(sed -n 's/.*"result":"\([A-Z_]*\)".*/\1/p' "$work/cmd.out" | head -n1)
  [ -n "$result" ] || result="none ($(tail -n1 "$work/cmd.err" | tr -d '"' | cut -c1-60))"
  cmd_bytes=$((b1 - b0)); cmd_s=$(python3 -c "print(round($t1 - $t0, 2))")
  sleep 5

  pmuctl_gnd watch --low-rate >"$work/low.out" 2>/dev/null &
  watcher=$!
  sleep 15  # the watcher's own discovery and the state it gets first are not the steady cost
  b0=$(link_bytes); l0=$(wc -l <"$work/low.out"); sleep 10; b1=$(link_bytes); l1=$(wc -l <"$work/low.out")
  kill "$watcher" 2>/dev/null || true; wait "$watcher" 2>/dev/null || true
  low=$(( (b1 - b0) / 10 )); low_samples=$(python3 -c "print(round(($l1 - $l0) / 10, 1))")
  drops=$(( $(link_drops) - d0 ))

  rows+=("$n $idle $list_bytes $list_s $listed $cmd_bytes $cmd_s $result $low $low_samples $drops")
  stop_all
  wait 2>/dev/null || true
done

ROWS=$(printf '%s\n' "${rows[@]}") python3 - "$rate" "$json_out" "$qos" "$ctl" "$ds" "$svc" "$server_xml" <<'PY'
import json, os, re, sys
rate, json_out, qos, ctl, ds, svc, server_xml = sys.argv[1:8]
m = re.match(r"(\d+)kbit", rate)
cap = int(m.group(1)) * 1000 / 8 if m else None
out = []
print(f"fleet over a {rate} link (tbf each way){', Discovery Server on the ground (' + server_xml + ')' if ds == '1' else ''}; qos {qos}; pmuctl {ctl}; pmu-service {svc}")
print("| aircraft | idle B/s | list: bytes, s, listed | command: bytes, s, result | watch --low-rate B/s (samples/s) | low-rate watch / one way's capacity | queue drops |")
print("|---|---|---|---|---|---|---|")
for line in os.environ["ROWS"].splitlines():
    f = line.split(" ", 7)
    n, idle, lb, ls, listed, cb, cs = (int(f[0]), int(f[1]), int(f[2]), float(f[3]), int(f[4]), int(f[5]), float(f[6]))
    rest = f[7].rsplit(" ", 3)
    result, low, low_samples, drops = rest[0], int(rest[1]), float(rest[2]), int(rest[3])
    share = f"{low / cap:.2f}" if cap else "-"
    print(f"| {n} | {idle} | {lb}, {ls} s, {listed} of {n} | {cb}, {cs} s, {result} | {low} ({low_samples}) | {share} | {drops} |")
    out.append(dict(aircraft=n, idle_bytes_per_s=idle, list_bytes=lb, list_seconds=ls, listed=listed,
                    command_bytes=cb, command_seconds=cs, command_result=result,
                    low_rate_bytes_per_s=low, low_rate_samples_per_s=low_samples, drops=drops))
if json_out:
    with open(json_out, "w") as fh:
        json.dump({"rate": rate, "qos": qos, "pmuctl": ctl, "pmu_service": svc, "discovery_server": ds == "1",
                   "server_xml": server_xml if ds == "1" else None, "rows": out}, fh, indent=1)
PY
