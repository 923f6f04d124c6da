#!/bin/sh
# pmu-dds hot-standby suite: the two instances of a pair (docs/design.md, "Hot standby";
# interface.md 4.7) in two hosts made of network namespaces inside the test VM that
# tests/system/run_vm_tests.sh --suite standby boots (Debian's kernel: vcan, vxcan, can-gw,
# veth and bridge are loaded by /init). /init runs `sh /standby.sh all`. Written for busybox
# ash. The topology, what each scenario asserts and the measured figures:
# tests/standby/README.md.
#
# The same protocol as tests/system/scenarios.sh: every scenario is an assertion with a time
# bound and ends with
#   RESULT <name> PASS|FAIL|SKIP <seconds>s <detail>
# on the console; a failover scenario also prints
#   FIGURES <name> takeover=S gap=S command=S period=S
# (bench/standby_failover.sh collects them). It runs in its own shell under `timeout`, with
# its own DDS domain; the driver kills what it started and puts the bus and the network back
# after it. Progress lines start with "[<name>]".
#
#   sh /standby.sh all          the scenarios named by pmu.scenarios=a,b on the kernel
#                               command line (all when absent): the topology is built once
#   sh /standby.sh one NAME     a single scenario (what `all` runs for each)

ALL_SCENARIOS="topology kill freeze bus_loss network_cut handover return"

export PATH=/opt/pmu/bin:/usr/sbin:/usr/bin:/sbin:/bin
export PMU_QOS_FILE=/etc/pmu-dds/qos.xml
WORK=/tmp/pmu-standby
mkdir -p "$WORK"

# ---- the topology ----------------------------------------------------------------------
# The bus: vcan0 in the root namespace (pmu-sim and the capture), and a vxcan pair into each
# instance's host (vxa <-> can0 in A, vxb <-> can0 in B), joined by can-gw rules. A frame
# crosses one gateway hop (can-gw's max_hops 1), so the rules name every path: the bus to
# each host, each host to the bus (echoed on vcan0, so its listeners see it) and each host to
# the other. A SocketCAN socket sees no frame of its own host's through the gateway, as on a
# real bus it sees none of its own.
# The network: a bridge br0 in the root namespace, a veth into each host (A, B and the
# consumer's host C). A cut between the instances isolates their two bridge ports (`isolated
# on`): they reach C, not each other, while CAN stays up.
HOSTS="A B C"
LAN_PREFIX=10.30.0
addr_of() { case $1 in A) echo "$LAN_PREFIX.1" ;; B) echo "$LAN_PREFIX.2" ;; C) echo "$LAN_PREFIX.3" ;; esac; }
# The instances: name, priority (A is the higher, so it owns the bus first), vxcan root end.
name_of() { case $1 in A) echo mc-a ;; B) echo mc-b ;; esac; }
priority_of() { case $1 in A) echo 2 ;; B) echo 1 ;; esac; }
vx_of() { case $1 in A) echo vxa ;; B) echo vxb ;; esac; }
other_of() { case $1 in A) echo B ;; B) echo A ;; esac; }
BUS=can0          # each host's CAN interface, and the bus's name in DDS
PERIOD=0.2        # s: the PMU's packet period (the config writes it: configure_streaming)
TAKEOVER_BOUND=20 # s: a takeover that has not happened by then never will
# The pair's periods (interface.md 4.7). The defaults (0.1, 0.3, 0.15) flap on this emulated VM:
# its busy moments (a service starting) stop a bus thread's calls for longer than lease -
# heartbeat_period, so the owner drops to joining and its CAN heartbeat stops for can_silence
# (tests/standby/README.md, "Periods"). These keep both bounds above the VM's pauses; the
# budget they give: the takeover after can_silence plus the claim window, 0.6 + 0.4 s.
HEARTBEAT_PERIOD=0.1
LEASE=1.0
CAN_SILENCE=0.6

# ---- helpers ---------------------------------------------------------------------------

# Debian's busybox shell runs its own applets before PATH: iproute2's ip by path.
ip() { /usr/sbin/ip "$@"; }
# In the background write `$NETNS_EXEC HOST CMD ... &`: `ip netns exec` execs CMD, so $! is
# CMD's pid (a backgrounded function would leave $! a subshell's).
NETNS_EXEC="/usr/sbin/ip netns exec"
on() { _host=$1; shift; $NETNS_EXEC "$_host" "$@"; }

log() { read -r _up _idle </proc/uptime; echo "[$SCEN] $_up $*"; }   # with the VM's uptime
. "$(dirname "$0")/scenario_lib.sh"
sleep_until() { _rest=$(calc "$1 - $(now)"); true_that "$_rest > 0" && sleep "$_rest"; return 0; }

diagnose() {
  log "diag: links: $(ip -br link 2>&1 | tr '\n' ' ' | cut -c1-300)"
  log "diag: cangw: $(cangw -L 2>&1 | tr '\n' ';' | cut -c1-300)"
  log "diag: processes: $(for p in $(cat "$WORK/pids" 2>/dev/null); do alive "$p" && printf '%s ' "$p:$(tr '\0' ' ' <"/proc/$p/cmdline" | cut -c1-40)"; done)"
  [ -f "$WORK/$SCEN.can" ] && log "diag: last frames: $(tail -n 6 "$WORK/$SCEN.can" | tr '\n' ' ')"
  for _h in A B; do
    [ -f "$WORK/$SCEN.$_h.log" ] && log "diag: $_h: $(grep -E 'role: |hot standby|--- start' "$WORK/$SCEN.$_h.log" | cut -c12-200 | tr '\n' ';' | cut -c1-900)"
    [ -f "$WORK/$SCEN.$_h.log" ] && log "diag: $_h: commands: $(grep -E 'audit: ' "$WORK/$SCEN.$_h.log" | tail -n 12 | cut -c12-220 | tr '\n' ';')"
  done
  # Where each live, running instance's threads are: a reply that never comes is a thread
  # waiting somewhere.
  if command -v eu-stack >/dev/null; then
    for _h in A B; do
      _p=$(eval echo "\${PID_$_h:-}")
      [ -n "$_p" ] && running "$_p" || continue
      eu-stack -p "$_p" 2>&1 | sed "s/^/diag: $_h stack: /"
    done
  fi
  return 0
}

