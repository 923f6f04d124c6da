#!/usr/bin/env bash
# A fleet over a radio link: what N aircraft cost a 250 kbit/s ground link, and whether the
# ground station still sees and commands them all.
#
#   bench/fleet_link.sh [--aircraft "1 4 8"] [--rate 250kbit] [--build-dir DIR] [--qos FILE]
#                       [--pmuctl BIN] [--service BIN] [--discovery-server [--server-xml FILE|none]]
#                       [--cut SECONDS] [--agent] [--loss PERCENT] [--link PROFILE] [--json FILE]
#                       [--keep DIR [--capture]] [--breakdown] [--low-rate-period S]
#
# Two network namespaces joined by one veth pair, shaped by tbf to RATE each way (a radio
# modem's queue of about 2 s; no delay or loss: the VM lab adds those): in `air`, N pmu-service
# (vehicles uav1..uavN, UDP only on the veth, one simulated PMU each, packets every 0.5 s); in
# `gnd`, the ground station's pmuctl. For each N, after a 20 s warm-up:
#   idle     10 s with no ground participant: discovery announcements alone
#   list     one `pmuctl --json list`: bytes over the link, seconds, vehicles listed of N
#   command  one `pmuctl --vehicle uavN config set payload_voltage 13.0`: bytes, seconds, result
#   low      10 s of `pmuctl watch --low-rate` (started 15 s before): the steady cost of watching
# Bytes are the ground interface's received + sent bytes (the veth counts each IP packet and
# its 14-byte Ethernet header; --breakdown counts IP bytes); drops are the tbf queues', from
# the list to the watch's end and, after discovery, in the watch's measured 10 s.
# --qos, --pmuctl and --service measure another qos.xml, pmuctl or pmu-service (a before and
# after, one run each). --discovery-server: Fast DDS's Discovery Server (fast-discovery-server)
# runs on the ground host with the shipped deploy/discovery-server.xml (--server-xml: another
# file, or none for the program's own defaults), and the services and pmuctl are its clients.
# With it, two more steps per N, and a second table:
#   round    one `pmuctl --vehicle uavI config set payload_voltage` to each aircraft in turn:
#            each call's seconds (start to exit), p50 / p99 / max (nearest rank), COMPLETED of N
#   cut      the veth down for CUT s (30), then up: seconds from its return until a `pmuctl
#            list` lists all N, and until a command to each (all at once, after that list)
#            COMPLETED; then every command's id is counted in the services' audit trails
#            (`audit: command ID ...` lines): executions must equal commands, none twice
# --agent: the ground's pmuctl calls go through one `pmuctl agent`, started in `gnd` after the
# idle step (so its first call, the list, pays for its participants' discovery); watch is
# never served by an agent and runs on its own as before. Without it, calls run on their own.
# --loss PERCENT: each namespace drops that share of the packets it sends on the veth, at
# random (nftables; the VM lab's netem also delays, which a namespace here cannot).
# --link PROFILE: the link profile on both sides: `link: {profile: PROFILE}` in every service's
# config and `--link PROFILE` on every pmuctl call and the agent (interface.md section 7.3).
# --keep DIR: the run's logs (services, agent, calls) are copied to DIR at the end; with
# --capture also a packet capture of the ground interface per fleet size (link-N.pcap, whole
# packets) and when each step began (steps-N: its name, uptime and wall-clock time, which the
# capture's timestamps use; `low` and `low-end` bound the watch's measured 10 s).
# --breakdown: capture (as --capture) and print, per fleet size, what the low-rate watch's
# measured 10 s were spent on, by RTPS submessage kind and by topic (bench/rtps_breakdown.py;
# also breakdown-N.md with --keep). --low-rate-period S: the services' config low_rate_period
# (interface.md 1.5; default theirs, 1 s).
# Needs root (ip netns); exit status 77 when namespaces cannot be made. Exit status 1 when
# a --discovery-server run found a command executed twice or by another vehicle.
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
cut_s=30
agent=0
keep=""
capture=0
breakdown=0
low_rate_period=""
loss=0
link_profile=""
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
    --cut) cut_s=$2; shift 2 ;;
    --agent) agent=1; shift ;;
    --loss) loss=$2; shift 2 ;;
    --keep) keep=$2; shift 2 ;;
    --capture) capture=1; shift ;;
    --breakdown) breakdown=1; capture=1; shift ;;
    --low-rate-period) low_rate_period=$2; shift 2 ;;
    --link) link_profile=$2; shift 2 ;;
    -h|--help) sed -n '2,48p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "fleet_link.sh: unknown argument '$1'" >&2; exit 2 ;;
  esac
