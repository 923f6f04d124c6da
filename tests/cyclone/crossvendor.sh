#!/usr/bin/env bash
# crossvendor.sh SERVICE PMUCTL CLIENT QOS_FILE RUNS [CLIENT OPTIONS...]
# Starts pmu-service --bus sim (Fast DDS) on a domain of its own, waits until it publishes
# its state, then runs the Cyclone DDS client RUNS times in a row, each a new late joiner.
# Fails, saying which run missed what, if any run misses anything.
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
cleanup() {
  if [ -n "$service_pid" ]; then kill "$service_pid" 2>/dev/null || true; wait "$service_pid" 2>/dev/null || true; fi
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
[ "$failed" -eq 0 ]