gw() { cangw -A -s "$1" -d "$2" ${3:+"$3"}; }
standby_up() {
  ip link add vcan0 type vcan || return 1
  ip link set vcan0 up || return 1
  ip link add br0 type bridge || return 1
  # No IGMP snooping: nothing is a querier; every port gets DDS's discovery multicast.
  echo 0 >/sys/class/net/br0/bridge/multicast_snooping
  ip link set br0 up || return 1
  for h in $HOSTS; do
    ip netns add "$h" || return 1
    ip link add "$h-lan" type veth peer name eth0 netns "$h" || return 1
    ip link set "$h-lan" master br0 up || return 1
    on "$h" /usr/sbin/ip link set lo up || return 1
    on "$h" /usr/sbin/ip addr add "$(addr_of "$h")/24" dev eth0 || return 1
    on "$h" /usr/sbin/ip link set eth0 up || return 1
    on "$h" /usr/sbin/ip route add default dev eth0 || return 1
  done
  for h in A B; do
    ip link add "$(vx_of "$h")" type vxcan peer name "$BUS" netns "$h" || return 1
    ip link set "$(vx_of "$h")" up || return 1
    on "$h" /usr/sbin/ip link set "$BUS" up || return 1
  done
  gw vcan0 vxa && gw vcan0 vxb && gw vxa vcan0 -e && gw vxb vcan0 -e && gw vxa vxb && gw vxb vxa || return 1
}

# ---- the programs ----------------------------------------------------------------------

start_sim() {  # pmu-sim options
  pmu-sim vcan0 "$@" >>"$WORK/$SCEN.sim.log" 2>&1 &
  SIM_PID=$!
  track "$SIM_PID"
}
# Every frame each instance sends (vxa, vxb: what the gateway takes from A and B) and the
# marks (id 123 on vcan0), with the kernel's receive time: "(T) IFACE ID#DATA".
start_capture() {
  candump -L vxa vxb vcan0,123:7FF >"$WORK/$SCEN.can" 2>"$WORK/$SCEN.can.err" &
  track $!
  sleep 0.3
}
# mark N: a frame 123#0N on vcan0, so that the capture (kernel time) can be cut where the
# scenario (uptime) did something; MARK_AT_N holds the uptime it was sent at.
mark() { cansend vcan0 "123#0$1"; eval "MARK_AT_$1=$(now)"; }

# The instance's config: the bus can0 with the PMU at address 1 streaming every PERIOD, UDP
# only (hosts share nothing but the network), the pair's section unless NOPAIR is set.
instance_config() {  # HOST FILE
  cat >"$2" <<EOF
dds_transport: udp
log_level: ${PMU_SERVICE_LOG_LEVEL:-info}
timeouts:
  reply: 1.0
  retries: 0
buses:
  - interface: $BUS
    devices:
      - address: 1
        period: $PERIOD
        configure_streaming: true
EOF
  [ -n "${NOPAIR:-}" ] && return 0
  cat >>"$2" <<EOF
redundancy:
  priority: $(priority_of "$1")
  peer: $(name_of "$(other_of "$1")")
  name: $(name_of "$1")
  heartbeat_period: $HEARTBEAT_PERIOD
  lease: $LEASE
  can_silence: $CAN_SILENCE
EOF
}
# start_instance HOST: pmu-service in HOST; its pid in PID_A / PID_B, its log
# $WORK/$SCEN.HOST.log (a restart appends).
start_instance() {
  instance_config "$1" "$WORK/$SCEN.$1.yaml"
  echo "--- start $(now)" >>"$WORK/$SCEN.$1.log"
  $NETNS_EXEC "$1" pmu-service --config "$WORK/$SCEN.$1.yaml" --domain "$DOMAIN" >>"$WORK/$SCEN.$1.log" 2>&1 &
  eval "PID_$1=$!"
  track $!
}
# The consumer in C: every telemetry sample with its writer (standby_consumer.cpp).
start_consumer() {
  CONSUMER="$WORK/$SCEN.samples"
  $NETNS_EXEC C standby_consumer --domain "$DOMAIN" >"$CONSUMER" 2>"$CONSUMER.err" &
  track $!
}
# An operator's `pmuctl watch` in C, through the whole scenario.
start_watch() {
  $NETNS_EXEC C pmuctl --domain "$DOMAIN" --json watch >"$WORK/$SCEN.watch" 2>"$WORK/$SCEN.watch.err" &
  track $!
}
# The ground station (lab_ground --stdin) in C, fed through a fifo held open on fd 3.
start_ground() {
  GROUND_OUT="$WORK/$SCEN.ground.out"
  rm -f "$WORK/$SCEN.ground.in"; mkfifo "$WORK/$SCEN.ground.in"; : >"$GROUND_OUT"
  $NETNS_EXEC C lab_ground --stdin --domain "$DOMAIN" --bus "$BUS" <"$WORK/$SCEN.ground.in" >"$GROUND_OUT" 2>"$GROUND_OUT.err" &
  track $!
  exec 3>"$WORK/$SCEN.ground.in"
}
batch_done() { BATCH=$(grep "\"batch\":\"$1\"" "$GROUND_OUT" | tail -n1); [ -n "$BATCH" ]; }

