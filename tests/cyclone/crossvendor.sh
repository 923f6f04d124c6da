#!/usr/bin/env bash
# crossvendor.sh SERVICE PMUCTL CLIENT QOS_FILE RUNS [CLIENT OPTIONS...]
# Starts pmu-service --bus sim (Fast DDS) on a domain of its own, waits until it publishes
# its state, then runs the Cyclone DDS client RUNS times in a row, each a new late joiner.
# Then a second pmu-service serving a battery and an MPPT (canopen_feeder.py plays them on
# its bus) and the client once more, checking pmu/battery, pmu/battery_cells, pmu/mppt and
# their pmu/health instances. Fails, saying which run missed what, if any run misses anything.
set -euo pipefail
service=$1 pmuctl=$2 client=$3 qos=$4 runs=$5
shift 5

# A domain no other test process uses, held (flock) while this script and its children run:
# the same lock files as pmu::test::exclusive_dds_domain() in the C++ tests.
. "$(dirname "${BASH_SOURCE[0]}")/../support/dds_domain.sh"
pmu_test_dds_domain
domain=$PMU_TEST_DDS_DOMAIN
work=$(mktemp -d /tmp/pmu-crossvendor-XXXXXX)
service_pid=
feeder_pid=
cleanup() {
  if [ -n "$service_pid" ]; then kill "$service_pid" 2>/dev/null || true; wait "$service_pid" 2>/dev/null || true; fi
  if [ -n "$feeder_pid" ]; then kill "$feeder_pid" 2>/dev/null || true; wait "$feeder_pid" 2>/dev/null || true; fi
  rm -rf "$work"
}
trap cleanup EXIT

export PMU_QOS_FILE=$qos
"$service" --bus sim --domain "$domain" --log-level warn >"$work/service.log" 2>&1 &
service_pid=$!

# The service is "up" once a client can read its state; pmuctl (Fast DDS) says so.
up=0
for _ in $(seq 1 60); do
  if "$pmuctl" --domain "$domain" --timeout 1 list >/dev/null 2>&1; then up=1; break; fi
  kill -0 "$service_pid" 2>/dev/null || break
  sleep 0.5
done
if [ "$up" != 1 ]; then
  echo "crossvendor: pmu-service on domain $domain never published its state; its log:" >&2
  cat "$work/service.log" >&2
  exit 1
fi

failed=0
for run in $(seq 1 "$runs"); do
  if out=$("$client" --domain "$domain" "$@" 2>&1); then
    echo "run $run: $(grep '^summary' <<<"$out")"
  else
    failed=$((failed + 1))
    echo "run $run FAILED:"
    sed 's/^/  /' <<<"$out"
  fi
done
if ! kill -0 "$service_pid" 2>/dev/null; then
  echo "crossvendor: pmu-service died during the runs; its log:" >&2
  cat "$work/service.log" >&2
  exit 1
fi
echo "crossvendor: $((runs - failed)) of $runs Cyclone DDS client runs without a miss (domain $domain)"
kill "$service_pid" 2>/dev/null || true
wait "$service_pid" 2>/dev/null || true
service_pid=

# Batteries and MPPTs (interface.md 1.4), through pmu-service's SocketCAN code on an fd bus.
cat >"$work/canopen.yaml" <<'YAML'
buses:
  - interface: can9
    batteries:
      - node: 2
        period: 0.5
    mppts:
      - device: 4
        period: 0.5
YAML
python3 "$(dirname "${BASH_SOURCE[0]}")/canopen_feeder.py" "$service" "$work/canopen.yaml" "$domain" "$work/bus" \
  --log-level warn >"$work/canopen.log" 2>&1 &
feeder_pid=$!
up=0
for _ in $(seq 1 60); do
  if [ -s "$work/bus" ] && "$pmuctl" --domain "$domain" --timeout 1 list 2>/dev/null | grep -q battery2; then up=1; break; fi
  kill -0 "$feeder_pid" 2>/dev/null || break
  sleep 0.5
done
if [ "$up" != 1 ]; then
  echo "crossvendor: pmu-service with a battery and an MPPT never listed them; its log:" >&2
  cat "$work/canopen.log" >&2
  exit 1
fi
bus=$(cat "$work/bus")
if out=$("$client" --domain "$domain" --canopen-bus "$bus" --telemetry-ms 10000 2>&1); then
  echo "canopen run: $(grep '^summary' <<<"$out")"
else
  failed=$((failed + 1))
  echo "canopen run FAILED:"
  sed 's/^/  /' <<<"$out"
fi
[ "$failed" -eq 0 ]
