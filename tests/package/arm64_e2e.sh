#!/bin/bash
# arm64_e2e.sh DEB_DIR PMUCTL QOS_XML
#
# The arm64 package end to end: pmu-service from DEB_DIR's pmu-dds_*_arm64.deb (extracted
# with dpkg-deb -x, not installed) runs under qemu-user on the built-in simulated bus with
# its packaged configuration (dds_transport: udp, so the traffic crosses UDP, not shared
# memory) on a random DDS domain; PMUCTL, a binary of this machine's architecture, then
#   1. reads telemetry: `watch --json --count 5` gives 5 samples from the simulated PMU;
#   2. sends a command: `config set avionics_voltage` to a value other than the current one
#      is COMPLETED with that value read back by the service, and `config get` agrees;
#   3. the service stops on SIGTERM with exit status 0.
# Missing debs are a failure, not a skip: CI builds them first (scripts/test.sh).
# One concession to the emulator: bookworm's qemu-user cannot pass IP_MULTICAST_IF to the
# kernel, without which Fast DDS opens no UDP output at all, so the service runs with
# qemu_multicast_if.c preloaded (cross-compiled here; that file says what it changes).
set -euo pipefail

if [ $# -ne 3 ]; then
  echo "usage: $0 DEB_DIR PMUCTL QOS_XML" >&2
  exit 2
fi
deb_dir=$1 pmuctl=$2 qos=$3

fail() { echo "FAIL: $*" >&2; exit 1; }
step() { echo "--- $*"; }

shopt -s nullglob
debs=("$deb_dir"/pmu-dds_*_arm64.deb)
[ ${#debs[@]} -eq 1 ] ||
  fail "expected one pmu-dds_*_arm64.deb in '$deb_dir', found ${#debs[@]}: build it with scripts/package.sh --arch arm64"
emulator=$(command -v qemu-aarch64-static) || fail "qemu-aarch64-static not found (scripts/setup.sh installs qemu-user-static)"
[ -x "$pmuctl" ] || fail "pmuctl '$pmuctl' is not an executable"
[ -f "$qos" ] || fail "QoS file '$qos' does not exist"
cross_cc=$(command -v aarch64-linux-gnu-gcc) ||
  fail "aarch64-linux-gnu-gcc not found (scripts/setup.sh installs crossbuild-essential-arm64)"

work=$(mktemp -d)
service_pid=
cleanup() {
  if [ -n "$service_pid" ] && kill -0 "$service_pid" 2>/dev/null; then kill -KILL "$service_pid" 2>/dev/null || true; fi
  rm -rf "$work"
}
trap cleanup EXIT

step "extract ${debs[0]}"
dpkg-deb -x "${debs[0]}" "$work/root"
service="$work/root/usr/bin/pmu-service"
[ -x "$service" ] || fail "the deb has no executable usr/bin/pmu-service"
machine=$(readelf -h "$service" | sed -n 's/^ *Machine: *//p')
[ "$machine" = "AArch64" ] || fail "usr/bin/pmu-service in the arm64 deb is built for '$machine', not AArch64"
config="$work/root/etc/pmu-dds/pmu-service.yaml"
grep -q '^dds_transport: udp$' "$config" || fail "the packaged $config does not set dds_transport: udp"

shim="$work/qemu_multicast_if.so"
"$cross_cc" -shared -fPIC -O2 -Wall -Wextra -Werror -o "$shim" "$(dirname "$0")/qemu_multicast_if.c" ||
  fail "cannot cross-compile tests/package/qemu_multicast_if.c"

domain=$((RANDOM % 200 + 20))
step "arm64 pmu-service under $emulator, simulated bus, DDS domain $domain"
log="$work/service.log"
# The packaged config and QoS profiles; --bus sim replaces the config's CAN buses.
# QEMU_SET_ENV: the preload is for the emulated program, not for qemu itself.
PMU_QOS_FILE="$work/root/etc/pmu-dds/qos.xml" QEMU_LD_PREFIX=/ QEMU_SET_ENV="LD_PRELOAD=$shim" \
  "$emulator" "$service" --config "$config" --bus sim --domain "$domain" >"$log" 2>&1 &
service_pid=$!

ctl() { PMU_QOS_FILE="$qos" "$pmuctl" --domain "$domain" --json "$@"; }
# A field of a JSON line, by a dotted path: jv LINE values.avionics_voltage
jv() {
  python3 -c '
import json, sys
v = json.loads(sys.argv[1]) if sys.argv[1] else {}
for k in sys.argv[2].split("."):
    v = v.get(k) if isinstance(v, dict) else None
print("" if v is None else v)' "$1" "$2"
}

step "1. telemetry: pmuctl watch --count 5"
watch_out=$(ctl --timeout 120 watch --count 5 2>"$work/watch.err") || {
  cat "$log" >&2; cat "$work/watch.err" >&2
  fail "pmuctl watch found no telemetry from the arm64 pmu-service within 120 s (service log above)"; }
echo "$watch_out"
kill -0 "$service_pid" 2>/dev/null || { cat "$log" >&2; fail "the arm64 pmu-service exited (log above)"; }
python3 - "$watch_out" <<'PY' || fail "the telemetry lines are not 5 samples of the simulated PMU at address 1"
import json, sys
lines = [json.loads(l) for l in sys.argv[1].splitlines() if l.strip()]
assert len(lines) == 5, f"{len(lines)} lines, want 5"
for l in lines:
    assert l.get("address") == 1, f"address {l.get('address')!r} in {l}"
    assert l.get("topic") in ("voltages", "currents", "battery_energy", "temperatures", "status"), \
        f"not a telemetry topic: {l}"
    assert l.get("values"), f"no values in {l}"
PY

step "2. command: config set avionics_voltage, read back"
before=$(jv "$(ctl --timeout 60 config get avionics_voltage 2>/dev/null | head -n1)" values.avionics_voltage)
[ -n "$before" ] || fail "pmuctl config get avionics_voltage gave no value"
want=12.5
python3 -c 'import sys; sys.exit(abs(float(sys.argv[1]) - 12.5) < 1e-6)' "$before" || want=13.0
reply=$(ctl --timeout 60 config set avionics_voltage "$want" 2>"$work/set.err") ||
  { cat "$work/set.err" >&2; fail "config set avionics_voltage $want failed (was $before): ${reply:-no reply}"; }
echo "$reply"
[ "$(jv "$reply" result)" = "COMPLETED" ] || fail "config set avionics_voltage $want: result '$(jv "$reply" result)', want COMPLETED"
python3 -c 'import sys; assert abs(float(sys.argv[1]) - float(sys.argv[2])) < 1e-6' "$(jv "$reply" value)" "$want" ||
  fail "config set avionics_voltage $want read back '$(jv "$reply" value)'"
after=$(jv "$(ctl --timeout 30 config get avionics_voltage 2>/dev/null | head -n1)" values.avionics_voltage)
python3 -c 'import sys; assert abs(float(sys.argv[1]) - float(sys.argv[2])) < 1e-6' "$after" "$want" ||
  fail "pmu/config avionics_voltage is '$after' after the set, want $want (was $before)"

step "3. SIGTERM stops the arm64 pmu-service"
kill -TERM "$service_pid"
for _ in $(seq 100); do kill -0 "$service_pid" 2>/dev/null || break; sleep 0.1; done
kill -0 "$service_pid" 2>/dev/null && fail "the arm64 pmu-service still runs 10 s after SIGTERM"
status=0; wait "$service_pid" || status=$?
service_pid=
[ "$status" -eq 0 ] || { cat "$log" >&2; fail "the arm64 pmu-service exited with status $status after SIGTERM (log above)"; }
echo "PASS: arm64 pmu-service (qemu-user) served telemetry and a COMPLETED command to $(basename "$pmuctl") over UDP"