# ---- what the consumer saw -------------------------------------------------------------
# Samples of TOPIC (default every topic) at or after uptime T: "T TOPIC BUS ADDRESS WRITER".
samples_after() { awk -v a="$1" -v tp="${2:-}" '$1 == "sample" && $2 >= a && (tp == "" || $3 == tp) { print $2, $3, $4, $5, $6 }' "$CONSUMER"; }
has_samples_after() { [ -n "$(samples_after "$1" | head -n1)" ]; }
# The writer of the last voltages sample before uptime T.
writer_before() { awk -v a="$1" '$1 == "sample" && $2 < a && $3 == "voltages" { w = $6 } END { print w }' "$CONSUMER"; }
# The first voltages sample at or after T from a writer other than W (a voltages writer):
# "T WRITER", or nothing. (Each topic has its own writer: only one topic's are compared.)
first_other_after() { awk -v a="$1" -v w="$2" '$1 == "sample" && $2 >= a && $3 == "voltages" && $6 != w { print $2, $6; exit }' "$CONSUMER"; }
took_over() { [ -n "$(first_other_after "$1" "$2")" ]; }
# One stream per device at any time, from uptime T on: for each topic and device, the
# writers' samples form runs that never interleave (a writer that hands over never writes
# again), with at most MOST writers. Prints what is wrong, nothing when all is well.
stream_problems() {  # T MOST
  awk -v a="$1" -v most="$2" '
    $1 != "sample" || $2 < a { next }
    { k = $3 " " $4 "/" $5
      if (last[k] != $6) {
        if (seen[k, $6]) bad[k] = bad[k] " " substr($6, 1, 8) " wrote again at " $2
        seen[k, $6] = 1; runs[k]++; last[k] = $6 } }
    END { for (k in runs) { if (runs[k] > most) print k ": " runs[k] " writers in turn"; if (bad[k] != "") print k ":" bad[k] } }' "$CONSUMER"
}
# The largest time between two voltages samples of the device in [T, U]: the gap.
largest_gap() { samples_after "$1" voltages | awk -v b="$2" '$1 <= b { if (p != "") { d = $1 - p; if (d > g) g = d } p = $1 } END { printf "%.2f", g }'; }

# ---- what the bus saw ------------------------------------------------------------------
# The capture's kernel time of mark N (empty if absent).
mark_time() { awk -v d="0$1" '$2 == "vcan0" && $3 == "123#" d { t = $1; gsub(/[()]/, "", t); print t; exit }' "$WORK/$SCEN.can"; }
# Frames HOST sent after kernel time K (and before L): "K ID#DATA".
frames_of() { awk -v i="$(vx_of "$1")" -v a="$2" -v b="${3:-1e18}" '{ t = $1; gsub(/[()]/, "", t) } $2 == i && t + 0 > a + 0 && t + 0 < b + 0 { print t, $3 }' "$WORK/$SCEN.can"; }
# PMU frames (group 0x1E: requests, commands, reads) among them.
pmu_frames_of() { frames_of "$@" | awk '$2 ~ /^1E/'; }
# The CAN heartbeats (interface.md 4.7: 0x1FFFFF00 + priority, layout 1, claim 1 claiming,
# 2 active, 3 released) of HOST after K whose claim is CLAIM.
# In candump's ID#DATA the claim is characters 12-13: after "1FFFFFPP#" and the layout "01".
beats_of() { frames_of "$1" "$2" "${4:-1e18}" | awk -v c="0$3" '$2 ~ /^1FFFFF[0-9A-F][0-9A-F]#01/ && substr($2, 12, 2) == c'; }
# The kernel time of HOST's first ACTIVE beat after K.
first_active_beat() { beats_of "$1" "$2" 2 | awk '{ print $1; exit }'; }
# The set frame of payload_voltage to V (protocol: 0x11, one byte in 0.1 V) sent by anyone.
set_frames() { awk -v d="$(printf '%02X' "$(awk -v v="$1" 'BEGIN { printf "%d", v * 10 + 0.5 }')")" '$3 == "1E110001#" d' "$WORK/$SCEN.can"; }

# ---- what each instance says of its role ------------------------------------------------
# Its log has a line at each change of role or alarm: `role: standby -> claiming (term 4)`,
# `role: fenced -> standby (term 3, alarm partition)`, `role: standby, alarm none`.
# role_of HOST: the role of its last such line; alarm_of HOST: that line's alarm (none).
last_role_line() { grep ' role: ' "$WORK/$SCEN.$1.log" 2>/dev/null | sed -n '$s/.* role: //p'; }
role_of() { last_role_line "$1" | sed 's/.*-> //; s/[ ,(].*//'; }
alarm_of() { _l=$(last_role_line "$1"); case $_l in *"alarm "*) echo "$_l" | sed 's/.*alarm //; s/[^a-z_].*//' ;; *) echo none ;; esac; }
role_is() { [ "$(role_of "$1")" = "$2" ]; }

