#!/usr/bin/env bash
# A radio's budget: the bytes per second pmu-mavlink sends at its default rates for the demo
# power system (deploy/examples/sim-power-system.yaml: one PMU, a BMS, two MPPTs on the
# built-in simulated bus), against a 57.6 kbit/s radio: 5,760 bytes/s on the serial line
# (8N1: 10 bits a byte). Goal: at most 5 %. A UDP sink counts every datagram (one frame each)
# over a window that starts once every battery has been heard, by message id.
#   bench/mavlink_budget.sh [--build-dir DIR] [--seconds N]
set -uo pipefail
src="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="$src/build/dev" seconds=30
while [ $# -gt 0 ]; do
  case "$1" in
    --build-dir) build=$2; shift 2 ;;
    --seconds) seconds=$2; shift 2 ;;
    *) echo "usage: $0 [--build-dir DIR] [--seconds N]" >&2; exit 2 ;;
  esac
done
svc="$build/service/app/pmu-service"
[ -x "$svc" ] || svc="$(find "$build" -name pmu-service -type f -perm -u+x | head -n1)"
bridge="$(find "$build" -name pmu-mavlink -type f -perm -u+x | head -n1)"
[ -x "$svc" ] && [ -x "$bridge" ] || { echo "build pmu-service and pmu-mavlink in $build first" >&2; exit 2; }
. "$src/tests/support/dds_domain.sh"
pmu_test_dds_domain || exit 1
export PMU_QOS_FILE="$src/deploy/qos.xml"
work=$(mktemp -d)
pids=()
trap 'for p in "${pids[@]}"; do kill "$p" 2>/dev/null; done; wait 2>/dev/null; rm -rf "$work"' EXIT
"$svc" --config "$src/deploy/examples/sim-power-system.yaml" --domain "$PMU_TEST_DDS_DOMAIN" >"$work/service.log" 2>&1 &
pids+=($!)
python3 - "$work/port" "$seconds" <<'PY' &
import socket, sys, time
s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
s.bind(("127.0.0.1", 0))
open(sys.argv[1], "w").write(str(s.getsockname()[1]))
window = float(sys.argv[2])
names = {0: "HEARTBEAT", 147: "BATTERY_STATUS", 373: "GENERATOR_STATUS", 376: "RELAY_STATUS", 253: "STATUSTEXT", 77: "COMMAND_ACK"}
batteries, start, by_id = set(), None, {}
while True:
    d = s.recv(65536)
    if len(d) < 10 or d[0] != 0xFD: continue
    msgid = d[7] | d[8] << 8 | d[9] << 16
    if start is None:
        if msgid == 147 and len(d) > 10 + 32: batteries.add(d[10 + 32])  # id: payload byte 32 in wire order
        if {10, 11, 20} <= batteries: start = time.monotonic()
        continue
    n, b = by_id.get(msgid, (0, 0))
    by_id[msgid] = (n + 1, b + len(d))
    if time.monotonic() - start >= window: break
total = sum(b for _, b in by_id.values())
rate = total / window
print(f"| message | frames/s | bytes/s |")
print(f"|---|---|---|")
for msgid, (n, b) in sorted(by_id.items()):
    print(f"| {names.get(msgid, msgid)} | {n / window:.2f} | {b / window:.1f} |")
share = 100.0 * rate / 5760.0
print(f"| all, default rates, demo power system | | **{rate:.1f}** = {share:.2f} % of a 57.6 kbit/s radio (5,760 B/s); goal <= 5 %: {'met' if share <= 5 else 'MISSED'} |")
PY
sink=$!
for _ in $(seq 100); do [ -s "$work/port" ] && break; sleep 0.1; done
"$bridge" --udp "127.0.0.1:$(cat "$work/port")" --system-id 1 --domain "$PMU_TEST_DDS_DOMAIN" >"$work/bridge.log" 2>&1 &
pids+=($!)
wait "$sink"
