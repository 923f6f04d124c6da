#!/usr/bin/env bash
# pmu-mavlink end to end: pmu-service on the demo power system (deploy/examples/
# sim-power-system.yaml: one PMU, a BMS, two MPPTs on the built-in simulated bus),
# pmu-mavlink with --udp to a node-mavlink ground station (ground_station.mjs), the PMU's
# payload output switched off with pmuctl first. Checks the HEARTBEAT, the BATTERY_STATUS of
# the PMU's two inputs (ids 10, 11) and of the BMS (id 20), the GENERATOR_STATUS and the
# RELAY_STATUS (the outputs and generation) against the service's own samples (pmuctl --json
# watch), the sentinels of what the service does not know, and the answers to
# SET_MESSAGE_INTERVAL and RUN_PREARM_CHECKS, the readiness said once as STATUSTEXT; and,
# started without --system-id, that it takes the autopilot's system id from its HEARTBEAT;
# then, with the simulated PMU in SOA shutdown (a critical alarm without delay), the alarm as
# a CRITICAL STATUSTEXT, the reason as a "PreArm:" line, the fault flag and "not ready"; then,
# with a silent PMU (known, never ONLINE), no output present in RELAY_STATUS (docs/safety.md
# H7). `serial`: the first run only, with pmu-mavlink on --serial PTY:57600, a pty pair whose
# master pty_relay.py relays to the ground station. Exit 77 (skipped) without Node.js or
# node-mavlink.
#   end_to_end.sh PMU-SERVICE PMU-MAVLINK PMUCTL SOURCE-DIR [udp|serial]
set -uo pipefail
svc=$1 bridge=$2 ctl=$3 src=$4 link=${5:-udp}
case "$link" in udp | serial) ;; *) echo "link: udp or serial, not '$link'" >&2; exit 2 ;; esac
. "$src/tests/pmu-mavlink/bridge/ground_station_setup.sh"
# pmu-mavlink ARGS... logging to $1, to the ground station whose port is in $work/port: over
# UDP, or (serial) on a pty's slave whose master pty_relay.py relays to that port.
start_bridge() {
  local log=$1
  shift
  if [ "$link" = serial ]; then
    rm -f "$work/pty"
    python3 "$here/pty_relay.py" "$work/pty" "$work/port" 2>"$work/relay.err" &
    pids+=($!)
    for _ in $(seq 100); do [ -s "$work/pty" ] && break; sleep 0.1; done
    [ -s "$work/pty" ] || { echo "FAIL: no pty pair: $(cat "$work/relay.err")" >&2; exit 1; }
    "$bridge" --serial "$(cat "$work/pty"):57600" "$@" >"$log" 2>&1 &
  else
    "$bridge" --udp "127.0.0.1:$(cat "$work/port")" "$@" >"$log" 2>&1 &
  fi
  bridge_pid=$!
  pids+=($bridge_pid)
}

"$svc" --config "$src/deploy/examples/sim-power-system.yaml" --domain "$domain" >"$work/service.log" 2>&1 &
pids+=($!)
# The payload output off, so RELAY_STATUS is checked on a mix of on and off. info and config
# get return once the service has read the PMU, which a command needs.
"$ctl" --domain "$domain" --timeout 60 info >/dev/null 2>"$work/ctl.err" &&
  "$ctl" --domain "$domain" --timeout 60 config get >/dev/null 2>>"$work/ctl.err" &&
  "$ctl" --domain "$domain" --timeout 20 --address 1 outputs disable payload >"$work/ctl.out" 2>>"$work/ctl.err" ||
  fail "pmuctl outputs disable payload: $(tail -n2 "$work/ctl.err") $(tail -n1 "$work/ctl.out" 2>/dev/null)"
# The ground station's script resolves node-mavlink from tests/mavlink's node_modules,
# linked beside its copy in the work folder (nothing is written into the source tree).
ln -s "$src/tests/mavlink/node_modules" "$work/node_modules"
gs="$work/ground_station.mjs"
cp "$here/ground_station.mjs" "$gs"
node "$gs" "$work/port" "$work/gs.jsonl" 2>"$work/gs.err" &
gs_pid=$!
pids+=($gs_pid)
for _ in $(seq 100); do [ -s "$work/port" ] && break; sleep 0.1; done
[ -s "$work/port" ] || { echo "FAIL: the ground station did not bind: $(cat "$work/gs.err")" >&2; exit 1; }
start_bridge "$work/bridge.log" --system-id 1 --domain "$domain"
"$ctl" --domain "$domain" --json --timeout 60 watch --count 80 >"$work/watch" 2>"$work/watch.err" ||
  fail "pmuctl watch: $(tail -n2 "$work/watch.err")"