# ---- the audit trail (command_service.cpp: one final line per decided command) ----------
# ID: the audit lines of ID in both instances' logs that decided it: not a resend answered
# again, not a standby's "not executed" (it saw the request, or answered it with the former
# owner's result, without executing it), not a former owner's "not answered here" (it stopped
# owning the bus while the command ran and left the answer to the new owner, whose line decides).
executions() {
  cat "$WORK/$SCEN.A.log" "$WORK/$SCEN.B.log" 2>/dev/null | grep "audit: command $1 " | grep -v 'reuses that id' |
    grep -v 'not executed' | grep -v 'not answered here'
}
audit_of() {  # ID: every audit line of ID, each with its instance, on one line
  for _h in A B; do grep "audit: .*command $1 " "$WORK/$SCEN.$_h.log" 2>/dev/null | sed "s/.*audit: /$_h: /; s/ from [^ ]*:/:/"; done | tr '\n' '|' | cut -c1-500
}

# The consumer's voltages reader and the ground station's command writer and reply reader
# each matched with two services' endpoints.
matched_both() {
  [ "$(awk '$1 == "matched" && $3 == "voltages" { c = $4 } END { print c + 0 }' "$CONSUMER")" -ge 2 ] &&
    [ "$(grep '"endpoint":"commands"' "$GROUND_OUT" | tail -n1 | sed -n 's/.*"current":\([0-9]*\).*/\1/p')" = 2 ] &&
    [ "$(grep '"endpoint":"replies"' "$GROUND_OUT" | tail -n1 | sed -n 's/.*"current":\([0-9]*\).*/\1/p')" = 2 ]
}

# ---- the pair --------------------------------------------------------------------------
# A, then B once A owns the bus; the consumer, a watch and the ground station in C. Leaves
# WRITER_A (A's voltages writer as the consumer sees it) and T_UP (uptime with both up).
pair_up() {
  start_sim
  start_capture
  start_consumer
  start_watch
  start_ground
  start_instance A
  wait_until 90 has_samples_after 0 || fail "no telemetry from A within 90 s ($(tail -n 2 "$WORK/$SCEN.A.log" | tr '\n' ' '))"
  WRITER_A=$(writer_before 1e18)
  start_instance B
  t_b=$(now)
  # B's writers matched by the consumer and its command reader by the ground station before
  # any fault: discovery (seconds on this emulated VM) is not what a takeover measures. The
  # design keeps a standby's writers made and matched from its start.
  wait_until 60 matched_both || fail "the consumer and the ground station did not match B's endpoints within 60 s of its start ($(tail -n 2 "$WORK/$SCEN.B.log" | tr '\n' ' '))"
  detail "B's endpoints matched in C $(since "$t_b") s after its start"
  sleep 2
  alive "$PID_B" || fail "B ended at its start: $(tail -n 3 "$WORK/$SCEN.B.log" | tr '\n' ' ')"
  [ -z "$(pmu_frames_of B 0)" ] || fail "B sent PMU frames while A owned the bus: $(pmu_frames_of B 0 | head -n 3 | tr '\n' ' ')"
  [ -z "$(frames_of B 0)" ] || fail "B sent on CAN while A owned the bus: $(frames_of B 0 | head -n 3 | tr '\n' ' ')"
  role_is A active || fail "A's log says it is '$(role_of A)', not active"
  case $(role_of B) in active | claiming) fail "B's log says it is '$(role_of B)' while A owns the bus" ;; esac
  T_UP=$(now)
  detail "A owns the bus (active, its telemetry reaches C), B joined ($(role_of B), alarm $(alarm_of B)) and sends nothing"
}

# fault_at HOST WHAT V1 V2: a command from C (tag SCEN-f) that sets payload_voltage to V1 (a
# value nothing else sets), resent every 0.25 s, is sent at uptime T (1 s from now) and WHAT
# is done to HOST as soon after as the shell manages; right after it another (SCEN-a, V2) is
# handed to the ground station, which sends it once the first has its final reply. T_FAULT is
# when WHAT was done, mark 1 its place in the capture.
fault_at() {
  mark 0
  _t=$(calc "$(now) + 1.0")
  batch_line "$SCEN-f" "$_t" "$3" >&3
  sleep_until "$_t"
  T_FAULT=$(now)
  case $2 in
    kill) kill -KILL "$(eval echo "\$PID_$1")" ;;
    stop) kill -STOP "$(eval echo "\$PID_$1")" ;;
    term) kill -TERM "$(eval echo "\$PID_$1")" ;;
    bus_down) on "$1" /usr/sbin/ip link set "$BUS" down ;;
    cut) ip link set A-lan type bridge_slave isolated on; ip link set B-lan type bridge_slave isolated on ;;
  esac
  batch_line "$SCEN-a" 0 "$4" >&3
  mark 1
  log "fault: $2 on $1 at $T_FAULT (the first command was due at $_t)"
}
batch_line() {  # TAG AT VALUE
  echo "batch tag=$1 at=$2 count=1 values=$3 resend=0.25 timeout=25 deadline=30 expires-in=30 wait-match=0"
}
# Both commands' summaries: BATCH_F, BATCH_A.
commands_done() { batch_done "$SCEN-f" && BATCH_F=$BATCH && batch_done "$SCEN-a" && BATCH_A=$BATCH; }