done
[ "$capture" = 0 ] || [ "$breakdown" = 1 ] || [ -n "$keep" ] || { echo "fleet_link.sh: --capture needs --keep DIR" >&2; exit 2; }
case "$loss" in '' | *[!0-9]* ) echo "fleet_link.sh: --loss takes a whole percentage, 0..99 (got '$loss')" >&2; exit 2 ;; esac
[ "$loss" -lt 100 ] || { echo "fleet_link.sh: --loss takes a whole percentage, 0..99 (got '$loss')" >&2; exit 2; }
case "$low_rate_period" in *[!0-9.]*) echo "fleet_link.sh: --low-rate-period takes seconds (got '$low_rate_period')" >&2; exit 2 ;; esac
case "$cut_s" in '' | *[!0-9]* | 0) echo "fleet_link.sh: --cut takes whole seconds, at least 1 (got '$cut_s')" >&2; exit 2 ;; esac
for n in $aircraft; do
  case "$n" in '' | *[!0-9]* | 0) echo "fleet_link.sh: --aircraft takes counts of at least 1 (got '$n')" >&2; exit 2 ;; esac
  [ "$n" -le 60 ] || { echo "fleet_link.sh: at most 60 aircraft (their two commands each set payload_voltage to its own value in 12.1..24.0)" >&2; exit 2; }
done
# A missing build directory is the error below, not find's.
[ -n "$svc" ] || svc=$(find "$build_dir" -type f -name pmu-service -perm -u+x 2>/dev/null | head -n1 || true)
[ -n "$ctl" ] || ctl=$(find "$build_dir" -type f -name pmuctl -perm -u+x 2>/dev/null | head -n1 || true)
[ -x "$svc" ] && [ -x "$ctl" ] || { echo "fleet_link.sh: build pmu-service and pmuctl in $build_dir first" >&2; exit 2; }
[ -r "$qos" ] || { echo "fleet_link.sh: cannot read $qos" >&2; exit 2; }
[ "$capture" = 0 ] || command -v tcpdump >/dev/null || { echo "fleet_link.sh: --capture and --breakdown need tcpdump" >&2; exit 2; }
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
  if [ -n "$keep" ]; then mkdir -p "$keep" && cp -r "$work"/. "$keep"/; fi
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
    if [ "$loss" -gt 0 ]; then
      ip netns exec "$ns" nft add table inet lossy &&
        ip netns exec "$ns" nft add chain inet lossy out '{ type filter hook output priority 0; }' &&
        ip netns exec "$ns" nft add rule inet lossy out oifname "$dev" numgen random mod 100 '<' "$loss" drop ||
        { echo "fleet_link.sh: --loss needs nftables (nft) in this kernel" >&2; exit 2; }
    fi
  done
  if [ "$capture" = 1 ]; then
    ip netns exec "$gnd" tcpdump -i gnd0 -s 0 -w "$work/link-$1.pcap" >/dev/null 2>&1 &
    sleep 1
  fi
}
# step NAME: the uptime a step starts at, for a capture's reader (--capture).
step() { echo "$1 $(cut -d' ' -f1 /proc/uptime) $(date +%s.%N)" >>"$work/steps-$n"; }
link_bytes() {
  ip -n "$gnd" -j -s link show gnd0 | python3 -c 'import json,sys; s=json.load(sys.stdin)[0]["stats64"]; print(s["rx"]["bytes"] + s["tx"]["bytes"])'
}
link_drops() {
  echo $(( $(ip netns exec "$air" tc -s -j qdisc show dev air0 | python3 -c 'import json,sys; print(json.load(sys.stdin)[0]["drops"])') +
           $(ip netns exec "$gnd" tc -s -j qdisc show dev gnd0 | python3 -c 'import json,sys; print(json.load(sys.stdin)[0]["drops"])') ))
}
ds_option=()
[ "$ds" = 1 ] && ds_option=(--discovery-server 10.79.0.2)
link_yaml=""
if [ -n "$link_profile" ]; then
  ds_option+=(--link "$link_profile")
  link_yaml="link: {profile: $link_profile}"
