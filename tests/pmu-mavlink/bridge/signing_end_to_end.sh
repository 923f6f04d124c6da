#!/usr/bin/env bash
# pmu-mavlink's message signing end to end (interface.md 12.6) with a node-mavlink ground
# station that signs (signed_ground_station.mjs), the key file holding the passphrase both
# use. Checks: every frame pmu-mavlink sends is signed and verifies under node-mavlink; a
# signed SET_MESSAGE_INTERVAL is answered, an unsigned RUN_PREARM_CHECKS, a
# SET_MESSAGE_INTERVAL signed with another key and a replayed one are not, and the counters
# printed at exit show one of each; without --system-id, an unsigned autopilot HEARTBEAT does
# not set the system id, a signed one does; a key file others can read, a missing one and an
# empty one stop the start (exit 2) with the reason; without a key, the log says what that
# means. No pmu-service: what is checked needs none. Exit 77 (skipped) without Node.js or
# node-mavlink.
#   signing_end_to_end.sh PMU-MAVLINK SOURCE-DIR
set -uo pipefail
bridge=$1 src=$2
. "$src/tests/pmu-mavlink/bridge/ground_station_setup.sh"

passphrase="pmu-dds signing end to end"
(umask 077 && printf '%s\n' "$passphrase" >"$work/signing.key")
# The ground station resolves node-mavlink from tests/mavlink's node_modules, linked beside
# its copy in the work folder (nothing is written into the source tree).
ln -s "$src/tests/mavlink/node_modules" "$work/node_modules"
gs="$work/signed_ground_station.mjs"
cp "$here/signed_ground_station.mjs" "$gs"

# run_gs MODE OUT -- BRIDGE-ARGS...: the ground station, then pmu-mavlink towards it; waits
# for the ground station to end (60 s only turns "never" into a FAIL line), then stops
# pmu-mavlink with SIGTERM. Leaves its log in $work/OUT.log.
run_gs() {
  local mode=$1 out=$2
  shift 3
  : >"$work/port"
  node "$gs" "$work/port" "$work/$out.jsonl" "$passphrase" "$mode" 2>"$work/$out.err" &
  local gs_pid=$!
  pids+=($gs_pid)
  for _ in $(seq 100); do [ -s "$work/port" ] && break; sleep 0.1; done
  [ -s "$work/port" ] || { fail "the ground station did not bind: $(cat "$work/$out.err")"; return; }
  "$bridge" --udp "127.0.0.1:$(cat "$work/port")" --domain "$domain" "$@" >"$work/$out.log" 2>&1 &
  local bridge_pid=$!
  pids+=($bridge_pid)
  local end=$((SECONDS + 60))
  while kill -0 "$gs_pid" 2>/dev/null && ((SECONDS < end)); do sleep 0.2; done
  if kill -0 "$gs_pid" 2>/dev/null; then
    kill "$gs_pid"
    fail "$mode: the ground station did not finish in 60 s: $(tail -n3 "$work/$out.jsonl" | cut -c1-120)"
  else
    wait "$gs_pid" || fail "$mode: the ground station: $(grep problem "$work/$out.jsonl" | head -n3) $(cat "$work/$out.err")"
  fi
  kill -TERM "$bridge_pid" 2>/dev/null
  wait "$bridge_pid"
  local status=$?
  [ $status -eq 0 ] || fail "$mode: pmu-mavlink exited $status on SIGTERM: $(tail -n3 "$work/$out.log")"
  ! grep -q '"problem"' "$work/$out.jsonl" || fail "$mode: $(grep '"problem"' "$work/$out.jsonl" | head -n5)"
}

