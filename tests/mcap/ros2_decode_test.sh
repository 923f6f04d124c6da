#!/usr/bin/env bash
# The ROS 2 samples of pmu-service (ros2: enabled) decoded by Foxglove's ROS 2 decoder with the
# upstream definitions: the end-to-end test captures each sample's bytes as they came off the
# wire, and ros2_decode.mjs decodes them and compares every field.
#   ros2_decode_test.sh INTEGRATION_TESTS
set -euo pipefail
TESTS=$1
. "$(dirname "$0")/mcap_env.sh"
if [ ! -d "$MCAP_TESTS_DIR/node_modules/@foxglove/rosmsg2-serialization" ]; then
  echo "SKIP: @foxglove/rosmsg2-serialization is not installed (scripts/setup.sh runs npm ci in tests/mcap)"; exit 77
fi
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
PMU_ROS2_CAPTURE="$work/capture.jsonl" "$TESTS" --gtest_filter='Ros2OverDds.*' > "$work/gtest.log" 2>&1 ||
  { echo "FAIL: the end-to-end test failed:"; tail -n 40 "$work/gtest.log"; exit 1; }
# battery_a, battery_b, the BMS's battery and one /diagnostics array
node "$MCAP_TESTS_DIR/ros2_decode.mjs" "$work/capture.jsonl" 4