fi
# Without --agent the socket names nothing, so an agent of this host's user is never used.
pmuctl_gnd() {
  if [ "${exec_gnd:-0}" = 1 ]; then  # in a subshell of its own: become pmuctl
    PMU_AGENT_SOCKET="$work/agent.sock" PMU_QOS_FILE="$qos" exec ip netns exec "$gnd" "$ctl" --domain "$domain" --interface gnd0 "${ds_option[@]}" --json "$@"
  fi
  PMU_AGENT_SOCKET="$work/agent.sock" PMU_QOS_FILE="$qos" ip netns exec "$gnd" "$ctl" --domain "$domain" --interface gnd0 "${ds_option[@]}" --json "$@"
}
start_agent() {
  PMU_AGENT_SOCKET="$work/agent.sock" PMU_QOS_FILE="$qos" ip netns exec "$gnd" "$ctl" --domain "$domain" --interface gnd0 "${ds_option[@]}" agent >"$work/agent.log" 2>&1 &
  local i
  for i in $(seq 1 50); do [ -S "$work/agent.sock" ] && return 0; sleep 0.1; done
  echo "fleet_link.sh: the agent did not start: $(cat "$work/agent.log")" >&2; exit 1
}
now() { date +%s.%N; }
# The audit trail (`audit: command ...` lines) is logged at info.
svc_log_level=warn
[ "$ds" = 1 ] && svc_log_level=info
# Command K of a run sets payload_voltage to its own value (12.1, 12.2, ...).
value_for() { printf '%d.%d' $((12 + $1 / 10)) $(($1 % 10)); }
# timed_command VEHICLE VALUE: "SECONDS RESULT REQUEST_ID END" of one pmuctl config set, start to exit.
timed_command() {
  local t0 t1 out
  t0=$(now)
  out=$(pmuctl_gnd --vehicle "$1" --timeout 30 config set payload_voltage "$2" 2>>"$work/commands.err" | head -n1) || true
  t1=$(now)
  python3 -c '
import json, sys
t0, t1 = float(sys.argv[1]), float(sys.argv[2])
try:
    j = json.loads(sys.argv[3])
except ValueError:
    j = {}
result, request = j.get("result") or "none", j.get("request_id") or "none"
print(f"{t1 - t0:.2f} {result} {request} {t1:.3f}")' "$t0" "$t1" "$out"
}
vehicles_listed() { sed -n 's/.*"vehicle":"\([^"]*\)".*/\1/p' "$1" | sort -u | wc -l; }
# The command round, the cut and the audit count of one fleet (--discovery-server runs): a
# row of the second table.
round_and_cut() {  # N
  local n=$1 i t_up t_list pids=() r listed_s
  : >"$work/round"; : >"$work/after"
  step round
  for i in $(seq 1 "$n"); do
    r=$(timed_command "uav$i" "$(value_for "$i")")
    echo "uav$i $r" >>"$work/round"
  done
  # A radio fade as the interface sees it: the carrier gone, on both ends, for cut_s seconds.
  step cut
  ip -n "$gnd" link set gnd0 down
  sleep "$cut_s"
  ip -n "$gnd" link set gnd0 up
  t_up=$(now)
  step restored
  # Down deleted the routes through gnd0; only the default one (for multicast) is not re-made.
  ip -n "$gnd" route replace default dev gnd0
  listed_s=none
  while python3 -c "import sys; sys.exit(not float(sys.argv[2]) - float(sys.argv[1]) < 120)" "$t_up" "$(now)"; do
    pmuctl_gnd --timeout 10 list >"$work/relist.out" 2>/dev/null || true
    if [ "$(vehicles_listed "$work/relist.out")" -ge "$n" ]; then
      t_list=$(now); listed_s=$(python3 -c "print(round($t_list - $t_up, 2))"); break
    fi
    sleep 0.5
  done
  # Then a command to each at once: the whole fleet checked after the link's return.
  step at-once
  for i in $(seq 1 "$n"); do
    (r=$(timed_command "uav$i" "$(value_for $((n + i)))"); echo "uav$i $r" >>"$work/after") &
    pids+=($!)
  done
  for i in "${pids[@]}"; do wait "$i" || true; done
  step finished
  python3 - "$n" "$work" "$t_up" "$listed_s" <<'PY'
import re, sys
n, work, t_up, listed = int(sys.argv[1]), sys.argv[2], float(sys.argv[3]), sys.argv[4]
def read(name):
    rows = []
    for line in open(f"{work}/{name}"):
        v, secs, result, rid, end = line.split()
        rows.append(dict(vehicle=v, secs=float(secs), result=result, id=rid, end=float(end)))
    return rows
round_, after = read("round"), read("after")
def rank(values, p):
    v = sorted(values)
    return v[max(0, -(-len(v) * p // 100) - 1)]
secs = [r["secs"] for r in round_]
done_round = sum(r["result"] == "COMPLETED" for r in round_)
done_after = sum(r["result"] == "COMPLETED" for r in after)
back = max(r["end"] for r in after) - t_up if after else float("nan")
# Every execution is one `audit: command ID from ...` line in the log of the service that ran it.
ids = {r["id"]: r["vehicle"] for r in round_ + after if r["id"] != "none"}
executed, dupes, problems = {}, 0, []
for i in range(1, n + 1):
    for line in open(f"{work}/uav{i}.log", errors="replace"):
        m = re.search(r"audit: command (\S+) from .* -> ([A-Z_]+)", line)
        if m and "reuses that id" not in line and m.group(1) in ids:
            executed.setdefault(m.group(1), []).append(f"uav{i}")
        if re.search(r"audit: duplicate command \S+ from", line):
            dupes += 1
for rid, vehicle in ids.items():
    ran = executed.get(rid, [])
    if len(ran) > 1 or any(v != vehicle for v in ran):
        problems.append(f"{rid} for {vehicle} executed by {','.join(ran)}")
execs = sum(len(v) for v in executed.values())
print(f"{rank(secs, 50):.2f} {rank(secs, 99):.2f} {max(secs):.2f} {done_round} {listed} {back:.2f} {done_after} "
      f"{execs} {len(round_) + len(after)} {dupes} {len(problems)}")
for p in problems:
    print("fleet_link.sh: " + p, file=sys.stderr)
PY
}

rows=()
ds_rows=()
for n in $aircraft; do
  link_up "$n"
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
log_level: $svc_log_level
${low_rate_period:+low_rate_period: $low_rate_period}
$ds_yaml
$link_yaml
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
  [ "$agent" = 1 ] && start_agent

  d0=$(link_drops); b0=$(link_bytes); t0=$(now)
  step list
  pmuctl_gnd --timeout 20 list >"$work/list.out" 2>"$work/list.err" || true
  t1=$(now); b1=$(link_bytes)
  listed=$(sed -n 's/.*"vehicle":"\([^"]*\)".*/\1/p' "$work/list.out" | sort -u | wc -l)
  list_bytes=$((b1 - b0)); list_s=$(python3 -c "print(round($t1 - $t0, 2))")
  sleep 5

  b0=$(link_bytes); t0=$(now)
  step command
  pmuctl_gnd --vehicle "uav$n" --timeout 30 config set payload_voltage 13.0 >"$work/cmd.out" 2>"$work/cmd.err" || true
  t1=$(now); b1=$(link_bytes)
  result=$(sed -n 's/.*"result":"\([A-Z_]*\)".*/\1/p' "$work/cmd.out" | head -n1)
  [ -n "$result" ] || result="none ($(tail -n1 "$work/cmd.err" | tr -d '"' | cut -c1-60))"
  cmd_bytes=$((b1 - b0)); cmd_s=$(python3 -c "print(round($t1 - $t0, 2))")
  step idle-after-command
  sleep 5

  # exec: $! is pmuctl itself, so the kill below ends the watch rather than only its shell,
  # and the round and the cut that follow have the link to themselves.
  (exec_gnd=1 pmuctl_gnd watch --low-rate >"$work/low.out" 2>/dev/null) &
  watcher=$!
  sleep 15  # the watcher's own discovery and the state it gets first are not the steady cost
  l0=$(wc -l <"$work/low.out"); w0=$(link_drops)
  # Per second of the interval the two counter readings really span (reading them takes time).
  step low
  t0=$(now); b0=$(link_bytes)
  sleep 10
  step low-end
  b1=$(link_bytes); t1=$(now)
  l1=$(wc -l <"$work/low.out"); steady_drops=$(( $(link_drops) - w0 ))
  kill "$watcher" 2>/dev/null || true; wait "$watcher" 2>/dev/null || true
  if [ -n "$(ip netns pids "$gnd" | xargs -r ps -o args= -p | grep ' watch ')" ]; then
    echo "fleet_link.sh: the low-rate watch did not end" >&2; exit 1
  fi
  low=$(python3 -c "print(round(($b1 - $b0) / ($t1 - $t0)))"); low_samples=$(python3 -c "print(round(($l1 - $l0) / 10, 1))")
  drops=$(( $(link_drops) - d0 ))

  rows+=("$n $idle $list_bytes $list_s $listed $cmd_bytes $cmd_s $result $low $low_samples $drops $steady_drops")
  [ "$ds" = 1 ] && ds_rows+=("$n $(round_and_cut "$n")")
  stop_all
  wait 2>/dev/null || true
done

status=0
( LINK_PROFILE=$link_profile ROWS=$(printf '%s\n' "${rows[@]}") DS_ROWS=$(printf '%s\n' "${ds_rows[@]}") python3 - "$rate" "$json_out" "$qos" "$ctl" "$ds" "$svc" "$server_xml" "$cut_s" "$agent" "$loss" <<'PY'
import json, os, re, sys
rate, json_out, qos, ctl, ds, svc, server_xml, cut_s, agent, loss = sys.argv[1:11]
m = re.match(r"(\d+)kbit", rate)
cap = int(m.group(1)) * 1000 / 8 if m else None
out = []
print(f"fleet over a {rate} link (tbf each way{', ' + loss + ' % loss' if loss != '0' else ''}){', link profile ' + os.environ['LINK_PROFILE'] if os.environ.get('LINK_PROFILE') else ''}{', Discovery Server on the ground (' + server_xml + ')' if ds == '1' else ''}{'; the calls through pmuctl agent' if agent == '1' else ''}; qos {qos}; pmuctl {ctl}; pmu-service {svc}")
print("| aircraft | idle B/s | list: bytes, s, listed | command: bytes, s, result | watch --low-rate B/s (samples/s) | low-rate watch / one way's capacity | queue drops: from the list on / in the watch's 10 s |")
print("|---|---|---|---|---|---|---|")
for line in os.environ["ROWS"].splitlines():
    f = line.split(" ", 7)
    n, idle, lb, ls, listed, cb, cs = (int(f[0]), int(f[1]), int(f[2]), float(f[3]), int(f[4]), int(f[5]), float(f[6]))
    rest = f[7].rsplit(" ", 4)
    result, low, low_samples, drops, steady = rest[0], int(rest[1]), float(rest[2]), int(rest[3]), int(rest[4])
    share = f"{low / cap:.2f}" if cap else "-"
    print(f"| {n} | {idle} | {lb}, {ls} s, {listed} of {n} | {cb}, {cs} s, {result} | {low} ({low_samples}) | {share} | {drops} / {steady} |")
    out.append(dict(aircraft=n, idle_bytes_per_s=idle, list_bytes=lb, list_seconds=ls, listed=listed,
                    command_bytes=cb, command_seconds=cs, command_result=result,
                    low_rate_bytes_per_s=low, low_rate_samples_per_s=low_samples, drops=drops,
                    steady_drops=steady))
failed = 0
if ds == "1":
    print()
    print(f"| aircraft | command round, one to each in turn: p50 / p99 / max s, COMPLETED | after a {cut_s} s cut (veth down): all listed after, a command to each (at once) COMPLETED after, COMPLETED | audit trails: executions / commands, resends answered again, executed twice or elsewhere |")
    print("|---|---|---|---|")
    by_n = {r["aircraft"]: r for r in out}
    for line in os.environ["DS_ROWS"].splitlines():
        f = line.split()
        n = int(f[0])
        p50, p99, mx, done, listed, back, done_after, execs, cmds, dupes, bad = f[1:12]
        listed_text = f"{listed} s" if listed != "none" else "not all within 120 s"
        print(f"| {n} | {p50} / {p99} / {mx} s, {done} of {n} | {listed_text}, {back} s, {done_after} of {n} | {execs} / {cmds}, {dupes}, {bad} |")
        failed += int(bad)
        by_n[n].update(round_p50_seconds=float(p50), round_p99_seconds=float(p99), round_max_seconds=float(mx),
                       round_completed=int(done), cut_seconds=int(cut_s),
                       relisted_seconds=None if listed == "none" else float(listed),
                       recommanded_seconds=float(back), after_cut_completed=int(done_after),
                       executions=int(execs), commands=int(cmds), resends_answered=int(dupes), executed_wrongly=int(bad))
if json_out:
    with open(json_out, "w") as fh:
        json.dump({"rate": rate, "loss_percent": int(loss), "qos": qos, "pmuctl": ctl, "pmu_service": svc, "discovery_server": ds == "1",
                   "server_xml": server_xml if ds == "1" else None, "rows": out}, fh, indent=1)
if failed:
    print(f"fleet_link.sh: {failed} command(s) executed twice or by another vehicle", file=sys.stderr)
    sys.exit(1)
PY
) || status=$?
if [ "$breakdown" = 1 ]; then
  for n in $aircraft; do
    echo
    python3 "$root/bench/rtps_breakdown.py" "$work/link-$n.pcap" --steps "$work/steps-$n" --from low --to low-end \
      --local 10.79.0.2 --title "The low-rate watch's measured 10 s, $n aircraft (ground gnd0: sent = to the air)" |
      tee "$work/breakdown-$n.md"
  done
fi
exit "$status"