# Signed commands answered, the three bad ones not.
run_gs commands commands -- --system-id 1 --signing-key "$work/signing.key"
grep -q "MAVLink signing on" "$work/commands.log" || fail "no 'signing on' line at start: $(head -n3 "$work/commands.log")"
python3 - "$work/commands.jsonl" <<'PY' || failures=$((failures + 1))
import json, sys
lines = [json.loads(l) for l in open(sys.argv[1]) if l.strip()]
acks = [l["ack"] for l in lines if "ack" in l]
problems = []
if sum(1 for l in lines if "name" in l) < 2: problems.append("fewer than two frames from pmu-mavlink")
if [a["command"] for a in acks if a["command"] == 511] != [511]:
    problems.append(f"SET_MESSAGE_INTERVAL answered {sum(1 for a in acks if a['command'] == 511)} times, want once (the signed one): {acks}")
elif acks[0]["result"] != 0: problems.append(f"the signed SET_MESSAGE_INTERVAL: {acks[0]}, want ACCEPTED (0)")
if any(a["command"] == 401 for a in acks): problems.append(f"the unsigned RUN_PREARM_CHECKS was answered: {acks}")
if not any(a["command"] == 31000 for a in acks): problems.append(f"the signed MAV_CMD_USER_1 was not answered: {acks}")
if problems:
    print("FAIL: " + "\n  ".join(problems), file=sys.stderr); sys.exit(1)
print(f"{len(lines)} signed frames from pmu-mavlink verified under node-mavlink; {len(acks)} answers")
PY
counters=$(grep "pmu-mavlink: signing:" "$work/commands.log")
[ -n "$counters" ] || fail "no signing counters at exit: $(tail -n4 "$work/commands.log")"
for want in "accepted 2" "unsigned 1" "bad signature 1" "replayed 1" "stale 0"; do
  grep -Eq "${want}([,;]|\$)" <<<"$counters" || fail "signing counters: want '$want' in: $counters"
done
grep -Eq "frames signed [1-9]" <<<"$counters" || fail "no frame counted as signed: $counters"

# The system id from a signed autopilot HEARTBEAT only.
run_gs learn learn -- --signing-key "$work/signing.key"
grep -Eq "pmu-mavlink: signing: .*accepted 1; refused: unsigned 1," "$work/learn.log" ||
  fail "learn: the unsigned HEARTBEAT not counted, or the signed one not accepted: $(grep 'signing:' "$work/learn.log")"

# The key file checked at start: exit 2 and the reason, before any endpoint opens.
check_refused() {
  local what=$1 want=$2
  shift 2
  "$bridge" --udp 127.0.0.1:9 --domain "$domain" "$@" >"$work/refused.log" 2>&1
  local status=$?
  [ $status -eq 2 ] || fail "$what: exit $status, want 2: $(head -n2 "$work/refused.log")"
  grep -qF "$want" "$work/refused.log" || fail "$what: want '$want' in: $(head -n2 "$work/refused.log")"
}
printf '%s\n' "$passphrase" >"$work/open.key"
chmod 644 "$work/open.key"
check_refused "a key others can read" "$work/open.key: is accessible by group or others" --signing-key "$work/open.key"
check_refused "a missing key" "$work/missing.key: does not exist" --signing-key "$work/missing.key"
(umask 077 && : >"$work/empty.key")
check_refused "an empty key" "$work/empty.key: is empty" --signing-key "$work/empty.key"
printf 'udp: 127.0.0.1:9\nsigning_key: %s\n' "$work/open.key" >"$work/config.yaml"
check_refused "a key from the config file" "$work/open.key: is accessible by group or others" --config "$work/config.yaml"

# Without a key: the log says what that means.
"$bridge" --udp 127.0.0.1:9 --domain "$domain" >"$work/nokey.log" 2>&1 &
nokey=$!
pids+=($nokey)
for _ in $(seq 100); do grep -q "signing off" "$work/nokey.log" && break; sleep 0.1; done
grep -q "MAVLink signing off (no --signing-key): .*anyone in range of a radio link.*can command the power system" \
  "$work/nokey.log" || fail "without a key: no warning in the log: $(head -n3 "$work/nokey.log")"
kill -TERM "$nokey"
wait "$nokey"

exit $((failures > 0))
