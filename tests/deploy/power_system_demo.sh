#!/usr/bin/env bash
# The demo of scripts/run.sh serves the whole power system: pmu-service on
# deploy/examples/sim-power-system.yaml publishes the PMU, the battery (its cells too) and
# both MPPTs with received values, `pmuctl list` shows every device ONLINE with its kind, and
# the bench session of tools/README.md runs on it as written.
#   power_system_demo.sh PMU-SERVICE PMUCTL SOURCE-DIR
set -uo pipefail
svc=$1 ctl=$2 src=$3
. "$src/tests/support/dds_domain.sh"
pmu_test_dds_domain || exit 1
domain=$PMU_TEST_DDS_DOMAIN
export PMU_QOS_FILE="$src/deploy/qos.xml"
work=$(mktemp -d)
trap 'kill "$pid" 2>/dev/null; wait "$pid" 2>/dev/null; rm -rf "$work"' EXIT
"$svc" --config "$src/deploy/examples/sim-power-system.yaml" --domain "$domain" >"$work/service.log" 2>&1 &
pid=$!
failures=0
fail() { echo "FAIL: $*" >&2; failures=$((failures + 1)); }

# 150 samples: the PMU's five packets every 0.5 s, the battery, its cells and two MPPTs (each
# at most every 0.2 s, canopen_publish_period); every value is sent once per 1 s period.
"$ctl" --domain "$domain" --json --timeout 60 watch --count 150 >"$work/watch" 2>"$work/watch.err" ||
  fail "pmuctl watch: $(tail -n2 "$work/watch.err")"
python3 - "$work/watch" <<'PY' || failures=$((failures + 1))
import json, math, sys
lines = [json.loads(l) for l in open(sys.argv[1]) if l.startswith("{")]
seen = {}
for l in lines:
    key = (l["topic"], l.get("node", l.get("device", l.get("address"))))
    seen[key] = l["values"]  # the newest sample of each device and topic
problems = []
for topic in ("voltages", "currents", "battery_energy", "temperatures", "status"):
    if (topic, 1) not in seen: problems.append(f"no pmu/{topic} from address 1")
bat = seen.get(("battery", 2))
if bat is None: problems.append("no pmu/battery from node 2")
else:
    for k in ("voltage", "current", "state_of_charge", "cell_voltage_high", "cell_voltage_low"):
        v = bat.get(k)
        if not isinstance(v, (int, float)) or math.isnan(v): problems.append(f"pmu/battery {k} is {v!r}, not a received value")
    if isinstance(bat.get("state_of_charge"), (int, float)) and not 0 <= bat["state_of_charge"] <= 100:
        problems.append(f"pmu/battery state_of_charge {bat['state_of_charge']} is not a percentage")
cells = seen.get(("battery_cells", 2))
if not cells or not cells.get("cells"): problems.append("no pmu/battery_cells from node 2 with cells")
for d in (0, 1):
    m = seen.get(("mppt", d))
    if m is None: problems.append(f"no pmu/mppt from device {d}")
    elif not isinstance(m.get("voltage_output_raw"), (int, float)): problems.append(f"pmu/mppt {d} voltage_output_raw is {m.get('voltage_output_raw')!r}")
if problems:
    print("FAIL: " + "; ".join(problems), file=sys.stderr); sys.exit(1)
print(f"{len(lines)} samples: PMU topics, battery (SoC {bat['state_of_charge']} %), {len(cells['cells'])} cells, MPPTs 0 and 1")
PY
"$ctl" --domain "$domain" --json --timeout 20 list >"$work/list" 2>&1
for want in '"kind":"pmu"' '"kind":"battery"' '"kind":"mppt"'; do
  grep "$want" "$work/list" | grep -q '"state":"ONLINE"' || fail "pmuctl list: no ONLINE line with $want: $(tr '\n' ' ' <"$work/list" | cut -c1-400)"
done
[ "$(grep -c '"kind":"mppt"' "$work/list")" -eq 2 ] || fail "pmuctl list: $(grep -c '"kind":"mppt"' "$work/list") MPPT lines, want 2"

# The bench session of tools/README.md, run as written against this demo: every line it shows after a
# `$ pmuctl ...` prompt is printed by that command, in that order ("..." stands for lines
# left out).
python3 - "$src/tools/README.md" "$ctl" "$domain" <<'PY' || failures=$((failures + 1))
import re, subprocess, sys
readme, ctl, domain = sys.argv[1:4]
text = open(readme).read()
section = text.split("### A bench check from the ground station", 1)[1]
block = section.split("```", 2)[1].strip("\n").splitlines()
steps = []
for line in block:
    if line.startswith("$ pmuctl "):
        steps.append((line[len("$ pmuctl "):], []))
    elif steps and line.strip() != "...":
        steps[-1][1].append(line)
problems = []
if len(steps) < 5:
    problems.append(f"only {len(steps)} commands found in the README's bench session")
for args, expected in steps:
    r = subprocess.run(f"{ctl} --domain {domain} --timeout 20 {args}", shell=True, capture_output=True, text=True)
    got = (r.stdout + r.stderr).splitlines()
    at = 0
    for want in expected:
        while at < len(got) and got[at].rstrip() != want.rstrip():
            at += 1
        if at == len(got):
            problems.append(f"`pmuctl {args}` did not print {want!r}; it printed: {got[:12]}")
            break
        at += 1
if problems:
    print("FAIL: README bench session: " + "; ".join(problems), file=sys.stderr); sys.exit(1)
print(f"README bench session: {len(steps)} commands as written")
PY
[ $failures -eq 0 ] || { tail -n 20 "$work/service.log" >&2; exit 1; }
echo "power system demo: PASS"