# After a fault on OLD: the other instance takes over; the figures, and the checks that hold
# for every failover. Leaves TAKEOVER, GAP, CMD_S and the new writer in WRITER_NEW.
check_takeover() {  # OLD V1 V2
  _new=$(other_of "$1")
  wait_until "$TAKEOVER_BOUND" took_over "$T_FAULT" "$WRITER_A" ||
    fail "no telemetry from another writer within $TAKEOVER_BOUND s of the fault ($(tail -n 2 "$WORK/$SCEN.$_new.log" | tr '\n' ' '))"
  # A claim before the fault is a takeover nobody caused (an owner whose heartbeat paused).
  _early=$(frames_of "$_new" 0 "$(mark_time 0)" | head -n 3)
  [ -z "$_early" ] || fail "$_new claimed the bus before the fault: $(echo "$_early" | tr '\n' ' ')"
  set -- "$1" "$2" "$3" $(first_other_after "$T_FAULT" "$WRITER_A")
  TAKEOVER=$(calc "$4 - $T_FAULT")
  WRITER_NEW=$5
  wait_until 60 commands_done || fail "the commands sent at the fault have no summary within 60 s ($(tail -n 2 "$GROUND_OUT.err" | tr '\n' ' '))"
  sleep 3
  GAP=$(largest_gap "$(calc "$T_FAULT - 2")" "$(calc "$T_FAULT + 5")")
  # The first command accepted: the one sent after the fault, when it COMPLETED.
  CMD_S=-
  [ "$(jv "$BATCH_A" COMPLETED)" = 1 ] && CMD_S=$(calc "$(jv "$BATCH_A" t_end) - $T_FAULT")
  echo "FIGURES $SCEN takeover=$TAKEOVER gap=$GAP command=$CMD_S period=$PERIOD lease=$LEASE can_silence=$CAN_SILENCE"
  detail "takeover $TAKEOVER s (the fault to the first sample of B's writer; goal 0.5), largest gap $GAP s (goal 1, PP $PERIOD), the command sent after the fault COMPLETED $CMD_S s after it (goal 1)"
  check_streams "$T_UP" 2
  check_one_owner "$_new"
  check_watch "$_new" active
}
# The operator's watch in C shows the pair as it is: INSTANCE's last role line there says ROLE.
watch_role() { grep '"topic":"role"' "$WORK/$SCEN.watch" 2>/dev/null | grep "\"name\":\"$(name_of "$1")\"" | tail -n1 | sed -n 's/.*"role":"\([a-z_]*\)".*/\1/p'; }
check_watch() {  # HOST ROLE
  [ "$(watch_role "$1")" = "$2" ] || fail "pmuctl watch last showed $1 as '$(watch_role "$1")', not $2: $(grep -c '"topic":"role"' "$WORK/$SCEN.watch" 2>/dev/null) role line(s)"
  detail "pmuctl watch shows $1 $2 (its role lines: $(grep '"topic":"role"' "$WORK/$SCEN.watch" | sed -n 's/.*"name":"\([^"]*\)".*"role":"\([a-z_]*\)".*"term":\([0-9]*\).*/\1 \2 \3/p' | tr '\n' ',' | cut -c1-200))"
}
# The two commands of the fault (check_command), checked last in a scenario, when every
# frame and audit line they could cause is in.
check_commands() {  # V1 V2
  check_command "$SCEN-f" "$BATCH_F" "$1" any
  check_command "$SCEN-a" "$BATCH_A" "$2" COMPLETED
}

# Each writer's voltages samples from uptime T on, in the order they first wrote: "WRITER N FIRST LAST".
writers_since() {
  awk -v a="$1" '$1 == "sample" && $2 >= a && $3 == "voltages" {
      if (!n[$6]++) { o[++k] = $6; f[$6] = $2 } l[$6] = $2 }
    END { for (i = 1; i <= k; i++) printf "%s %d %s %s\n", o[i], n[o[i]], f[o[i]], l[o[i]] }' "$CONSUMER"
}
# One stream per device at any time, and after the takeover only the new writer.
check_streams() {  # T MOST
  _w=$(writers_since "$1" | awk '{ printf "%s %d samples %s-%s; ", $1, $2, $3, $4 }')
  _p=$(stream_problems "$1" "$2")
  [ -z "$_p" ] || fail "two streams of one device: $(echo "$_p" | tr '\n' ';' | cut -c1-400) (voltages writers: $_w)"
  detail "one stream per device at a time (voltages writers: $_w)"
}

# A command of the fault (TAG, its summary, its VALUE, WANT: COMPLETED or any): exactly one
# final reply (a resend answered again says the same), one decision in the two instances'
# audit trails, and at most one set frame of its value on the bus (one when COMPLETED).
check_command() {  # TAG SUMMARY VALUE WANT
  [ "$(jv "$2" final_replies)" = 1 ] || fail "$1: $(jv "$2" final_replies) final replies ($2); the audit trails: $(audit_of "$1-1")"
  _res=$(printf '%s' "$2" | sed -n 's/.*"results":{\([^}]*\)}.*/\1/p')
  _done=$(jv "$2" COMPLETED)
  [ "$4" = any ] || [ "$_done" = 1 ] || fail "$1 was not COMPLETED: $_res"
  _dups=$(grep '"event":"duplicate_reply"' "$GROUND_OUT" | grep -c "\"id\":\"$1-1\"")
  _first=$(printf '%s' "$_res" | sed 's/"\([A-Z_]*\)":1.*/\1/; s/.*"//')
  _other=$(grep '"event":"duplicate_reply"' "$GROUND_OUT" | grep "\"id\":\"$1-1\"" | grep -vc "\"result\":\"$_first\"")
  [ "$_other" = 0 ] || fail "$1 was answered $_first and then otherwise: $(grep '"duplicate_reply"' "$GROUND_OUT" | grep "\"id\":\"$1-1\"" | tr '\n' ' ' | cut -c1-300); the audit trails: $(audit_of "$1-1")"
  # A new owner's "outcome unknown" answers without executing: the former owner may have
  # executed the command and died before its reply went out (one execution, one reply).
  _ex=$(executions "$1-1" | grep -vc 'outcome unknown')
  _unknown=$(executions "$1-1" | grep -c 'outcome unknown')
  [ "$_ex" -le 1 ] || fail "$1 was executed $_ex times in the two logs (want at most 1): $(audit_of "$1-1")"
  [ "$_unknown" -le 1 ] || fail "$1 was answered 'outcome unknown' $_unknown times: $(audit_of "$1-1")"
  [ $((_ex + _unknown)) -ge 1 ] || fail "$1 was decided nowhere: $(audit_of "$1-1")"
  [ "$_done" != 1 ] || [ "$_ex" = 1 ] || fail "$1 COMPLETED with $_ex executions in the two logs: $(audit_of "$1-1")"
  _sets=$(set_frames "$3" | wc -l)
  if [ "$_done" = 1 ]; then
    [ "$_sets" = 1 ] || fail "$1 COMPLETED with $_sets set frames of payload_voltage $3 on the bus (one execution sends one): $(set_frames "$3" | tr '\n' ' ')"
  elif [ "$_first" = REJECTED ]; then
    # REJECTED says the command was not executed: nothing of it may be on the bus.
    [ "$_sets" = 0 ] || fail "$1 was answered REJECTED, yet its set frame is on the bus ($_sets): $(set_frames "$3" | tr '\n' ' '); the audit trails: $(audit_of "$1-1")"
  else
    [ "$_sets" -le 1 ] || fail "$1 ($_res) sent $_sets set frames of payload_voltage $3: $(set_frames "$3" | tr '\n' ' ')"
  fi
  _by=A; grep -q "audit: command $1-1 " "$WORK/$SCEN.B.log" 2>/dev/null && _by=B
  detail "$1: one final reply ($_res, $_dups resends answered again), decided once by $_by, $_sets set frame(s)"
}

