#!/bin/bash
# deploy_test.sh PMU_SERVICE REPO_ROOT
#
# Checks the shipped deployment files:
#   1. pmu-service --check-config accepts deploy/pmu-service.yaml, also with its commented
#      examples (polling device, discovery, simulated bus, qos_file, dds_statistics,
#      dds_type_objects,
#      batteries, MPPTs, alarm settings)
#      switched on, and
#      rejects a misspelt key (so the check really checks);
#   2. deploy/install.sh --dry-run changes nothing; a DESTDIR install puts every file in
#      place with the right modes, the installed binary accepts the installed config, a
#      second run changes nothing and an edited config is kept;
#   3. systemd-analyze verify accepts the unit (ExecStart= pointed at PMU_SERVICE, since
#      /usr/bin/pmu-service is not installed here) and its offline security exposure is
#      at most 1.5 (measured 1.3 with systemd 252), when systemd-analyze exists; the same
#      for pmu-discovery-server.service (measured 1.1), whose ExecStart= uses exactly the
#      variables discovery-server.env sets, and whose program takes those arguments and
#      discovery-server.xml (a SERVER on the command line's address and port); and
#      systemd-analyze --user verify accepts pmuctl-agent@.service for a domain.
# Exits non-zero on the first failure.

set -euo pipefail

