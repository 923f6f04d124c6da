#!/bin/bash
# tools_alone.sh DEB_DIR PMU_SERVICE QOS_XML
#
# pmu-dds-tools without the daemon package, as a ground station installs it: pmuctl from
# DEB_DIR's pmu-dds-tools_*_<this arch>.deb sees only that package's /usr/share/pmu-dds
# (bind-mounted in a private mount namespace over an empty /usr/share, with /etc/pmu-dds
# hidden), no PMU_QOS_FILE, and must
#   1. refuse to start, naming both places it looked, when /usr/share/pmu-dds is empty
#      (the control: the check below can only pass through the package's copy);
#   2. find the package's qos.xml and list the PMU of PMU_SERVICE (a build-tree service on
#      the simulated bus, given QOS_XML) on a random DDS domain.
# Needs root for the mount namespace (CI runs as root); exits 77 (skipped) otherwise.
set -euo pipefail

if [ $# -ne 3 ]; then
  echo "usage: $0 DEB_DIR PMU_SERVICE QOS_XML" >&2
  exit 2
fi
deb_dir=$1 service=$2 qos=$3
arch=$(dpkg --print-architecture)

fail() { echo "FAIL: $*" >&2; exit 1; }
step() { echo "--- $*"; }

if [ "$(id -u)" -ne 0 ]; then
  echo "SKIP: needs root for a private mount namespace (unshare -m)"
  exit 77
fi
shopt -s nullglob
debs=("$deb_dir"/pmu-dds-tools_*_"$arch".deb)
[ ${#debs[@]} -eq 1 ] ||
  fail "expected one pmu-dds-tools_*_$arch.deb in '$deb_dir', found ${#debs[@]}: build it with scripts/package.sh"
[ -x "$service" ] || fail "pmu-service '$service' is not an executable"

work=$(mktemp -d)
service_pid=
cleanup() {
  if [ -n "$service_pid" ]; then kill -TERM "$service_pid" 2>/dev/null || true; wait "$service_pid" 2>/dev/null || true; fi
  rm -rf "$work"
}
trap cleanup EXIT

dpkg-deb -x "${debs[0]}" "$work/root"
[ -f "$work/root/usr/share/pmu-dds/qos.xml" ] || fail "the tools package has no usr/share/pmu-dds/qos.xml"
pmuctl="$work/root/usr/bin/pmuctl"
[ -x "$pmuctl" ] || fail "the tools package has no executable usr/bin/pmuctl"

domain=$((RANDOM % 200 + 20))
PMU_QOS_FILE="$qos" "$service" --bus sim --domain "$domain" >"$work/service.log" 2>&1 &
service_pid=$!

# in_namespace SHARE_DIR CMD...: runs CMD with SHARE_DIR as /usr/share/pmu-dds and nothing
# else under /usr/share, and an empty /etc/pmu-dds.
in_namespace() {
  local share=$1; shift
  unshare -m --propagation private /bin/sh -c '
    set -e
    share=$1; shift
    mount -t tmpfs pmu-share /usr/share
    mkdir /usr/share/pmu-dds
    mount --bind "$share" /usr/share/pmu-dds
    if [ -d /etc/pmu-dds ]; then mount -t tmpfs pmu-etc /etc/pmu-dds; fi
    exec env -u PMU_QOS_FILE "$@"' sh "$share" "$@"
}

step "1. control: no qos.xml under /usr/share/pmu-dds"
mkdir "$work/empty"
status=0
out=$(in_namespace "$work/empty" "$pmuctl" --domain "$domain" list 2>&1) || status=$?
echo "$out"
[ "$status" -ne 0 ] || fail "pmuctl listed PMUs without any QoS file: the check below would prove nothing"
grep -q "/usr/share/pmu-dds/qos.xml" <<<"$out" || fail "pmuctl's error does not name /usr/share/pmu-dds/qos.xml"

step "2. the tools package's /usr/share/pmu-dds"
out=$(in_namespace "$work/root/usr/share/pmu-dds" "$pmuctl" --domain "$domain" --json --timeout 30 list 2>&1) ||
  { cat "$work/service.log" >&2; fail "pmuctl from the tools package alone failed: $out"; }
echo "$out"
python3 - "$out" <<'PY' || fail "pmuctl list did not report the simulated PMU at address 1 ONLINE"
import json, sys
rows = [json.loads(l) for l in sys.argv[1].splitlines() if l.startswith("{")]
assert any(r.get("address") == 1 and r.get("values", {}).get("state") == "ONLINE" for r in rows), rows
PY
echo "PASS: pmuctl from pmu-dds-tools alone used /usr/share/pmu-dds/qos.xml and listed the PMU"