# Alive and not stopped (SIGSTOP): a frozen instance's log still ends at the role it froze in.
running() { alive "$1" && ! grep -q '^State:.*T' "/proc/$1/status" 2>/dev/null; }
# The instance NEW is the one bus owner now: its ACTIVE beats in the last second, none of
# the other's, and the other sent no PMU frame after NEW's first ACTIVE beat.
check_one_owner() {  # NEW
  _old=$(other_of "$1")
  mark 2
  sleep 1
  mark 3
  _k2=$(mark_time 2); _k3=$(mark_time 3)
  [ -n "$_k2" ] && [ -n "$_k3" ] || fail "the marks are not in the capture"
  [ -n "$(beats_of "$1" "$_k2" 2 "$_k3")" ] || fail "$1 sent no ACTIVE heartbeat in the last second: it does not own the bus"
  [ -z "$(beats_of "$_old" "$_k2" 2 "$_k3")" ] || fail "$_old still sends ACTIVE heartbeats: two bus owners"
  _first=$(first_active_beat "$1" 0)
  _late=$(pmu_frames_of "$_old" "$_first")
  [ -z "$_late" ] || fail "split brain: $_old sent PMU frames after $1 owned the bus: $(echo "$_late" | head -n 3 | tr '\n' ' ')"
  _late=$(beats_of "$_old" "$_first" 2)
  [ -z "$_late" ] || fail "split brain: $_old sent ACTIVE heartbeats after $1 owned the bus: $(echo "$_late" | head -n 3 | tr '\n' ' ')"
  role_is "$1" active || fail "$1's log says it is '$(role_of "$1")', not active"
  if running "$(eval echo "\$PID_$_old")"; then
    case $(role_of "$_old") in active | claiming) fail "$_old's log says it is '$(role_of "$_old")' beside $1" ;; esac
    _also="; $_old says $(role_of "$_old")"
  else
    _also=""
  fi
  detail "$1 alone sends ACTIVE heartbeats and says it is active; $_old sent no PMU frame and no ACTIVE heartbeat after $1's first$_also"
}

# ---- scenarios -------------------------------------------------------------------------

