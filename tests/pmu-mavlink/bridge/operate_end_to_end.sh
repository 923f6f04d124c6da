#!/usr/bin/env bash
# pmu-mavlink's parameters and commands end to end: pmu-service on the demo power system
# (deploy/examples/sim-power-system.yaml, its PMU's engine stopped so that a start has
# something to do), pmu-mavlink with --udp to a node-mavlink ground station (operator.mjs).
# Checks, against the service and pmuctl:
#   - the parameter list: every parameter, each value the one `pmuctl config snapshot` writes;
#   - a set of PMU1_SERVO_V addressed to the autopilot neither answered nor carried out;
#   - a set of PMU1_SERVO_V answered by exactly one PARAM_VALUE with the new value, which
#     pmuctl then shows; a set out of range answered with the old value and a STATUSTEXT
#     saying why;
#   - DO_SET_RELAY payload off: ACCEPTED, and pmuctl shows the output off;
#   - DO_ENGINE_CONTROL start without --confirm engine_start: DENIED, a STATUSTEXT naming the
#     rule, nothing sent to the service;
#   - with --confirm engine_start: IN_PROGRESS at once, ACCEPTED when the engine runs, and
#     the ground station's retransmission (the same COMMAND_LONG, confirmation 1) answered
#     IN_PROGRESS and executed once: the service's audit log has one line per command it
#     carried out (`audit: command ID from SENDER: engine_start ... -> RESULT`, written
#     once per request at its final reply; a resend of the same id is logged apart as
#     "duplicate command ... not executed"), so one engine_start line is one execution;
#   - the program's counters at exit.
# Exit 77 (skipped) without Node.js or node-mavlink.
#   operate_end_to_end.sh PMU-SERVICE PMU-MAVLINK PMUCTL SOURCE-DIR
set -uo pipefail
svc=$1 bridge=$2 ctl=$3 src=$4
. "$src/tests/pmu-mavlink/bridge/ground_station_setup.sh"

# The demo's PMU with its engine stopped; it fires after 1 s of cranking.
sed 's/^      - address: 1$/      - address: 1\n        sim: {engine: stopped, engine_starts_after: 1}/' \
  "$src/deploy/examples/sim-power-system.yaml" >"$work/system.yaml"
grep -q engine_starts_after "$work/system.yaml" || { echo "FAIL: the demo config's PMU line moved: cannot add its sim: setting" >&2; exit 1; }
"$svc" --config "$work/system.yaml" --domain "$domain" >"$work/service.log" 2>&1 &
pids+=($!)
ln -s "$src/tests/mavlink/node_modules" "$work/node_modules"
op="$work/operator.mjs"
cp "$here/operator.mjs" "$op"

# What the service holds before anything is set: the list must show exactly this.
"$ctl" --domain "$domain" --timeout 30 config snapshot "$work/before.yaml" 2>"$work/before.err" ||
  { echo "FAIL: pmuctl config snapshot: $(cat "$work/before.err")" >&2; exit 1; }

# run MODE OUT [BRIDGE OPTIONS...]: the operator in MODE against a new pmu-mavlink, until it
# exits (60 s turns "never" into a FAIL line); then pmu-mavlink is stopped and its log kept.
run() {
  local mode=$1 out=$2
  shift 2
  : >"$work/port"
  node "$op" "$work/port" "$work/$out.jsonl" "$mode" 2>"$work/$out.err" &
  local gs_pid=$!
  pids+=($gs_pid)
  for _ in $(seq 100); do [ -s "$work/port" ] && break; sleep 0.1; done
  [ -s "$work/port" ] || { fail "$mode: the operator did not bind: $(cat "$work/$out.err")"; return; }
  "$bridge" --udp "127.0.0.1:$(cat "$work/port")" --system-id 1 --domain "$domain" "$@" >"$work/$out.log" 2>&1 &
  local bridge_pid=$!
  pids+=($bridge_pid)
  local end=$((SECONDS + 60))
  while kill -0 "$gs_pid" 2>/dev/null && ((SECONDS < end)); do sleep 0.2; done
  if kill -0 "$gs_pid" 2>/dev/null; then
    fail "$mode: the operator did not finish in 60 s; last: $(grep -v '"HEARTBEAT"\|"BATTERY_STATUS"\|"GENERATOR_STATUS"' "$work/$out.jsonl" | tail -n4 | cut -c1-160)"
    kill "$gs_pid"
  else
    wait "$gs_pid" || fail "$mode operator: $(cat "$work/$out.err")"
  fi
  kill -TERM "$bridge_pid"
  wait "$bridge_pid" || fail "$mode: pmu-mavlink exited $? on SIGTERM: $(tail -n3 "$work/$out.log")"
}

