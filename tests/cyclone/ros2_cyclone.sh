#!/usr/bin/env bash
# ros2_cyclone.sh SERVICE READER QOS_FILE
# pmu-service (Fast DDS) with ros2: enabled on the built-in simulator, read by
# cyclone_ros2_reader as rmw_cyclonedds would read it: each value as the simulator set it.
set -euo pipefail
service=$1 reader=$2 qos=$3
. "$(dirname "${BASH_SOURCE[0]}")/../support/dds_domain.sh"
pmu_test_dds_domain
domain=$PMU_TEST_DDS_DOMAIN
work=$(mktemp -d /tmp/pmu-ros2-cyclone-XXXXXX)
service_pid=
cleanup() {
  if [ -n "$service_pid" ]; then kill "$service_pid" 2>/dev/null || true; wait "$service_pid" 2>/dev/null || true; fi
  rm -rf "$work"
}
trap cleanup EXIT

cat >"$work/pmu-service.yaml" <<YAML
domain: $domain
qos_file: $qos
vehicle: uav1
ros2:
  enabled: true
  namespace: /test
buses:
  - interface: sim
    devices:
      - address: 1
        sim: {battery_a_voltage: 24.6, serial: 4321}
    batteries:
      - node: 2
        capacity_ah: 20
        sim:
          state_of_charge: 80
          cell_voltages: [4.0, 4.0, 4.0, 4.0, 4.0, 4.0, 4.0, 4.0, 4.0, 4.0, 4.0, 4.0]
YAML
"$service" --config "$work/pmu-service.yaml" >"$work/service.log" 2>&1 &
service_pid=$!

fail() { echo "FAIL: $*"; echo "--- reader:"; cat "$work/out" 2>/dev/null; echo "--- service log:"; cat "$work/service.log"; exit 1; }
"$reader" "$domain" /test/uav1/sim >"$work/out" 2>&1 || fail "the Cyclone reader missed a topic"
cat "$work/out"
expect() { grep -q -- "$1" "$work/out" || fail "no '$1'"; }
expect '^battery_a voltage=24.6 .* temperature=25 .*present=1 .*health=1 location=battery_a serial=pmu 4321 frame_id=test/uav1/sim/pmu_1$'
expect '^bms voltage=48 current=-[0-9.]* .*percentage=0.8 charge=16 design_capacity=20 cells=12 present=1 status=2 health=1 location=bms node 2 serial= frame_id=test/uav1/sim/bms_2$'
expect '^diagnostics name=test/uav1/sim/\(pmu_1\|bms_2\) level=0 message=online hardware_id=\(pmu serial 4321\|pmu at address 1\|bms node 2\) values=1[0-9]$'
echo "ros2_cyclone: the Cyclone DDS reader got battery_a, the BMS and /diagnostics with the simulator's values"