# The topology itself, with a service that is no pair: frames cross the gateway once each way
# (the bus to each host, each host to the bus and to the other host, none back to its sender),
# pmu-sim's telemetry reaches the consumer in C through A's service, and the cut keeps B from
# A's samples while C still gets them.
b_sample_after() { B_FIRST=$(awk -v a="$1" '$1 == "sample" && $2 >= a { print $2; exit }' "$WORK/$SCEN.B.samples"); [ -n "$B_FIRST" ]; }
scenario_topology() {
  start_sim
  start_capture
  on A candump -L "$BUS" >"$WORK/$SCEN.A.can" 2>&1 &
  track $!
  on B candump -L "$BUS" >"$WORK/$SCEN.B.can" 2>&1 &
  track $!
  candump -L vcan0,1FFFFFF0:1FFFFFF0 >"$WORK/$SCEN.bus.can" 2>&1 &
  track $!
  sleep 1
  on A cansend "$BUS" 1FFFFFF1#A1
  on B cansend "$BUS" 1FFFFFF2#B2
  cansend vcan0 1FFFFFF3#C3
  sleep 1
  for f in A:1FFFFFF2#B2 A:1FFFFFF3#C3 B:1FFFFFF1#A1 B:1FFFFFF3#C3 bus:1FFFFFF1#A1 bus:1FFFFFF2#B2; do
    n=$(grep -c " ${f#*:}\$" "$WORK/$SCEN.${f%%:*}.can")
    [ "$n" = 1 ] || fail "${f#*:} seen $n times on ${f%%:*}'s interface (want once): $(cat "$WORK/$SCEN.${f%%:*}.can" | tr '\n' ' ' | cut -c1-300)"
  done
  # A host's other sockets see its frame once (SocketCAN's local loopback, as on a real
  # interface); a second copy would have come back through the gateway.
  for f in A:1FFFFFF1#A1 B:1FFFFFF2#B2; do
    n=$(grep -c " ${f#*:}\$" "$WORK/$SCEN.${f%%:*}.can")
    [ "$n" -le 1 ] || fail "${f%%:*} received its own frame ${f#*:} back through the gateway ($n copies)"
  done
  detail "a frame of A, of B and of the bus each reached the two others once, none came back to its sender"
  grep -q " 1E0[0-4]0001#" "$WORK/$SCEN.A.can" || fail "pmu-sim's telemetry does not reach A: $(head -n 3 "$WORK/$SCEN.A.can" | tr '\n' ' ')"
  NOPAIR=1 start_instance A
  start_consumer
  $NETNS_EXEC B standby_consumer --domain "$DOMAIN" >"$WORK/$SCEN.B.samples" 2>&1 &
  track $!
  wait_until 90 has_samples_after 0 || fail "no telemetry in C within 90 s ($(tail -n 2 "$WORK/$SCEN.A.log" | tr '\n' ' '))"
  wait_until 30 grep -q '^sample' "$WORK/$SCEN.B.samples" || fail "no telemetry in B within 30 s"
  same "$(jv "$(on C pmuctl --domain "$DOMAIN" --json --timeout 20 --address 1 info 2>/dev/null | head -n1)" bus)" "$BUS" ||
    fail "pmuctl info in C does not show the PMU on $BUS"
  detail "pmu-sim on vcan0 -> A's service on its vxcan -> the consumer and pmuctl in C"
  ip link set A-lan type bridge_slave isolated on
  ip link set B-lan type bridge_slave isolated on
  t_cut=$(now)
  sleep 4
  t_mid=$(calc "$t_cut + 1")
  in_b=$(awk -v a="$t_mid" '$1 == "sample" && $2 >= a' "$WORK/$SCEN.B.samples" | wc -l)
  in_c=$(samples_after "$t_mid" | wc -l)
  [ "$in_b" = 0 ] || fail "the cut leaves B $in_b samples of A's in 3 s"
  [ "$in_c" -gt 0 ] || fail "the cut leaves C without A's samples"
  ip link set A-lan type bridge_slave isolated off
  ip link set B-lan type bridge_slave isolated off
  t_back=$(now)
  wait_until 30 b_sample_after "$t_back" || fail "B gets no sample within 30 s of the cut's end"
  detail "the cut: B got none of A's samples in 3 s while C got $in_c; B's came back $(calc "$B_FIRST - $t_back") s after it"
}

# SIGKILL of the bus owner: B takes over.
scenario_kill() {
  pair_up
  fault_at A kill 12.1 12.2
  check_takeover A 12.1 12.2
  check_watch A silent
  check_commands 12.1 12.2
}

# SIGSTOP of the bus owner for longer than the lease: B takes over; after SIGCONT A comes back
# as a standby that sends nothing, and B stays the one owner.
scenario_freeze() {
  pair_up
  fault_at A stop 12.3 12.4
  check_takeover A 12.3 12.4
  mark 4
  t_cont=$(now)   # before the signal: what A does on its first instant awake counts
  kill -CONT "$PID_A"
  sleep 4
  alive "$PID_A" || fail "A ended after SIGCONT: $(tail -n 3 "$WORK/$SCEN.A.log" | tr '\n' ' ')"
  k4=$(mark_time 4)
  late=$(pmu_frames_of A "$k4")
  [ -z "$late" ] || fail "A sent PMU frames after SIGCONT: $(echo "$late" | head -n 3 | tr '\n' ' ')"
  [ -z "$(beats_of A "$k4" 2)$(beats_of A "$k4" 1)" ] || fail "A claimed the bus after SIGCONT: $(beats_of A "$k4" 2 | head -n 2 | tr '\n' ' ')"
  check_streams "$T_UP" 2
  [ -z "$(awk -v a="$t_cont" -v w="$WRITER_A" '$1 == "sample" && $2 >= a && $3 == "voltages" && $6 == w' "$CONSUMER" | head -n1)" ] ||
    fail "A wrote telemetry after SIGCONT"
  check_one_owner B
  detail "after SIGCONT A sent nothing on CAN and wrote no sample"
  check_commands 12.3 12.4
}

# The owner's CAN interface goes down: B takes over; A's bus back, A stays a standby.
scenario_bus_loss() {
  pair_up
  fault_at A bus_down 12.5 12.6
  check_takeover A 12.5 12.6
  mark 4
  on A /usr/sbin/ip link set "$BUS" up
  sleep 4
  k4=$(mark_time 4)
  [ -z "$(pmu_frames_of A "$k4")$(beats_of A "$k4" 1)$(beats_of A "$k4" 2)" ] ||
    fail "A claimed or sent PMU frames after its bus came back: $(frames_of A "$k4" | head -n 3 | tr '\n' ' ')"
  check_one_owner B
  detail "A's bus back: A sent no claim and no PMU frame"
  check_commands 12.5 12.6
}