run operate operate
"$ctl" --domain "$domain" --timeout 30 config snapshot "$work/after.yaml" 2>"$work/after.err" ||
  fail "pmuctl config snapshot after the set: $(cat "$work/after.err")"
starts_before=$(grep -c 'audit: command .*engine_start' "$work/service.log")
run start start --confirm engine_start
# The service writes the audit line before it sends the final reply the operator waited for.
grep 'audit: command .*engine_start' "$work/service.log" >"$work/starts"

grep -q "not addressed to us 1$" "$work/operate.log" ||
  fail "the set addressed to the autopilot is not counted: $(grep 'parameters:' "$work/operate.log")"
for log in operate start; do
  grep -q "pmu-mavlink: parameters: list requests" "$work/$log.log" &&
    grep -q "pmu-mavlink: commands: received" "$work/$log.log" &&
    grep -q "pmu-mavlink: service requests: written" "$work/$log.log" ||
    fail "$log: the protocol counters are not printed at exit: $(cat "$work/$log.log")"
done

python3 - "$work" "$starts_before" <<'PY' || failures=$((failures + 1))
import json, sys, yaml
work, starts_before = sys.argv[1], int(sys.argv[2])
def lines(name): return [json.loads(l) for l in open(f"{work}/{name}.jsonl") if l.strip()]
problems = []
# Masks as their numbers, from the snapshot's bit names (interface.md 3.2).
BITS = {"packets_streamed": ["voltages", "currents", "battery_energy", "temperatures", "status"],
        "outputs": ["avionics_servo", "payload", "charger_a", "charger_b"],
        "power_up_state": ["avionics_servo", "payload", "charger_a", "charger_b", "battery_disconnect_detect",
                           "payload_shedding", "soa_management"]}
NAMES = {"AVION_V": "avionics_voltage", "PAYLD_V": "payload_voltage", "SERVO_V": "servo_voltage",
         "BATT_V": "battery_voltage", "PKT_PERIOD": "packet_period", "PKT_STREAM": "packets_streamed",
         "TEMP_OFFSET": "temperature_offset", "TEMP_UPPER": "upper_temperature_limit", "POWERUP": "power_up_state",
         "CRANK_TIME": "cranking_time", "CAN_ADDR": "can_address", "OUTPUTS": "outputs", "GEN_ENABLE": "generation_enabled"}
def snapshot(path):
    doc = yaml.safe_load(open(path))
    values = dict(doc.get("parameters") or {})
    values["outputs"] = doc.get("outputs")
    values["generation_enabled"] = doc.get("generation_enabled")
    def number(k, v):
        if k in BITS and isinstance(v, list): return sum(1 << BITS[k].index(b) for b in v)
        if v in ("none", None) and k in BITS: return 0
        if isinstance(v, bool): return 1 if v else 0
        return float(v)
    return {k: number(k, v) for k, v in values.items()}
before, after = snapshot(f"{work}/before.yaml"), snapshot(f"{work}/after.yaml")