# The ground station ends once it has every message and both answers; 60 s only turns
# "never" into a FAIL line.
end=$((SECONDS + 60))
while kill -0 "$gs_pid" 2>/dev/null && ((SECONDS < end)); do sleep 0.2; done
if kill -0 "$gs_pid" 2>/dev/null; then
  fail "the ground station did not get every message and answer in 60 s: $(cut -c1-120 "$work/gs.jsonl" | awk -F'"name":' '{print $2}' | cut -d, -f1 | sort | uniq -c | tr '\n' ' ')"
else
  wait "$gs_pid" || fail "ground station: $(cat "$work/gs.err")"
fi
kill -TERM "$bridge_pid"
wait "$bridge_pid"; status=$?
[ $status -eq 0 ] || fail "pmu-mavlink exited $status on SIGTERM: $(tail -n3 "$work/bridge.log")"
grep -q "frames in" "$work/bridge.log" || fail "pmu-mavlink did not report its counters: $(cat "$work/bridge.log")"
# The ground station's noise and bad-CRC frame: counted, and the program went on (it answered
# the commands sent after them, checked below).
grep -Eq "bad CRC [1-9][0-9]*, .*garbage bytes [1-9]" "$work/bridge.log" ||
  fail "the bad input is not counted: $(grep 'frames in' "$work/bridge.log")"

python3 - "$work/gs.jsonl" "$work/watch" "$link" <<'PY' || failures=$((failures + 1))
import json, math, sys
msgs = [json.loads(l) for l in open(sys.argv[1]) if l.strip()]
samples = [json.loads(l) for l in open(sys.argv[2]) if l.startswith("{")]
problems = []
def last(name, **match):
    found = [m for m in msgs if m["name"] == name and all(m["fields"].get(k) == v for k, v in match.items())]
    return found[-1]["fields"] if found else None
def sample(topic, **key):
    found = [s for s in samples if s["topic"] == topic and all(s.get(k) == v for k, v in key.items())]
    return found[-1]["values"] if found else None
def near(what, got, want, tol):
    if want is None or got is None or abs(got - want) > tol:
        problems.append(f"{what}: MAVLink {got}, service {want} (tolerance {tol})")

for m in msgs:
    if (m["sysid"], m["compid"]) != (1, 180): problems.append(f"{m['name']} from {m['sysid']}/{m['compid']}, want 1/180")
hb = last("HEARTBEAT")
if not hb or hb["type"] != 36 or hb["autopilot"] != 8:
    problems.append(f"HEARTBEAT {hb}: want type 36 (BATTERY), autopilot 8 (INVALID)")

v, c, t = sample("voltages", address=1), sample("currents", address=1), sample("temperatures", address=1)
for bid, inp in ((10, "battery_a"), (11, "battery_b")):
    b = last("BATTERY_STATUS", id=bid)
    if not b or not v or not c:
        problems.append(f"BATTERY_STATUS {bid} or the service's samples missing"); continue
    near(f"BATTERY_STATUS {bid} voltages[0] (mV)", b["voltages"][0], v[inp] * 1000, 500)
    near(f"BATTERY_STATUS {bid} current_battery (cA, discharge positive)", b["currentBattery"], -c[inp] * 100, 50)
    if any(x != 65535 for x in b["voltages"][1:]): problems.append(f"BATTERY_STATUS {bid}: cells 1..9 not 65535")
    if b["batteryRemaining"] != -1: problems.append(f"BATTERY_STATUS {bid}: battery_remaining {b['batteryRemaining']}, the PMU knows none: want -1")
    tv = t.get(inp) if t else None
    if tv is None: 
        if b["temperature"] != 32767: problems.append(f"BATTERY_STATUS {bid}: temperature {b['temperature']} without a sensor, want 32767")
    else: near(f"BATTERY_STATUS {bid} temperature (cdegC)", b["temperature"], tv * 100, 200)

bat = sample("battery", node=2)
b = last("BATTERY_STATUS", id=20)
if not b or not bat: problems.append("BATTERY_STATUS 20 (BMS node 2) or pmu/battery missing")
else:
    near("BATTERY_STATUS 20 battery_remaining (%)", b["batteryRemaining"], bat["state_of_charge"], 2)
    near("BATTERY_STATUS 20 current_battery (cA)", b["currentBattery"], -bat["current"] * 100, 100)
    if b["voltages"][0] == 65535: problems.append("BATTERY_STATUS 20: no cell voltage")