# The network between A and B cut, CAN alive: nobody takes over, no split brain; a command
# during the cut is executed once, by A.
scenario_network_cut() {
  pair_up
  fault_at A cut 12.7 12.8
  wait_until 60 commands_done || fail "the commands sent at the cut have no summary within 60 s"
  sleep 5
  mark 4
  # Both say it (design: "both say it, and the pair has no second bus owner").
  [ "$(alarm_of A)" = peer_unreachable ] || fail "during the cut A's alarm is '$(alarm_of A)', not peer_unreachable ($(last_role_line A))"
  role_is B fenced && [ "$(alarm_of B)" = partition ] || fail "during the cut B is '$(role_of B)' with alarm '$(alarm_of B)', not fenced with partition"
  detail "during the cut: A active with peer_unreachable, B fenced with partition"
  [ -z "$(first_other_after "$T_UP" "$WRITER_A")" ] || fail "another writer during the cut: $(first_other_after "$T_UP" "$WRITER_A")"
  [ -z "$(frames_of B 0)" ] || fail "B sent on CAN during the cut: $(frames_of B 0 | head -n 3 | tr '\n' ' ')"
  ip link set A-lan type bridge_slave isolated off
  ip link set B-lan type bridge_slave isolated off
  sleep 4
  [ -z "$(frames_of B 0)" ] || fail "B sent on CAN after the cut: $(frames_of B 0 | head -n 3 | tr '\n' ' ')"
  role_is B standby && [ "$(alarm_of B)" = none ] && [ "$(alarm_of A)" = none ] ||
    fail "4 s after the cut B is '$(role_of B)' (alarm '$(alarm_of B)'), A's alarm '$(alarm_of A)': want standby and no alarms"
  [ -z "$(first_other_after "$T_UP" "$WRITER_A")" ] || fail "another writer after the cut"
  check_one_owner A
  detail "6 s cut: B never sent a CAN frame, A's writer the only one throughout"
  check_command "$SCEN-f" "$BATCH_F" 12.7 COMPLETED
  check_command "$SCEN-a" "$BATCH_A" 12.8 COMPLETED
}

a_ended() { ! alive "$PID_A"; }
# SIGTERM of the owner: it releases the bus and ends; B takes over.
scenario_handover() {
  pair_up
  fault_at A term 12.9 13.1
  check_takeover A 12.9 13.1
  wait_until 10 a_ended || fail "A did not end within 10 s of SIGTERM"
  wait "$PID_A"; st=$?
  [ "$st" = 0 ] || fail "A ended with status $st after SIGTERM"
  [ -n "$(beats_of A 0 3)" ] || fail "A sent no release frame"
  detail "A ended with status 0 after its release frame"
  check_commands 12.9 13.1
}

# The old owner comes back (restarted after its hand-over): it joins as a standby and takes
# nothing back, although its priority is the higher.
scenario_return() {
  pair_up
  fault_at A term 13.2 13.3
  check_takeover A 13.2 13.3
  wait_until 10 a_ended || fail "A did not end within 10 s of SIGTERM"
  mark 4
  t_back=$(now)
  start_instance A
  sleep 6
  alive "$PID_A" || fail "A ended after its restart: $(tail -n 3 "$WORK/$SCEN.A.log" | tr '\n' ' ')"
  k4=$(mark_time 4)
  [ -z "$(frames_of A "$k4")" ] || fail "the restarted A sent on CAN: $(frames_of A "$k4" | head -n 3 | tr '\n' ' ')"
  [ -z "$(first_other_after "$t_back" "$WRITER_NEW")" ] || fail "a writer other than B's after A's restart: $(first_other_after "$t_back" "$WRITER_NEW")"
  check_one_owner B
  detail "A restarted: 6 s later it had sent nothing on CAN and written nothing; B the owner"
  check_commands 13.2 13.3
}

# A scenario's own start (two services, their discovery in C) takes 40-60 s of it on this
# emulated VM; the limit only stops one that hangs.
scenario_limit() { echo 180; }

# The bus and the network as standby_up left them: every host's CAN interface up, no port
# isolated, no process left in a host.
after_scenario() {
  for h in A B; do on "$h" /usr/sbin/ip link set "$BUS" up 2>/dev/null; done
  ip link set A-lan type bridge_slave isolated off 2>/dev/null
  ip link set B-lan type bridge_slave isolated off 2>/dev/null
  for h in $HOSTS; do
    for p in $(ip netns pids "$h" 2>/dev/null); do kill -9 "$p" 2>/dev/null; done
  done
}
FAIL_LOGS="A.log B.log sim.log samples.err ground.out.err watch.err"
DOMAIN_BASE=60

case "${1:-all}" in
  one) run_scenario "$2" ;;
  all)
    pick_scenarios
    SCEN=setup
    if ! standby_up >"$WORK/setup.log" 2>&1; then
      sed 's/^/[setup] /' "$WORK/setup.log"
      echo "RESULT setup FAIL 0s could not build the bus, the gateway and the hosts"
      exit 0
    fi
    echo "STANDBY: hosts $HOSTS on br0 ($LAN_PREFIX.0/24); bus vcan0 + vxcan into A and B ($BUS), can-gw: $(cangw -L 2>&1 | grep -c '^cangw') rules"
    run_list $SCENARIOS
    ;;
  *) echo "usage: $0 all | one NAME" >&2; exit 2 ;;
esac