msgs = lines("operate")
sent_at = lambda pred: next((i for i, m in enumerate(msgs) if "sent" in m and pred(m)), None)
got = lambda name, since=0, until=None: [m for m in msgs[since:until] if m.get("name") == name]
first_set = sent_at(lambda m: m["sent"] == "PARAM_SET")
if first_set is None: problems.append("no PARAM_SET was sent: the list never completed")
else:
    listed = {}
    counts = set()
    for m in got("PARAM_VALUE", 0, first_set):
        f = m["fields"]; listed[f["paramIndex"]] = f; counts.add(f["paramCount"])
    if counts != {13}: problems.append(f"param_count {counts}, want 13 (one PMU)")
    if sorted(listed) != list(range(13)): problems.append(f"indices listed {sorted(listed)}, want 0..12")
    for f in listed.values():
        name = f["paramId"].rstrip("\x00")
        key = NAMES.get(name.removeprefix("PMU1_"))
        if f["paramType"] != 9: problems.append(f"{name}: type {f['paramType']}, want REAL32 (9)")
        if key is None or key not in before: problems.append(f"{name}: not in pmuctl's snapshot {sorted(before)}"); continue
        if abs(f["paramValue"] - before[key]) > 1e-3: problems.append(f"{name} = {f['paramValue']}, pmuctl {key}: {before[key]}")

    if msgs[first_set]["fields"]["targetComponent"] != 1: problems.append("the set addressed to the autopilot was not sent first")
    first_set = sent_at(lambda m: m["sent"] == "PARAM_SET" and m["fields"]["targetComponent"] == 180)
    set_value = msgs[first_set]["fields"]["paramValue"]
    second_set = sent_at(lambda m: m["sent"] == "PARAM_SET" and m["fields"]["paramValue"] == 30.0)
    if any(m["fields"]["paramValue"] == 9.0 for m in got("PARAM_VALUE")):
        problems.append("the set addressed to the autopilot (9.0) was answered")
    answers = [m["fields"] for m in got("PARAM_VALUE", first_set, second_set) if m["fields"]["paramId"].startswith("PMU1_SERVO_V")]
    if len(answers) != 1 or abs(answers[0]["paramValue"] - set_value) > 1e-3:
        problems.append(f"the set of PMU1_SERVO_V to {set_value}: answered by {answers}, want exactly one PARAM_VALUE with it")
    said = [m["fields"]["text"] for m in got("STATUSTEXT", first_set, second_set) if "SERVO_V" in m["fields"]["text"]]
    if said: problems.append(f"the set of PMU1_SERVO_V to {set_value} was verified, yet: {said}")
    if abs(after.get("servo_voltage", -1) - set_value) > 1e-3:
        problems.append(f"pmuctl shows servo_voltage {after.get('servo_voltage')} after the set to {set_value}")
    if second_set is None: problems.append("the out-of-range set was not sent")
    else:
        relay = sent_at(lambda m: m["sent"] == "COMMAND_LONG")
        answers = [m["fields"] for m in got("PARAM_VALUE", second_set, relay) if m["fields"]["paramId"].startswith("PMU1_SERVO_V")]
        texts = [m["fields"]["text"] for m in got("STATUSTEXT", second_set, relay)]
        if len(answers) != 1 or abs(answers[0]["paramValue"] - set_value) > 1e-3:
            problems.append(f"the set to 30.0: answered by {answers}, want one PARAM_VALUE with the old value {set_value}")
        if not any(t.startswith("PMU1_SERVO_V not set") and "out of range" in t for t in texts):
            problems.append(f"the set to 30.0: no STATUSTEXT saying it is out of range: {texts}")

acks = lambda ms, cmd: [m["fields"] for m in ms if m.get("name") == "COMMAND_ACK" and m["fields"]["command"] == cmd]
relay = acks(msgs, 181)
if not relay or relay[-1]["result"] != 0: problems.append(f"DO_SET_RELAY payload off: {relay}, want ACCEPTED")
if after.get("outputs", 0) & 2 or not before.get("outputs", 0) & 2:
    problems.append(f"outputs before {before.get('outputs')}, after {after.get('outputs')}: want payload (bit 1) on, then off")
denied = acks(msgs, 223)
texts = [m["fields"]["text"] for m in msgs if m.get("name") == "STATUSTEXT"]
if [a["result"] for a in denied] != [2]: problems.append(f"engine start without --confirm: acks {denied}, want one DENIED (2)")
if not any("rule engine_start" in t for t in texts): problems.append(f"no STATUSTEXT naming rule engine_start: {texts}")
if starts_before != 0: problems.append(f"{starts_before} engine starts reached the service without --confirm engine_start")
for a in acks(msgs, 181) + denied:
    if (a["targetSystem"], a["targetComponent"]) != (255, 190): problems.append(f"COMMAND_ACK not addressed to the asker: {a}")

start = lines("start")
sends = [m for m in start if m.get("sent") == "COMMAND_LONG"]
if [m["fields"]["confirmation"] for m in sends] != [0, 1]: problems.append(f"start: sent {sends}, want the start and one retransmission")
results = [a["result"] for a in acks(start, 223)]
if not results or results[0] != 5 or results[-1] != 0 or any(r != 5 for r in results[:-1]):
    problems.append(f"engine start with --confirm engine_start: acks {results}, want IN_PROGRESS (5) ... then ACCEPTED (0)")
executed = [l for l in open(f"{work}/starts")]
if len(executed) != 1 or "-> COMPLETED" not in executed[0] or "(confirmed)" not in executed[0]:
    problems.append(f"the service executed {len(executed)} engine starts: {executed}, want one, confirmed, COMPLETED")
if problems:
    print("FAIL: " + "\n  ".join(problems), file=sys.stderr); sys.exit(1)
print(f"{len(msgs) + len(start)} MAVLink messages checked")
PY
exit $((failures > 0))