if [ $# -ne 2 ]; then
  echo "usage: $0 PMU_SERVICE REPO_ROOT" >&2
  exit 2
fi
service_bin=$(cd "$(dirname "$1")" && pwd)/$(basename "$1")
repo=$(cd "$2" && pwd)
build_dir=$(cd "$(dirname "$service_bin")/.." && pwd)  # BUILD/service/pmu-service
deploy="$repo/deploy"
install_sh="$deploy/install.sh"

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

step() { echo "--- $*"; }
fail() { echo "FAIL: $*" >&2; exit 1; }

[ -x "$service_bin" ] || fail "$service_bin is not an executable"
for f in pmu-service.yaml qos.xml install.sh README.md systemd/pmu-service.service systemd/80-can0.network \
         systemd/pmu-discovery-server.service discovery-server.env discovery-server.xml; do
  [ -f "$deploy/$f" ] || fail "deploy/$f is missing"
done
[ -x "$install_sh" ] || fail "deploy/install.sh is not executable"

# ---- 1. the example configuration ------------------------------------------------------
step "check-config deploy/pmu-service.yaml"
out=$("$service_bin" --config "$deploy/pmu-service.yaml" --check-config 2>&1) ||
  fail "pmu-service rejected deploy/pmu-service.yaml: $out"
echo "$out"
grep -q "configuration OK (1 bus(es))" <<<"$out" || fail "unexpected check-config output: $out"
# The unit's transient user can share shared memory with no one: the shipped config must
# keep DDS on UDP (deploy/README.md, "Fast DDS shared memory is off").
grep -q "^dds_transport: udp$" "$deploy/pmu-service.yaml" ||
  fail "deploy/pmu-service.yaml must set dds_transport: udp for the DynamicUser unit"

step "check-config with the commented examples switched on"
full="$work/full.yaml"
sed -e "s|^# qos_file: .*|qos_file: $deploy/qos.xml|" \
    -e 's/^# dds_statistics:/dds_statistics:/' \
    -e 's/^# dds_type_objects:/dds_type_objects:/' \
    -e '/^# ros2:$/,/^#   namespace:/ s/^# //' \
    -e '/^ *discover: false$/d' \
    -e '/^ *# discover:$/,/^ *#   packets:/ s/# //' \
    -e '/^ *# - address: 2$/,/^ *#   packets:/ s/# //' \
    -e '/^ *# - interface: sim$/,/^ *#         panels: 2$/ s/# //' \
    "$deploy/pmu-service.yaml" > "$full"
changed_lines=$(diff "$deploy/pmu-service.yaml" "$full" | grep -c '^>' || true)
# qos_file (1) + dds_statistics (1) + dds_type_objects (1) + ros2 (3) + discover mapping (4) + polling device (4)
# + sim bus with its devices' sim: mappings (50)
[ "$changed_lines" -eq 64 ] ||
  fail "expected 64 example lines to switch on, got $changed_lines (were the commented examples changed?)"
out=$("$service_bin" --config "$full" --check-config 2>&1) ||
  fail "pmu-service rejected the example with its commented parts enabled: $out"
echo "$out"
grep -q "configuration OK (2 bus(es))" <<<"$out" || fail "unexpected check-config output: $out"

step "check-config with the battery and MPPT examples switched on"
canopen="$work/canopen.yaml"
sed -e 's/^# canopen_publish_period:/canopen_publish_period:/' \
    -e '/^ *# batteries:$/,/^ *#     period: 1.0$/ s/# //' \
    -e '/^ *# mppts:$/,/^ *#     period: 1.0$/ s/# //' \
    -e 's/^\( *\)# listen_canopen: false$/\1listen_canopen: true/' \
    "$deploy/pmu-service.yaml" > "$canopen"
# canopen_publish_period (1) + batteries (8 lines, 5 of them comments) + mppts (6, 3 of
# them comments) + listen_canopen (1)
changed_lines=$(diff "$deploy/pmu-service.yaml" "$canopen" | grep -c '^>' || true)
[ "$changed_lines" -eq 16 ] ||
  fail "expected 16 battery/MPPT example lines to switch on, got $changed_lines (were the commented examples changed?)"
grep -q "^    batteries:$" "$canopen" && grep -q "^      - node: 2$" "$canopen" && grep -q "^      - device: 0$" "$canopen" ||
  fail "the battery/MPPT examples did not switch on as keys of the bus"
out=$("$service_bin" --config "$canopen" --check-config 2>&1) ||
  fail "pmu-service rejected the battery and MPPT examples: $out"
echo "$out"
grep -q "configuration OK (1 bus(es))" <<<"$out" || fail "unexpected check-config output: $out"

step "check-config with the alarm settings examples switched on"
# On top of the battery and MPPT examples: a device's, the battery's, the MPPT's and the
# bus's alarms.
with_alarms="$work/alarms.yaml"
sed -e '/^        # alarms:$/,/^        #   payload_shed:/ s/# //' \
    -e '/^    #     alarms:$/,/^    #       [a-z_]*: {.*}$/ s/# //' \
    -e '/^    # alarms:$/,/^    #   bus_error_passive:/ s/# //' \
    "$canopen" > "$with_alarms"
# device (5) + battery (2) + MPPT (2) + bus (2)
changed_lines=$(diff "$canopen" "$with_alarms" | grep -c '^>' || true)
[ "$changed_lines" -eq 11 ] ||
  fail "expected 11 alarm example lines to switch on, got $changed_lines (were the commented examples changed?)"
out=$("$service_bin" --config "$with_alarms" --check-config 2>&1) ||
  fail "pmu-service rejected the alarm settings examples: $out"
echo "$out"
grep -q "configuration OK (1 bus(es))" <<<"$out" || fail "unexpected check-config output: $out"

step "check-config with the discovery and interfaces examples switched on"
# The unicast example (its host name swapped for one that resolves everywhere) with the
# interface example on lo, then the server example.
unicast="$work/unicast.yaml"
awk '/^# discovery:$/ { n++ } { if (n == 1 && /^# (discovery:|  mode:|  peers:)/) sub(/^# /, ""); print }' \
    "$deploy/pmu-service.yaml" | sed -e 's/gcs\.local\]$/localhost]/' -e 's/^# interfaces: \[eth1\]$/interfaces: [lo]/' > "$unicast"
[ "$(diff "$deploy/pmu-service.yaml" "$unicast" | grep -c '^>' || true)" -eq 4 ] ||
  fail "expected 4 discovery/interfaces example lines to switch on (were the commented examples changed?)"
out=$("$service_bin" --config "$unicast" --check-config 2>&1) || fail "pmu-service rejected the unicast example: $out"
echo "$out"
grep -q "DDS unicast discovery to 192.168.10.2, 192.168.10.7:7412, 127.0.0.1; DDS over UDP only on 127.0.0.1 (lo)$" \
  <<<"$out" || fail "unexpected check-config output for the unicast example: $out"
server="$work/server.yaml"
awk '/^# discovery:$/ { n++ } { if (n == 2 && /^# (discovery:|  mode:|  servers:)/) sub(/^# /, ""); print }' \
    "$deploy/pmu-service.yaml" > "$server"
out=$("$service_bin" --config "$server" --check-config 2>&1) || fail "pmu-service rejected the server example: $out"
echo "$out"
grep -q "DDS server discovery through Discovery Server id 0 at 192.168.10.1:11811$" <<<"$out" ||
  fail "unexpected check-config output for the server example: $out"

step "check-config rejects a misspelt key"
bad="$work/bad.yaml"
sed 's/^log_level: info$/log_levle: info/' "$deploy/pmu-service.yaml" > "$bad"
cmp -s "$bad" "$deploy/pmu-service.yaml" && fail "could not make the misspelt copy (no 'log_level: info' line)"
set +e
out=$("$service_bin" --config "$bad" --check-config 2>&1)
rc=$?
set -e
[ "$rc" -eq 2 ] || fail "a misspelt key gave exit status $rc, expected 2: $out"
grep -q "unknown key 'log_levle'" <<<"$out" || fail "unexpected message for a misspelt key: $out"
echo "rejected as expected: $out"

# ---- 2. install.sh ---------------------------------------------------------------------
step "install.sh --dry-run"
empty="$work/dry"
mkdir "$empty"
out=$("$install_sh" --dry-run --build-dir "$build_dir" 2>&1) || fail "install.sh --dry-run failed: $out"
echo "$out"
grep -q "would install .* -> /usr/bin/pmu-service" <<<"$out" || fail "dry run does not mention /usr/bin/pmu-service"
grep -q "dry run: nothing was changed" <<<"$out" || fail "dry run did not say it changed nothing"
out=$(DESTDIR="$empty" "$install_sh" --dry-run --build-dir "$build_dir" 2>&1) || fail "install.sh --dry-run with DESTDIR failed: $out"
[ -z "$(ls -A "$empty")" ] || fail "install.sh --dry-run wrote into DESTDIR: $(find "$empty")"

step "install.sh into a DESTDIR"
dest=$(mktemp -d "$work/destdir.XXXXXX")
DESTDIR="$dest" "$install_sh" --build-dir "$build_dir" || fail "install.sh into DESTDIR failed"
expect() {  # MODE PATH
  local mode=$1 path=$2
  [ -f "$dest$path" ] || fail "install.sh did not install $path"
  local got
  got=$(stat -c %a "$dest$path")
  [ "$got" = "$mode" ] || fail "$path has mode $got, expected $mode"
}
expect 755 /usr/bin/pmu-service
expect 644 /etc/pmu-dds/qos.xml
expect 644 /etc/pmu-dds/pmu-service.yaml
expect 644 /etc/pmu-dds/pmu-service.yaml.example
expect 644 /usr/lib/systemd/system/pmu-service.service
expect 644 /usr/lib/systemd/system/pmu-discovery-server.service
expect 644 /etc/pmu-dds/discovery-server.env
expect 644 /etc/pmu-dds/discovery-server.env.example
cmp -s "$deploy/discovery-server.env" "$dest/etc/pmu-dds/discovery-server.env" ||
  fail "installed discovery-server.env differs from deploy/discovery-server.env"
expect 644 /etc/pmu-dds/discovery-server.xml
expect 644 /etc/pmu-dds/discovery-server.xml.example
cmp -s "$deploy/discovery-server.xml" "$dest/etc/pmu-dds/discovery-server.xml" ||
  fail "installed discovery-server.xml differs from deploy/discovery-server.xml"
grep -qx "ExecStart=/usr/bin/fast-discovery-server -i \${PMU_DISCOVERY_SERVER_ID} -l \${PMU_DISCOVERY_SERVER_ADDRESS} -p \${PMU_DISCOVERY_SERVER_PORT} -x /etc/pmu-dds/discovery-server.xml" \
  "$dest/usr/lib/systemd/system/pmu-discovery-server.service" || fail "installed discovery server unit has an unexpected ExecStart="
expect 644 /etc/systemd/network/80-can0.network
expect 644 /usr/share/doc/pmu-dds/README.md
expect 644 /usr/share/doc/pmu-dds/security.md
expect 755 /usr/share/pmu-dds/make_pki.sh
cmp -s "$deploy/security/make_pki.sh" "$dest/usr/share/pmu-dds/make_pki.sh" || fail "installed make_pki.sh differs from deploy/security/make_pki.sh"
if [ -f "$build_dir/tools/pmuctl" ]; then
  expect 755 /usr/bin/pmuctl
  expect 644 /usr/lib/systemd/user/pmuctl-agent@.service
  grep -qx "ExecStart=/usr/bin/pmuctl --domain %i agent" "$dest/usr/lib/systemd/user/pmuctl-agent@.service" ||
    fail "installed pmuctl agent user unit has an unexpected ExecStart="
fi
[ -f "$build_dir/tools/pmu-sim" ] && expect 755 /usr/bin/pmu-sim
cmp -s "$deploy/qos.xml" "$dest/etc/pmu-dds/qos.xml" || fail "installed qos.xml differs from deploy/qos.xml"
cmp -s "$deploy/pmu-service.yaml" "$dest/etc/pmu-dds/pmu-service.yaml" || fail "installed config differs from the example"
grep -qx "ExecStart=/usr/bin/pmu-service --config /etc/pmu-dds/pmu-service.yaml" \
  "$dest/usr/lib/systemd/system/pmu-service.service" || fail "installed unit has an unexpected ExecStart="
"$dest/usr/bin/pmu-service" --config "$dest/etc/pmu-dds/pmu-service.yaml" --check-config ||
  fail "the installed pmu-service rejects the installed config"

step "install.sh again: nothing to do, an edited config is kept"
out=$(DESTDIR="$dest" "$install_sh" --build-dir "$build_dir" 2>&1) || fail "second install.sh run failed: $out"
grep -q "nothing to do" <<<"$out" || fail "second run changed something: $out"
echo "# edited on site" >> "$dest/etc/pmu-dds/pmu-service.yaml"
echo "PMU_DISCOVERY_SERVER_ID=1" >> "$dest/etc/pmu-dds/discovery-server.env"
out=$(DESTDIR="$dest" "$install_sh" --build-dir "$build_dir" 2>&1) || fail "third install.sh run failed: $out"
tail -n 1 "$dest/etc/pmu-dds/pmu-service.yaml" | grep -q "edited on site" || fail "install.sh overwrote an edited config"
grep -q "kept .*pmu-service.yaml" <<<"$out" || fail "install.sh did not report keeping the config: $out"
tail -n 1 "$dest/etc/pmu-dds/discovery-server.env" | grep -q "PMU_DISCOVERY_SERVER_ID=1" ||
  fail "install.sh overwrote an edited discovery-server.env"

step "install.sh --prefix /usr/local"
local_dest=$(mktemp -d "$work/prefix.XXXXXX")
"$install_sh" --build-dir "$build_dir" --prefix /usr/local --destdir "$local_dest" >/dev/null || fail "install.sh --prefix failed"
[ -x "$local_dest/usr/local/bin/pmu-service" ] || fail "--prefix /usr/local: no usr/local/bin/pmu-service"
grep -q "^ExecStart=/usr/local/bin/pmu-service " "$local_dest/usr/local/lib/systemd/system/pmu-service.service" ||
  fail "--prefix /usr/local: the unit's ExecStart= does not follow the prefix"
if [ -f "$build_dir/tools/pmuctl" ]; then
  grep -q "^ExecStart=/usr/local/bin/pmuctl " "$local_dest/usr/local/lib/systemd/user/pmuctl-agent@.service" ||
    fail "--prefix /usr/local: the agent user unit's ExecStart= does not follow the prefix"
fi

# ---- 3. the unit -----------------------------------------------------------------------
if command -v systemd-analyze >/dev/null 2>&1; then
  step "systemd-analyze verify"
  unit_dir="$work/unit"
  mkdir "$unit_dir"
  sed "s#^ExecStart=/usr/bin/pmu-service #ExecStart=$service_bin #" \
    "$deploy/systemd/pmu-service.service" > "$unit_dir/pmu-service.service"
  grep -q "^ExecStart=$service_bin " "$unit_dir/pmu-service.service" || fail "could not point ExecStart= at $service_bin"
  systemd-analyze verify "$unit_dir/pmu-service.service" || fail "systemd-analyze verify rejected the unit"

  step "systemd-analyze security --offline=true"
  if out=$(systemd-analyze security --offline=true "$deploy/systemd/pmu-service.service" 2>&1); then
    score_line=$(grep "Overall exposure level" <<<"$out") || fail "no exposure level in: $out"
    echo "$score_line"
    score=$(sed -E 's/.*: ([0-9]+\.[0-9]+).*/\1/' <<<"$score_line")
    awk -v s="$score" 'BEGIN { exit !(s <= 1.5) }' || fail "exposure $score is above 1.5: the unit was weakened"
  else
    echo "skipped: this systemd-analyze has no --offline ($out)"
  fi

  # The Discovery Server unit runs Debian's fast-discovery-server (fastdds-tools, which
  # scripts/setup.sh installs); verify needs the program to exist.
  ds_unit="$deploy/systemd/pmu-discovery-server.service"
  if [ -x /usr/bin/fast-discovery-server ]; then
    step "systemd-analyze verify pmu-discovery-server.service"
    cp "$ds_unit" "$unit_dir/pmu-discovery-server.service"
    systemd-analyze verify "$unit_dir/pmu-discovery-server.service" ||
      fail "systemd-analyze verify rejected pmu-discovery-server.service"
  else
    echo "--- skipped systemd-analyze verify pmu-discovery-server.service: /usr/bin/fast-discovery-server missing (fastdds-tools)"
  fi
  step "systemd-analyze security --offline=true pmu-discovery-server.service"
  if out=$(systemd-analyze security --offline=true "$ds_unit" 2>&1); then
    score_line=$(grep "Overall exposure level" <<<"$out") || fail "no exposure level in: $out"
    echo "$score_line"
    score=$(sed -E 's/.*: ([0-9]+\.[0-9]+).*/\1/' <<<"$score_line")
    awk -v s="$score" 'BEGIN { exit !(s <= 1.5) }' || fail "discovery server exposure $score is above 1.5: the unit was weakened"
  else
    echo "skipped: this systemd-analyze has no --offline ($out)"
  fi

  # The user unit, for one domain, checked as the user's manager would load it (it needs a
  # runtime directory; man pages are not installed here).
  if [ -f "$build_dir/tools/pmuctl" ]; then
    step "systemd-analyze --user verify pmuctl-agent@73.service"
    user_dir="$work/user-unit"
    mkdir -p "$user_dir" "$work/runtime"
    chmod 700 "$work/runtime"
    sed "s#^ExecStart=/usr/bin/pmuctl #ExecStart=$build_dir/tools/pmuctl #" \
      "$deploy/systemd/pmuctl-agent@.service" > "$user_dir/pmuctl-agent@.service"
    grep -q "^ExecStart=$build_dir/tools/pmuctl " "$user_dir/pmuctl-agent@.service" ||
      fail "could not point the agent unit's ExecStart= at $build_dir/tools/pmuctl"
    (cd "$user_dir" && XDG_RUNTIME_DIR="$work/runtime" systemd-analyze --user --man=no verify pmuctl-agent@73.service) ||
      fail "systemd-analyze --user verify rejected pmuctl-agent@.service"
  fi
else
  echo "--- skipped systemd-analyze checks: systemd-analyze is not installed"
fi

# ---- 4. the Discovery Server's settings --------------------------------------------------
step "discovery-server.env sets what the unit's ExecStart= uses, and the server accepts it"
used=$(grep "^ExecStart=" "$deploy/systemd/pmu-discovery-server.service" | grep -o '\${[A-Z_]*}' | tr -d '${}' | sort -u)
set_in_env=$(grep -E '^[A-Z_]+=' "$deploy/discovery-server.env" | cut -d= -f1 | sort -u)
[ "$used" = "$set_in_env" ] || fail "the unit uses [$(echo $used)] but discovery-server.env sets [$(echo $set_in_env)]"
grep -vE '^(#.*|[A-Z_]+=[^ ]*|)$' "$deploy/discovery-server.env" &&
  fail "discovery-server.env has lines systemd's EnvironmentFile= would not read as NAME=value"
if [ -x /usr/bin/fast-discovery-server ]; then
  # The shipped values (address swapped for loopback and the port for a free one, so the
  # test binds nothing outside this host nor a port in use): the server starts and says so.
  # SIGINT is how the unit stops it (KillSignal=).
  ( set -a; . "$deploy/discovery-server.env"; set +a
    port=$(python3 -c 'import socket; s=socket.socket(socket.AF_INET, socket.SOCK_DGRAM); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])')
    /usr/bin/fast-discovery-server -i "$PMU_DISCOVERY_SERVER_ID" -l 127.0.0.1 -p "$port" -x "$deploy/discovery-server.xml" \
      > "$work/ds.out" 2>&1 &
    pid=$!
    for _ in $(seq 100); do grep -q "Server is running" "$work/ds.out" && break; sleep 0.1; done
    kill -INT "$pid"; wait "$pid" || true
    grep -q "Server is running" "$work/ds.out" || fail "fast-discovery-server did not start with the shipped id: $(cat "$work/ds.out")"
    grep -q "Server shut down" "$work/ds.out" || fail "fast-discovery-server did not stop cleanly on SIGINT: $(cat "$work/ds.out")"
    grep -q "Server ID: *$PMU_DISCOVERY_SERVER_ID\$" "$work/ds.out" || fail "unexpected server id: $(cat "$work/ds.out")"
    # With -x the protocol comes from the file alone: a file without SERVER makes a client.
    grep -q "Participant Type: *SERVER\$" "$work/ds.out" || fail "discovery-server.xml does not make a SERVER: $(cat "$work/ds.out")"
    grep -q "Server Addresses: *UDPv4:\[127.0.0.1\]:$port\$" "$work/ds.out" ||
      fail "the command line's address and port did not take precedence over the XML: $(cat "$work/ds.out")" )
  cat "$work/ds.out"
else
  echo "--- skipped running fast-discovery-server: not installed (fastdds-tools)"
fi

echo "deploy files OK"