g, s = last("GENERATOR_STATUS"), sample("status", address=1)
if not g or not s or not v: problems.append("GENERATOR_STATUS or pmu/status missing")
else:
    near("GENERATOR_STATUS bus_voltage (V)", g["busVoltage"], v["generator"], 0.5)
    rpm = s.get("generator_rpm")
    if rpm is None:
        if g["generatorSpeed"] != 65535: problems.append(f"GENERATOR_STATUS speed {g['generatorSpeed']} without a reading, want 65535")
    else: near("GENERATOR_STATUS generator_speed (rpm)", g["generatorSpeed"], rpm, 300)
    if g["runtime"] != 4294967295 or g["rectifierTemperature"] != 32767 or g["timeUntilMaintenance"] != 2147483647:
        problems.append(f"GENERATOR_STATUS: unknown fields not their sentinels: {g}")
    want_flag = 1 if not s["generation_enabled"] else (2 | 4)
    if not int(g["status"]) & want_flag: problems.append(f"GENERATOR_STATUS status {g['status']}, generation_enabled {s['generation_enabled']}")

acks = {m["fields"]["command"]: m["fields"] for m in msgs if m["name"] == "COMMAND_ACK"}
if acks.get(511, {}).get("result") != 0: problems.append(f"SET_MESSAGE_INTERVAL: {acks.get(511)}, want ACCEPTED")
if acks.get(401, {}).get("result") != 0: problems.append(f"RUN_PREARM_CHECKS: {acks.get(401)}, want ACCEPTED")
for a in acks.values():
    if (a["targetSystem"], a["targetComponent"]) != (255, 190): problems.append(f"COMMAND_ACK not addressed to the asker: {a}")
said = [m["fields"]["text"] for m in msgs if m["name"] == "STATUSTEXT" and m["fields"]["text"].startswith("PMU: ") and "ready" in m["fields"]["text"] and "pre-arm" not in m["fields"]["text"]]
# Each change once: the service may say not ready while its devices come online, then ready.
if not said or said[-1] != "PMU: ready" or any(a == b for a, b in zip(said, said[1:])):
    problems.append(f"readiness said as {said}: want each change once, ending 'PMU: ready'")
if hb and hb["systemStatus"] not in (3, 4): problems.append(f"HEARTBEAT system_status {hb['systemStatus']} with the service's readiness heard, want STANDBY or ACTIVE")

# RELAY_STATUS: PMU 0's bits 0..4 are DO_SET_RELAY's instances 0..4, all present or none.
relays = [m["fields"] for m in msgs if m["name"] == "RELAY_STATUS"]
known = [r for r in relays if r["present"]]
if not known: problems.append("no RELAY_STATUS with the PMU's outputs present")
elif s:
    names = ("avionics_servo_on", "payload_on", "charger_a_on", "charger_b_on", "generation_enabled")
    want = sum(1 << i for i, n in enumerate(names) if s[n])
    r = known[-1]
    if (r["on"], r["present"]) != (want, 0x1F):
        problems.append(f"RELAY_STATUS on {r['on']:#06x} present {r['present']:#06x}; pmu/status {[n for n in names if s[n]]}: want on {want:#06x} present 0x001f")
    if s["payload_on"]: problems.append("pmu/status payload_on: pmuctl outputs disable payload did not take")
for r in relays:
    if r["present"] not in (0, 0x1F) or r["on"] & ~r["present"]:
        problems.append(f"RELAY_STATUS on {r['on']:#06x} present {r['present']:#06x}: one PMU's five bits, on only where present")
if [r["timeBootMs"] for r in relays] != sorted(r["timeBootMs"] for r in relays): problems.append("RELAY_STATUS time_boot_ms goes back")
if problems:
    print("FAIL: " + "\n  ".join(problems), file=sys.stderr); sys.exit(1)
print(f"{len(msgs)} MAVLink messages over {sys.argv[3]} checked against {len(samples)} service samples")
PY
# Serial: the program's serial endpoint carried all of the above; the runs below are not
# about the link.
[ "$link" = serial ] && exit $((failures > 0))
# Without --system-id: the autopilot's (system 7, from its HEARTBEAT) once heard.
: >"$work/port"
node "$gs" "$work/port" "$work/learn.jsonl" learn 2>"$work/learn.err" &
gs_pid=$!
pids+=($gs_pid)
for _ in $(seq 100); do [ -s "$work/port" ] && break; sleep 0.1; done
start_bridge "$work/learn.log" --domain "$domain"
end=$((SECONDS + 30))
while kill -0 "$gs_pid" 2>/dev/null && ((SECONDS < end)); do sleep 0.2; done
if kill -0 "$gs_pid" 2>/dev/null; then
  fail "no frame from system 7 after the autopilot's HEARTBEAT: $(cut -c1-100 "$work/learn.jsonl" | tail -n3)"
else
  wait "$gs_pid" || fail "learn: $(cat "$work/learn.err")"
  head -n1 "$work/learn.jsonl" | grep -q '"sysid":1,' || fail "before the autopilot is heard: $(head -n1 "$work/learn.jsonl" | cut -c1-100), want system 1"
fi

