#!/usr/bin/env bash
# The ground link's budget: bytes per second one PMU's telemetry costs a ground subscriber,
# at full rate and on the low-rate topics (docs/interface.md 1.5), measured on the wire.
#
#   bench/ground_link.sh [--build-dir DIR] [--seconds S] [--period P] [--check] [--json FILE]
#
# Two network namespaces joined by a veth pair make an aircraft (pmu-service on the simulated
# bus, one PMU streaming its five packets every P s, default 0.1 s: the realistic rate of
# a flight) and a ground station. Phases of S seconds each (default 20), after a warm-up:
#   idle   no ground subscriber: what discovery alone costs the link
#   full   pmuctl watch (pmu/voltages ... pmu/status)
#   low    pmuctl watch --low-rate (pmu/low_rate/*, the service's low_rate_period: 1 s)
# Bytes are the ground interface's received + sent bytes (IP packets: RTPS, UDP, IP headers),
# so ACKNACKs and heartbeats count too. The service uses UDP only: Fast DDS's shared memory
# would otherwise carry the samples past the veth (both namespaces share /dev/shm).
# --check: exit 1 unless the low-rate phase costs at most a third of the full-rate phase and
# delivers about one sample per packet per second (what the ctest ground_link_budget asserts).
# Needs root (ip netns). Exit status 77 when network namespaces cannot be made here.
set -euo pipefail

root=$(cd "$(dirname "$0")/.." && pwd)
build_dir="$root/build/release"
seconds=20
period=0.1
check=0
json_out=""
while [ $# -gt 0 ]; do
  case "$1" in
    --build-dir) build_dir=$2; shift 2 ;;
    --seconds) seconds=$2; shift 2 ;;
    --period) period=$2; shift 2 ;;
    --check) check=1; shift ;;
    --json) json_out=$2; shift 2 ;;
    -h|--help) sed -n '2,19p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "ground_link.sh: unknown argument '$1'" >&2; exit 2 ;;
  esac
done
svc=$(find "$build_dir" -type f -name pmu-service -perm -u+x | head -n1)
ctl=$(find "$build_dir" -type f -name pmuctl -perm -u+x | head -n1)
[ -x "$svc" ] && [ -x "$ctl" ] || { echo "ground_link.sh: build pmu-service and pmuctl in $build_dir first" >&2; exit 2; }
[ "$(id -u)" = 0 ] || { echo "ground_link.sh: SKIP: needs root for network namespaces" >&2; exit 77; }

. "$root/tests/support/dds_domain.sh"
pmu_test_dds_domain || exit 1
domain=$PMU_TEST_DDS_DOMAIN
tag=$$
air=pmu-air-$tag
gnd=pmu-gnd-$tag
work=$(mktemp -d /tmp/pmu-ground-link.XXXXXX)
pids=()
cleanup() {
  # Whatever still runs in the namespaces, then what was started here.
  for p in $(ip netns pids "$air" 2>/dev/null) $(ip netns pids "$gnd" 2>/dev/null); do kill "$p" 2>/dev/null || true; done
  for p in "${pids[@]}"; do kill "$p" 2>/dev/null || true; done
  wait 2>/dev/null || true
  ip netns del "$air" 2>/dev/null || true
  ip netns del "$gnd" 2>/dev/null || true
  rm -rf "$work"
}
trap cleanup EXIT

if ! ip netns add "$air" 2>/dev/null || ! ip netns add "$gnd" 2>/dev/null; then
  echo "ground_link.sh: SKIP: cannot create network namespaces here" >&2
  exit 77
fi
ip link add air0 netns "$air" type veth peer name gnd0 netns "$gnd"
ip -n "$air" addr add 10.77.0.1/24 dev air0
ip -n "$gnd" addr add 10.77.0.2/24 dev gnd0
for ns in "$air" "$gnd"; do
  ip -n "$ns" link set lo up
  dev=$([ "$ns" = "$air" ] && echo air0 || echo gnd0)
  ip -n "$ns" link set "$dev" up
  ip -n "$ns" route add 224.0.0.0/4 dev "$dev"  # SPDP multicast
done

