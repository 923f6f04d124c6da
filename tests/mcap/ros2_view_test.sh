#!/usr/bin/env bash
# pmuctl record and serve of the ROS 2 topics pmu-service writes (docs/interface.md 9.1, 9.2,
# 11): the service with `vehicle: uav1` and `ros2: {enabled: true}` on the simulated power
# system.
#   record: the recording's /diagnostics and battery channels (found in DDS discovery), read
#     by @mcap/core and decoded by Foxglove's ROS 2 decoder from the channels' ros2msg schemas
#     (check_ros2_recording.mjs); --topic by a ROS 2 name; --vehicle's battery topics only; an
#     unknown ROS 2 name refused.
#   serve: Foxglove's WebSocket client (serve_ros2_client.mjs) connected before the service
#     runs gets the ROS 2 channels advertised when they are found; one connecting later gets
#     them in the first advertise and /diagnostics's kept message at once.
#   ros2_view_test.sh PMU-SERVICE PMUCTL SOURCE-DIR record|serve
set -uo pipefail
svc=$1 ctl=$2 src=$3 mode=$4
. "$(dirname "$0")/mcap_env.sh"
. "$src/tests/support/dds_domain.sh"
pmu_test_dds_domain || exit 1
domain=$PMU_TEST_DDS_DOMAIN
export PMU_QOS_FILE="$src/deploy/qos.xml"
work=$(mktemp -d)
pid=
server=
trap '[ -n "$server" ] && kill "$server" 2>/dev/null; [ -n "$pid" ] && kill "$pid" 2>/dev/null; wait 2>/dev/null; rm -rf "$work"' EXIT
{ cat "$src/deploy/examples/sim-power-system.yaml"; printf 'vehicle: uav1\nros2:\n  enabled: true\n'; } >"$work/ros2.yaml"
start_service() {
  "$svc" --config "$work/ros2.yaml" --domain "$domain" >"$work/service.log" 2>&1 &
  pid=$!
}
failures=0
fail() { echo "FAIL: $*" >&2; failures=$((failures + 1)); }
# holds FILE FLAGS...: the complete chunks of FILE's temporary file pass check_ros2_recording.mjs
holds() {
  local f name=$1
  shift
  f=$(ls "$name".partial-* 2>/dev/null) && [ -n "$f" ] && read_mcap --stream "$f" >"$work/poll.jsonl" 2>/dev/null &&
    node "$MCAP_TESTS_DIR/check_ros2_recording.mjs" "$work/poll.jsonl" --crashed "$@" >/dev/null 2>&1
}
# record NAME FLAGS -- PMUCTL-ARGS...: runs pmuctl with PMUCTL-ARGS, FILE standing for the
# recording's path, until the file holds what FLAGS check; stops it with SIGINT and checks the
# complete file with the indexed reader. As in record_test.sh, a recorder is stopped once its
# output holds what is checked; the 30 s bound only turns "never" into a FAIL line.
record() {
  local name=$1 flags=() args=()
  shift
  while [ "$1" != "--" ]; do flags+=("$1"); shift; done
  shift
  for a in "$@"; do [ "$a" = FILE ] && args+=("$work/$name.mcap") || args+=("$a"); done
  "$ctl" --domain "$domain" "${args[@]}" 2>"$work/$name.err" &
  local rec=$!
  local end=$((SECONDS + 30))
  until holds "$work/$name.mcap" "${flags[@]}"; do
    if ! kill -0 "$rec" 2>/dev/null || ((SECONDS >= end)); then
      fail "$name: the recording is not as checked (after $((30 - end + SECONDS)) s)"
      break
    fi
    sleep 0.5
  done
  kill -INT "$rec" 2>/dev/null
  wait "$rec" || fail "$name: record exited $?: $(cat "$work/$name.err")"
  if read_mcap "$work/$name.mcap" >"$work/$name.jsonl"; then
    node "$MCAP_TESTS_DIR/check_ros2_recording.mjs" "$work/$name.jsonl" "${flags[@]}" || fail "$name (indexed reader)"
  else
    fail "$name: @mcap/core's indexed reader or Foxglove's decoders refused the file"
  fi
}

case "$mode" in
record)
start_service
# 1. By default: the contract's topics and every ROS 2 topic of the service.
record all --batteries -- record FILE
grep -q '"topic":"pmu/voltages"' "$work/all.jsonl" || fail "all: no pmu/voltages beside the ROS 2 topics"
# 2. By ROS 2 name, and by DDS name: those alone.
record named --batteries --only-ros2 -- record --topic /diagnostics --topic rt/uav1/sim0/pmu_1/battery_a \
  --topic /uav1/sim0/pmu_1/battery_b --topic /uav1/sim0/bms_2/battery FILE
record diagnostics --no-batteries --only-ros2 -- record --topic rt/diagnostics FILE
# 3. --vehicle: that vehicle's battery topics; /diagnostics is every vehicle's.
record uav1 --batteries -- --vehicle uav1 record FILE
record uav2 --no-batteries -- --vehicle uav2 record FILE
# 4. A name that is no topic of the service: refused before any participant, exit 2.
"$ctl" --domain "$domain" record --topic /uav1/sim0/pmu_1/voltage "$work/x.mcap" 2>"$work/err"; status=$?
[ $status -eq 2 ] || fail "an unknown ROS 2 name: exit $status, want 2"
grep -q "/uav1/sim0/pmu_1/voltage" "$work/err" || fail "the refusal does not name the topic: $(cat "$work/err")"
[ ! -e "$work/x.mcap" ] || fail "a refused recording created its file"
;;

serve)
port=$(python3 -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1",0)); print(s.getsockname()[1])')
"$ctl" --domain "$domain" serve --port "$port" 2>"$work/serve.err" &
server=$!
for _ in $(seq 200); do
  grep -q "serving .* on ws://" "$work/serve.err" && break
  kill -0 "$server" 2>/dev/null || break
  sleep 0.1
done
grep -q "serving .* on ws://" "$work/serve.err" || { fail "serve did not start: $(cat "$work/serve.err")"; exit 1; }
# Connected before any ROS 2 topic exists: the channels come in a later advertise.
node "$MCAP_TESTS_DIR/serve_ros2_client.mjs" "ws://127.0.0.1:$port" early 30 &
early=$!
for _ in $(seq 100); do
  grep -q "client 127.0.0.1:[0-9]* connected" "$work/serve.err" && break
  sleep 0.1
done
start_service
wait "$early" || fail "serve_ros2_client early"
node "$MCAP_TESTS_DIR/serve_ros2_client.mjs" "ws://127.0.0.1:$port" late 30 || fail "serve_ros2_client late"
kill -INT "$server"
wait "$server" || fail "serve exited $?: $(tail -n 5 "$work/serve.err")"
server=
;;
esac

if [ $failures -ne 0 ]; then
  echo "service log:" >&2
  tail -20 "$work/service.log" >&2
  exit 1
fi
echo "ok"