# An active critical alarm: the service restarted with the PMU in SOA shutdown.
for p in "${pids[@]}"; do kill "$p" 2>/dev/null; done
wait 2>/dev/null
pids=()
sed 's/^      - address: 1$/      - address: 1\n        sim: {soa_shutdown: true}/' "$src/deploy/examples/sim-power-system.yaml" >"$work/soa.yaml"
grep -q soa_shutdown "$work/soa.yaml" || fail "the demo config's PMU line moved: cannot add its sim: setting"
"$svc" --config "$work/soa.yaml" --domain "$domain" >"$work/service2.log" 2>&1 &
pids+=($!)
: >"$work/port"
node "$gs" "$work/port" "$work/soa.jsonl" 2>"$work/soa.err" &
gs_pid=$!
pids+=($gs_pid)
for _ in $(seq 100); do [ -s "$work/port" ] && break; sleep 0.1; done
start_bridge "$work/soa.log" --system-id 1 --domain "$domain"
end=$((SECONDS + 60))
while kill -0 "$gs_pid" 2>/dev/null && ((SECONDS < end)); do sleep 0.2; done
if kill -0 "$gs_pid" 2>/dev/null; then
  fail "SOA shutdown: the ground station did not get every message and answer in 60 s"
else
  wait "$gs_pid" || fail "SOA shutdown ground station: $(cat "$work/soa.err")"
fi
python3 - "$work/soa.jsonl" <<'PY' || failures=$((failures + 1))
import json, sys
msgs = [json.loads(l) for l in open(sys.argv[1]) if l.strip()]
texts = [(m["fields"]["severity"], m["fields"]["text"]) for m in msgs if m["name"] == "STATUSTEXT"]
problems = []
alarm = [t for s, t in texts if s == 2 and t.startswith("PMU: ") and "soa" in t.lower()]
if len(alarm) != 1: problems.append(f"the SOA alarm said {len(alarm)} times as CRITICAL 'PMU: ...', want once: {texts}")
if not any(s == 2 and t.startswith("PreArm: ") and "soa" in t.lower() for s, t in texts): problems.append(f"no CRITICAL 'PreArm:' line for the SOA shutdown: {texts}")
if not any(s == 4 and t.startswith("PMU: not ready") for s, t in texts): problems.append(f"'PMU: not ready' not said as WARNING: {texts}")
gens = [m["fields"] for m in msgs if m["name"] == "GENERATOR_STATUS"]
if not gens or not int(gens[-1]["status"]) & 32768: problems.append(f"GENERATOR_STATUS without OVERCURRENT_FAULT: {gens[-1:] }")
hbs = [m["fields"] for m in msgs if m["name"] == "HEARTBEAT"]
if not hbs or hbs[-1]["systemStatus"] != 3: problems.append(f"HEARTBEAT system_status {hbs[-1:]} while not ready, want STANDBY (3)")
if problems:
    print("FAIL (SOA shutdown): " + "\n  ".join(problems), file=sys.stderr); sys.exit(1)
PY

# A silent PMU: pmu-mavlink knows it (its pmu/health, never ONLINE) but not its outputs.
for p in "${pids[@]}"; do kill "$p" 2>/dev/null; done
wait 2>/dev/null
pids=()
printf 'buses:\n  - interface: sim\n    name: sim0\n    devices:\n      - address: 1\n        period: 0.5\n        sim: {silent: true}\n' >"$work/silent.yaml"
"$svc" --config "$work/silent.yaml" --domain "$domain" >"$work/service3.log" 2>&1 &
pids+=($!)
: >"$work/port"
node "$gs" "$work/port" "$work/silent.jsonl" unknown 2>"$work/silent.err" &
gs_pid=$!
pids+=($gs_pid)
for _ in $(seq 100); do [ -s "$work/port" ] && break; sleep 0.1; done
start_bridge "$work/silent.log" --system-id 1 --domain "$domain"
end=$((SECONDS + 60))
while kill -0 "$gs_pid" 2>/dev/null && ((SECONDS < end)); do sleep 0.2; done
if kill -0 "$gs_pid" 2>/dev/null; then
  fail "silent PMU: no RELAY_STATUS after a GENERATOR_STATUS saying COMMUNICATION_WARNING in 60 s"
else
  wait "$gs_pid" || fail "silent PMU ground station: $(cat "$work/silent.err")"
fi
python3 - "$work/silent.jsonl" <<'PY' || failures=$((failures + 1))
import json, sys
relays = [json.loads(l)["fields"] for l in open(sys.argv[1]) if '"RELAY_STATUS"' in l]
bad = [r for r in relays if r["present"] or r["on"]]
if not relays or bad:
    print(f"FAIL (silent PMU): RELAY_STATUS {bad or relays}: want nothing present or on while the PMU is not ONLINE", file=sys.stderr); sys.exit(1)
PY
exit $((failures > 0))