cat > "$work/air.yaml" <<EOF
domain: $domain
vehicle: uav1
low_rate_period: 1.0
qos_file: $root/deploy/qos.xml
dds_transport: udp
log_level: warn
buses:
  - interface: sim
    name: can0
    devices:
      - address: 1
        period: $period
EOF
ip netns exec "$air" "$svc" --config "$work/air.yaml" > "$work/service.log" 2>&1 &
pids+=($!)

ground_bytes() {
  ip -n "$gnd" -j -s link show gnd0 | python3 -c 'import json,sys; s=json.load(sys.stdin)[0]["stats64"]; print(s["rx"]["bytes"] + s["tx"]["bytes"])'
}

# One phase: optional pmuctl in the ground namespace, warm-up, then S seconds counted.
phase() {  # NAME [pmuctl watch options...]
  local name=$1; shift
  local out="$work/$name.jsonl" p=""
  : > "$out"
  if [ "$name" != idle ]; then
    PMU_QOS_FILE="$root/deploy/qos.xml" ip netns exec "$gnd" "$ctl" --domain "$domain" --json watch "$@" > "$out" 2> "$work/$name.err" &
    p=$!
    pids+=("$p")
  fi
  sleep 5  # discovery and the first samples: not part of the steady cost
  local b0 l0 b1 l1 t0 t1
  b0=$(ground_bytes); l0=$(wc -l < "$out"); t0=$(date +%s.%N)
  sleep "$seconds"
  b1=$(ground_bytes); l1=$(wc -l < "$out"); t1=$(date +%s.%N)
  if [ -n "$p" ]; then kill "$p" 2>/dev/null || true; wait "$p" 2>/dev/null || true; fi
  sleep 2  # the reader's leaving settles before the next phase
  python3 -c "t = $t1 - $t0; print('%s %.1f %.2f' % ('$name', ($b1 - $b0) / t, ($l1 - $l0) / t))"
}

sleep 2
results=$( { phase idle; phase full; phase low --low-rate; } )
RESULTS="$results" python3 - "$period" "$seconds" "$check" "$json_out" <<'PY'
import json, os, sys
period, seconds, check, json_out = float(sys.argv[1]), float(sys.argv[2]), sys.argv[3] == "1", sys.argv[4]
r = {}
for line in os.environ["RESULTS"].split("\n"):
    if line.strip():
        name, bps, sps = line.split()
        r[name] = {"bytes_per_s": float(bps), "samples_per_s": float(sps)}
full, low, idle = r["full"], r["low"], r["idle"]
ratio = low["bytes_per_s"] / full["bytes_per_s"] if full["bytes_per_s"] else float("nan")
print(f"ground link, one PMU streaming 5 packets every {period} s, {seconds:.0f} s per phase:")
print(f"  discovery only (no subscriber): {idle['bytes_per_s']:9.0f} B/s")
print(f"  full rate   (pmuctl watch):     {full['bytes_per_s']:9.0f} B/s = {full['bytes_per_s']*8/1000:6.1f} kbit/s, {full['samples_per_s']:5.1f} samples/s")
print(f"  low rate    (watch --low-rate): {low['bytes_per_s']:9.0f} B/s = {low['bytes_per_s']*8/1000:6.1f} kbit/s, {low['samples_per_s']:5.1f} samples/s")
print(f"  low / full = {ratio:.3f}")
if json_out:
    with open(json_out, "w") as f:
        json.dump({"period": period, "seconds": seconds, **r, "low_over_full": ratio}, f, indent=1)
if check:
    problems = []
    if full["samples_per_s"] < 0.7 * 5 / period:
        problems.append(f"full rate delivered {full['samples_per_s']:.1f} samples/s, expected about {5/period:.0f}")
    if not 3.5 <= low["samples_per_s"] <= 6.5:
        problems.append(f"low rate delivered {low['samples_per_s']:.1f} samples/s, expected about 5 (one per packet per second)")
    if not ratio <= 1 / 3:
        problems.append(f"the low-rate topics cost {ratio:.2f} of the full rate on the link (more than a third)")
    for p in problems:
        print("ground_link.sh: FAIL: " + p, file=sys.stderr)
    sys.exit(1 if problems else 0)
PY
