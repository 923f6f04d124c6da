#!/bin/sh
# pmu-dds under a real systemd: scenarios run inside the VM that run_systemd_vm.sh boots
# (Debian bookworm, systemd as PID 1), by pmu-vm-test.service after multi-user.target, from
# the payload disk mounted at /run/payload (debs/, upgrade/, make_pki.sh). Written for dash.
#
# Each scenario is an assertion with a time bound and ends with
#   RESULT <name> PASS|FAIL <seconds>s <detail>
# (tests/system/scenario_lib.sh runs them and prints these lines). The scenarios share one
# system, so each first brings it to the state it needs (need_* below: packages installed,
# vcan0 up by networkd, pmu-sim on it, the baseline config, the service active) instead of
# relying on the one before it; a single scenario can be run alone (--scenario NAME).
#
#   sh scenarios.sh all        the scenarios named by pmu.scenarios= on the kernel command line
#   sh scenarios.sh one NAME   one scenario in this shell

ALL_SCENARIOS="networkd_vcan install ready_status journal pmuctl_user agent_user stop_fast watchdog bad_config other_iface security upgrade remove purge"

export PATH=/usr/sbin:/usr/bin:/sbin:/bin
export DEBIAN_FRONTEND=noninteractive
PAY=/run/payload
WORK=/run/pmu-systemd-test
CONF=/etc/pmu-dds/pmu-service.yaml
OPUSER=pmuop           # the unprivileged operator who runs pmuctl
SECURITY_DROPIN=/etc/systemd/system/pmu-service.service.d/security-credentials.conf
DOMAIN_BASE=0          # the packaged config's domain; scenario_lib gives each a DOMAIN, unused here
FAIL_LOGS="out err"
mkdir -p "$WORK"

log() { echo "[$SCEN] $*"; }
diagnose() {
  log "diag: $(systemctl show -p ActiveState -p SubState -p Result -p MainPID -p NRestarts -p ExecMainStatus -p StatusText pmu-service 2>&1 | tr '\n' ' ')"
  journalctl -b -u pmu-service --no-pager -n 6 -o short-monotonic 2>&1 | sed "s/^/[$SCEN] journal: /"
  # The service's own last words (systemd's lines about it above may hide them).
  journalctl -b _SYSTEMD_UNIT=pmu-service.service --no-pager -n 3 -o cat 2>&1 | sed "s/^/[$SCEN] service: /"
  log "diag: links: $(ip -br link 2>&1 | tr '\n' ' ')"
}
. "$(dirname "$0")/scenario_lib.sh"

# ---- helpers ---------------------------------------------------------------------------

prop() { systemctl show -p "$1" --value "${2:-pmu-service}"; }
active() { [ "$(prop ActiveState "${1:-pmu-service}")" = active ]; }
installed() { dpkg-query -W -f='${Status}' "$1" 2>/dev/null | grep -q 'install ok installed'; }
hires() { date +%s.%N; }
elapsed() { awk -v a="$1" -v b="$(hires)" 'BEGIN { printf "%.2f", b - a }'; }
# A process that is gone or a zombie (waited for by nobody yet) no longer runs.
running_pid() { [ -n "$1" ] && [ "$1" != 0 ] && alive "$1"; }
service_procs() { for c in /proc/[0-9]*/comm; do [ "$(cat "$c" 2>/dev/null)" = pmu-service ] && basename "$(dirname "$c")"; done; true; }

# pmuctl as the unprivileged operator; JSON, one object per line.
ctl() { runuser -u "$OPUSER" -- pmuctl --json "$@"; }
# True when KEY in the first JSON line of `pmuctl VERB...` equals WANT; keeps that line in
# LAST_LINE and the value in LAST for the failure message.
field_is() {  # KEY WANT VERB...
  _k=$1 _w=$2; shift 2
  LAST_LINE=$(ctl --timeout 10 "$@" 2>/dev/null | head -n1)
  LAST=$(jv "$LAST_LINE" "$_k")
  same "$LAST" "$_w"
}

# The config the package ships, with its bus on IFACE (the shipped one names can0).
shipped_config() { dpkg-deb --fsys-tarfile "$(ls "$PAY"/debs/pmu-dds_*.deb)" | tar -xO ./etc/pmu-dds/pmu-service.yaml; }
config_for() {  # IFACE > file
  shipped_config | sed -e "s/^\(  - interface:\) can0\$/\1 $1/" -e "s/^\(    name:\) can0\$/\1 $1/"
}
set_config() {  # IFACE: the baseline config on IFACE; true when the file changed
  config_for "$1" >"$WORK/want.yaml"
  grep -q "^  - interface: $1\$" "$WORK/want.yaml" || fail "cannot point the shipped config at $1 (no '  - interface: can0' line in it)"
  # An operator's comment (the upgrade scenario's edit) changes nothing the service reads.
  [ "$(grep -v '^#' "$WORK/want.yaml")" = "$(grep -v '^#' "$CONF" 2>/dev/null)" ] && return 1
  cp "$WORK/want.yaml" "$CONF"
}

need_user() { id "$OPUSER" >/dev/null 2>&1 || useradd -m -s /bin/sh "$OPUSER" || fail "useradd $OPUSER failed"; }

VCAN_NETDEV=/etc/systemd/network/70-pmu-test-vcan0.netdev
need_vcan0() {
  if [ ! -f "$VCAN_NETDEV" ]; then
    printf '[NetDev]\nName=vcan0\nKind=vcan\n' >"$VCAN_NETDEV"
    # A vcan link has no address: without RequiredForOnline=no it would hold
    # network-online.target, which pmu-service wants.
    printf '[Match]\nName=vcan0\n\n[Link]\nRequiredForOnline=no\n' >/etc/systemd/network/70-pmu-test-vcan0.network
    networkctl reload || fail "networkctl reload failed"
  fi
  wait_until 30 vcan_up vcan0 || fail "systemd-networkd did not bring vcan0 up within 30 s: $(ip -br link show vcan0 2>&1)"
}
vcan_up() { ip -br link show "$1" 2>/dev/null | grep -q '[<,]UP[,>]'; }

need_installed() {
  if ! installed pmu-dds || ! installed pmu-dds-tools; then
    dpkg -i "$PAY"/debs/pmu-dds_*.deb "$PAY"/debs/pmu-dds-tools_*.deb </dev/null >"$WORK/$SCEN.dpkg" 2>&1 ||
      fail "dpkg -i of the packages failed: $(tail -n 3 "$WORK/$SCEN.dpkg" | tr '\n' ' ')"
  fi
}

need_sim() {  # IFACE: pmu-sim on IFACE as a transient unit
  active "pmu-sim-$1" && return 0
  systemctl reset-failed "pmu-sim-$1" 2>/dev/null
  systemd-run --quiet --unit="pmu-sim-$1" --property=DynamicUser=yes /usr/bin/pmu-sim "$1" ||
    fail "systemd-run pmu-sim $1 failed"
  wait_until 10 active "pmu-sim-$1" || fail "pmu-sim-$1 is $(prop ActiveState "pmu-sim-$1"): $(journalctl -u "pmu-sim-$1" -o cat --no-pager -n 3 | tr '\n' ' ')"
}

# Packages installed, vcan0 by networkd, pmu-sim on it, the baseline config (vcan0) and
# the service active: what most scenarios start from.
need_service() {
  need_user
  need_vcan0
  need_installed
  need_sim vcan0
  if set_config vcan0 || ! active; then
    systemctl reset-failed pmu-service 2>/dev/null
    systemctl restart pmu-service || fail "systemctl restart pmu-service failed: $(prop Result) $(prop StatusText)"
  fi
  active || fail "pmu-service is $(prop ActiveState) after start"
}
# Every telemetry topic appears in a `pmuctl watch --json` capture.
five_topics() {  # FILE: pmuctl watch --json output
  for t in voltages currents battery_energy temperatures status; do
    grep -q "\"topic\":\"$t\"" "$1" || return 1
  done
}

# ---- scenarios -------------------------------------------------------------------------

# systemd-networkd creates vcan0 from a .netdev and brings it up (the CAN modules load by
# themselves from the kernel package's /lib/modules).
scenario_networkd_vcan() {
  ip link show vcan0 >/dev/null 2>&1 && fail "vcan0 exists before the test's .netdev is installed"
  t=$(hires)
  need_vcan0
  detail "vcan0 up $(elapsed "$t") s after networkctl reload: $(ip -br link show vcan0 | tr -s ' ')"
  lsmod | grep -q '^vcan ' || fail "vcan0 is up but the vcan module is not listed by lsmod"
  st=$(networkctl list --no-legend vcan0 2>&1 | awk '{print $4, $5}')
  case "$st" in *configured*|*configuring*) ;; *) fail "networkctl does not show vcan0 managed: '$st'" ;; esac
  detail "networkctl: vcan0 $st"
}

# dpkg -i of both packages: the unit is enabled and started by the package, with the
# shipped config (can0, which does not exist here) and without waiting for can0.
scenario_install() {
  installed pmu-dds && fail "pmu-dds is installed already (run install on a fresh root)"
  need_user
  t=$(hires)
  dpkg -i "$PAY"/debs/pmu-dds_*.deb "$PAY"/debs/pmu-dds-tools_*.deb </dev/null >"$WORK/$SCEN.out" 2>&1 ||
    fail "dpkg -i failed (status $?): $(tail -n 3 "$WORK/$SCEN.out" | tr '\n' ' ')"
  secs=$(elapsed "$t")
  detail "dpkg -i of $(ls "$PAY"/debs | tr '\n' ' ')in $secs s"
  true_that "$secs < 60" || fail "dpkg -i took $secs s (a start waiting for a device that never comes?)"
  for b in /usr/bin/pmu-service /usr/bin/pmuctl /usr/bin/pmu-sim; do [ -x "$b" ] || fail "$b not installed"; done
  [ -f "$CONF" ] || fail "$CONF not installed"
  [ "$(systemctl is-enabled pmu-service 2>&1)" = enabled ] || fail "pmu-service is '$(systemctl is-enabled pmu-service 2>&1)' after install, not enabled"
  wait_until 20 active || fail "pmu-service is $(prop ActiveState)/$(prop SubState) after install with the shipped config (can0 absent), not active"
  wait_until 30 field_is bus_state DOWN --bus can0 health || fail "health of can0 (absent): bus_state '$LAST', want DOWN ($LAST_LINE)"
  detail "enabled, active with the shipped config (interface can0 absent, health bus_state DOWN): $(prop StatusText)"
}

# Type=notify: active means READY=1 arrived; STATUS= text; a dynamic user, not root.
scenario_ready_status() {
  need_service
  [ "$(prop Type)" = notify ] || fail "unit Type is '$(prop Type)', not notify"
  wait_until 30 active || fail "not active: $(prop ActiveState)/$(prop SubState)"
  [ "$(prop SubState)" = running ] || fail "SubState '$(prop SubState)', not running"
  wait_until 20 test -n "$(prop StatusText)" || fail "no STATUS= text (StatusText empty)"
  pid=$(prop MainPID)
  uid=$(awk '/^Uid:/ {print $2}' "/proc/$pid/status")
  [ -n "$uid" ] && [ "$uid" != 0 ] || fail "the service (pid $pid) runs as uid '$uid'"
  detail "active/running (READY), StatusText '$(prop StatusText)', pid $pid uid $uid ($(getent passwd "$uid" | cut -d: -f1))"
}

# The service's own lines are in the journal under the unit.
scenario_journal() {
  need_service
  pid=$(prop MainPID)
  wait_until 20 journal_has_ready "$pid" || fail "journalctl -u pmu-service has no 'ready on DDS domain' line from pid $pid: $(journalctl -b -u pmu-service -o cat --no-pager -n 3 | tr '\n' ' ')"
  n=$(journalctl -b _PID="$pid" -o cat --no-pager | wc -l)
  detail "journal of pid $pid: $n lines, e.g. '$(journalctl -b -u pmu-service _PID="$pid" -o cat --no-pager | grep -m1 'ready on DDS domain')'"
}
journal_has_ready() { journalctl -b -u pmu-service _PID="$1" -o cat --no-pager | grep -q 'ready on DDS domain'; }

# pmuctl as an unprivileged user reads every state verb and topic and commands the PMU.
scenario_pmuctl_user() {
  need_service
  [ "$(id -u "$OPUSER")" != 0 ] || fail "$OPUSER is root"
  wait_until 90 field_is state ONLINE list || fail "pmuctl list as $OPUSER: no ONLINE PMU within 90 s (last: '$LAST_LINE')"
  detail "list: $LAST_LINE"
  ctl --timeout 60 watch --count 15 >"$WORK/$SCEN.out" 2>"$WORK/$SCEN.err" || fail "pmuctl watch --count 15 as $OPUSER failed: $(tail -n1 "$WORK/$SCEN.err")"
  five_topics "$WORK/$SCEN.out" || fail "pmuctl watch: not all five topics among 15 samples: $(sed -n 's/.*"topic":"\([a-z_]*\)".*/\1/p' "$WORK/$SCEN.out" | sort | uniq -c | tr '\n' ' ')"
  [ "$(jv "$(head -n1 "$WORK/$SCEN.out")" bus)" = vcan0 ] || fail "watch: bus is '$(jv "$(head -n1 "$WORK/$SCEN.out")" bus)', not vcan0"
  detail "watch: all five topics from vcan0"
  field_is bus_state UP health || fail "health bus_state '$LAST', want UP ($LAST_LINE)"
  field_is state ONLINE health || fail "health state '$LAST', want ONLINE"
  info=$(ctl --timeout 10 info 2>&1 | head -n1)
  [ -n "$(jv "$info" serial_number)" ] || fail "pmuctl info: no serial_number in '$info'"
  cfg=$(ctl --timeout 10 config get 2>&1)
  printf '%s' "$cfg" | grep -q avionics_voltage || fail "pmuctl config get: no avionics_voltage in '$(printf '%s' "$cfg" | head -c 200)'"
  detail "health UP/ONLINE, info serial $(jv "$info" serial_number), config get"
  for c in "config set avionics_voltage 12.5" "outputs get" "outputs enable payload" "generation on" "measure voltages currents"; do
    # shellcheck disable=SC2086 # the command's words
    ctl --timeout 20 --address 1 $c >"$WORK/$SCEN.out" 2>"$WORK/$SCEN.err" ||
      fail "pmuctl $c as $OPUSER: exit $? ($(tail -n1 "$WORK/$SCEN.err") $(tail -n1 "$WORK/$SCEN.out"))"
  done
  field_is avionics_voltage 12.5 config get avionics_voltage || fail "config get avionics_voltage '$LAST' after setting 12.5"
  detail "5 commands completed (exit 0), avionics_voltage read back 12.5"
}

# The operator's pmuctl agent as a systemd user service (pmuctl-agent@.service of
# pmu-dds-tools), started by the operator's own manager (lingering, so no login is
# needed): its socket is where the operator's calls look, a call goes through it (one line
# in the operator's journal), and stopping it removes the socket.
agent_uid() { id -u "$OPUSER"; }
# systemctl --user of the operator: its manager's private socket under XDG_RUNTIME_DIR (no
# session bus in this image).
uctl() { runuser -u "$OPUSER" -- env XDG_RUNTIME_DIR="/run/user/$(agent_uid)" systemctl --user "$@"; }
user_manager_up() { [ -S "/run/user/$(agent_uid)/systemd/private" ]; }
agent_log() { journalctl _SYSTEMD_USER_UNIT=pmuctl-agent@0.service -o cat --no-pager 2>/dev/null; }
scenario_agent_user() {
  need_service
  need_user
  sock="/run/user/$(agent_uid)/pmu-dds/agent-0.sock"
  loginctl enable-linger "$OPUSER" || fail "loginctl enable-linger $OPUSER failed"
  wait_until 60 user_manager_up ||
    fail "no systemd user manager for $OPUSER within 60 s (user@$(agent_uid).service $(systemctl is-active "user@$(agent_uid).service"); $(journalctl -b -u "user@$(agent_uid).service" -u systemd-logind -o cat --no-pager | tail -n4 | tr '\n' ' '))"
  uctl start pmuctl-agent@0 2>"$WORK/$SCEN.err" || fail "systemctl --user start pmuctl-agent@0: $(tail -n1 "$WORK/$SCEN.err")"
  wait_until 30 test -S "$sock" || fail "no agent socket at $sock within 30 s ($(uctl is-active pmuctl-agent@0))"
  detail "agent active, socket $sock"
  wait_until 90 agent_lists || fail "pmuctl list through the agent: no ONLINE PMU within 90 s (last: '$LAST_LINE')"
  agent_log | grep -q -- "--timeout 10 list: exit 0" || fail "the agent's journal has no line for the list: $(agent_log | tail -n2 | tr '\n' ' ')"
  detail "list as $OPUSER went through it (its journal: $(agent_log | grep -c ': exit ') calls)"
  uctl stop pmuctl-agent@0 || fail "systemctl --user stop pmuctl-agent@0 failed"
  [ ! -e "$sock" ] || fail "the stopped agent left its socket $sock"
  loginctl disable-linger "$OPUSER"
  detail "stopped, socket removed"
}
agent_lists() {
  LAST_LINE=$(runuser -u "$OPUSER" -- env XDG_RUNTIME_DIR="/run/user/$(agent_uid)" pmuctl --json --timeout 10 list 2>&1 | head -n1)
  same "$(jv "$LAST_LINE" state)" ONLINE
}

# systemctl stop is quick: SIGTERM, and the service is gone within a second. Asserted on
# systemd's own clock (leaving active -> inactive), which the emulated systemctl client's
# start-up does not inflate; the client's wall time is reported beside it.
scenario_stop_fast() {
  need_service
  pid=$(prop MainPID)
  t=$(hires)
  systemctl stop pmu-service || fail "systemctl stop failed"
  wall=$(elapsed "$t")
  [ "$(prop ActiveState)" = inactive ] || fail "after stop: $(prop ActiveState)"
  running_pid "$pid" && fail "pid $pid still runs after systemctl stop"
  secs=$(awk -v a="$(prop ActiveExitTimestampMonotonic)" -v b="$(prop InactiveEnterTimestampMonotonic)" 'BEGIN { printf "%.2f", (b - a) / 1e6 }')
  detail "stop took $secs s (active -> inactive; bound 1 s; systemctl returned after $wall s), result $(prop Result)"
  true_that "$secs < 1.0" || fail "stopping took $secs s, not under 1 s"
  [ "$(prop Result)" = success ] || fail "Result $(prop Result) after stop (SIGKILL needed?)"
  systemctl start pmu-service || fail "start after stop failed"
}

# A stopped main process stops sending WATCHDOG=1: systemd kills it after WatchdogSec (10 s)
# and restarts it (Restart=on-failure), READY again.
scenario_watchdog() {
  need_service
  pid=$(prop MainPID); n0=$(prop NRestarts)
  t=$(hires)
  kill -STOP "$pid" || fail "kill -STOP $pid failed"
  wait_until 60 restarted_from "$pid" || fail "no new MainPID 60 s after SIGSTOP of $pid (now $(prop MainPID), $(prop ActiveState)/$(prop SubState), NRestarts $(prop NRestarts))"
  secs=$(elapsed "$t")
  n1=$(prop NRestarts)
  [ "$n1" -eq $((n0 + 1)) ] || fail "NRestarts $n0 -> $n1, want one restart"
  running_pid "$pid" && fail "the stopped pid $pid still exists"
  journalctl -b -u pmu-service -o cat --no-pager | grep -qi 'watchdog timeout' || fail "no 'Watchdog timeout' in the unit's journal"
  true_that "$secs >= 9" || fail "restarted after $secs s, before the 10 s watchdog could fire"
  detail "SIGSTOP pid $pid -> watchdog timeout, new pid $(prop MainPID) active after $secs s, NRestarts $n0 -> $n1"
}
restarted_from() { _p=$(prop MainPID); [ "$_p" != 0 ] && [ "$_p" != "$1" ] && active; }

# A syntax error in the config: exit status 2, failed, and no automatic restart.
scenario_bad_config() {
  need_service
  printf 'log_level: [unclosed\n' >>"$CONF"
  systemctl restart pmu-service 2>"$WORK/$SCEN.err" && fail "systemctl restart succeeded with a broken config"
  n1=$(prop NRestarts)
  wait_until 10 test "$(prop ActiveState)" = failed || fail "unit is $(prop ActiveState), not failed"
  [ "$(prop ExecMainStatus)" = 2 ] || fail "ExecMainStatus $(prop ExecMainStatus), want 2"
  sleep 7   # > 3 x RestartSec (2 s): a restart loop would have shown by now
  n2=$(prop NRestarts)
  [ "$n2" = "$n1" ] || fail "NRestarts $n1 -> $n2 within 7 s: restarted despite exit status 2"
  [ "$(prop ActiveState)" = failed ] || fail "unit is $(prop ActiveState) 7 s later, not failed"
  why=$(journalctl -b -u pmu-service -o cat --no-pager -n 30 | grep -m1 -i 'pmu-service.yaml' | cut -c1-120)
  detail "failed, ExecMainStatus 2, Result $(prop Result), NRestarts $n1 -> $n2 over 7 s; journal: $why"
  set_config vcan0
  systemctl reset-failed pmu-service
  systemctl start pmu-service || fail "start with the fixed config failed"
}

# Another interface by the config alone: vcan1 does not exist at restart; the start does
# not wait for it (health DOWN), and when it appears the same process binds it.
scenario_other_iface() {
  need_service
  ip link del vcan1 2>/dev/null
  set_config vcan1
  t=$(hires)
  systemctl restart pmu-service || fail "systemctl restart with interface vcan1 (absent) failed: $(prop Result)"
  secs=$(elapsed "$t")
  true_that "$secs < 10" || fail "systemctl restart took $secs s with vcan1 absent (waiting for a device?)"
  active || fail "not active with vcan1 absent: $(prop ActiveState)"
  pid=$(prop MainPID)
  wait_until 30 field_is bus_state DOWN --bus vcan1 health || fail "health of vcan1 (absent): bus_state '$LAST', want DOWN ($LAST_LINE)"
  detail "restart with vcan1 absent: $secs s, active, bus_state DOWN"
  ip link add vcan1 type vcan && ip link set vcan1 up || fail "cannot create vcan1"
  need_sim vcan1
  ctl --timeout 60 --bus vcan1 watch --count 5 >"$WORK/$SCEN.out" 2>"$WORK/$SCEN.err" || fail "no telemetry from vcan1 within 60 s after it appeared: $(tail -n1 "$WORK/$SCEN.err")"
  [ "$(prop MainPID)" = "$pid" ] || fail "MainPID changed $pid -> $(prop MainPID): not bound in place"
  detail "vcan1 created: telemetry from vcan1, same pid $pid"
  set_config vcan0; systemctl restart pmu-service   # after_scenario removes vcan1 and its pmu-sim
}

# DDS-Security with the key root-only (0600) handed over by LoadCredential=; pmuctl as the
# operator with its own identity; the service's user cannot open the key file itself.
scenario_security() {
  need_service
  SEC=/etc/pmu-dds/security
  mk=/usr/share/pmu-dds/make_pki.sh; src="the package's $mk"
  [ -f "$mk" ] || { mk=$PAY/make_pki.sh; src="deploy/security/make_pki.sh (the package ships no $mk)"; }
  rm -rf "$SEC"
  t=$(hires)
  bash "$mk" "$SEC" >"$WORK/$SCEN.out" 2>&1 || fail "make_pki.sh failed: $(tail -n2 "$WORK/$SCEN.out" | tr '\n' ' ')"
  pki_secs=$(elapsed "$t")
  rm -rf "$SEC/ca"   # the CA keys never stay on the machine
  KEY=$SEC/pmu-service/key.pem
  chown root:root "$KEY" && chmod 600 "$KEY"
  [ "$(stat -c '%a %U' "$KEY")" = "600 root" ] || fail "key mode/owner $(stat -c '%a %U' "$KEY")"
  detail "PKI from $src in $pki_secs s; key 0600 root"
  # The operator's own identity, in its home, readable by it alone.
  H=$(getent passwd "$OPUSER" | cut -d: -f6)
  rm -rf "$H/security"; mkdir -p "$H/security"
  cp -r "$SEC/identity_ca.pem" "$SEC/permissions_ca.pem" "$SEC/governance.p7s" "$SEC/ground-station" "$H/security/"
  chown -R "$OPUSER:" "$H/security"; chmod 700 "$H/security"
  # The drop-in the package ships as an example, installed as deploy/security/README.md
  # says; the same line written here if the package has none.
  mkdir -p "${SECURITY_DROPIN%/*}"
  ex=/usr/share/doc/pmu-dds/examples/security-credentials.conf
  if [ -f "$ex" ]; then
    cp "$ex" "$SECURITY_DROPIN"; dsrc="the package's example drop-in"
  else
    printf '[Service]\nLoadCredential=pmu-service-key.pem:%s\n' "$KEY" >"$SECURITY_DROPIN"; dsrc="a drop-in written here (the package ships no $ex)"
  fi
  grep -q "^LoadCredential=pmu-service-key.pem:$KEY\$" "$SECURITY_DROPIN" || fail "$dsrc has no LoadCredential=pmu-service-key.pem:$KEY"
  cat >>"$CONF" <<EOF
security:
  identity_ca: security/identity_ca.pem
  identity_certificate: security/pmu-service/cert.pem
  private_key: credential:pmu-service-key.pem
  permissions_ca: security/permissions_ca.pem
  governance: security/governance.p7s
  permissions: security/pmu-service/permissions.p7s
EOF
  systemctl daemon-reload
  systemctl restart pmu-service || fail "restart with security on failed: ExecMainStatus $(prop ExecMainStatus), $(journalctl -b -u pmu-service -o cat --no-pager -n 2 | tr '\n' ' ')"
  active || fail "not active with security on"
  pid=$(prop MainPID)
  journalctl -b -u pmu-service _PID="$pid" -o cat --no-pager | grep -qi 'security' || fail "the service's journal does not mention security after a start with it on"
  runuser -u "$OPUSER" -- pmuctl --json --security-dir "$H/security" --identity ground-station --timeout 90 watch --count 15 \
    >"$WORK/$SCEN.out" 2>"$WORK/$SCEN.err" || fail "secure pmuctl watch as $OPUSER failed: $(tail -n1 "$WORK/$SCEN.err")"
  five_topics "$WORK/$SCEN.out" || fail "secure watch: not all five topics among 15 samples"
  detail "with $dsrc the service is active with the key from its credential; $OPUSER as ground-station reads all five topics"
  # Without an identity the service is invisible.
  ctl --timeout 8 watch --count 1 >"$WORK/$SCEN.out" 2>/dev/null
  grep -q '"topic"' "$WORK/$SCEN.out" && fail "pmuctl without an identity read telemetry from the secure service: $(head -c 120 "$WORK/$SCEN.out")"
  # The service's dynamic user (same name, so the same transient uid while it runs).
  uid=$(awk '/^Uid:/ {print $2}' "/proc/$pid/status")
  out=$(systemd-run --quiet --wait --pipe -p DynamicUser=yes -p User=pmu-service sh -c "id -u; cat $KEY >/dev/null && echo READ-OK" 2>&1)
  [ "$(printf '%s\n' "$out" | head -n1)" = "$uid" ] || fail "the probe did not run as the service's uid $uid: '$out'"
  printf '%s' "$out" | grep -q READ-OK && fail "the service's user (uid $uid) can read $KEY directly"
  detail "unauthenticated pmuctl sees nothing; uid $uid cannot open $KEY ($(printf '%s' "$out" | tail -n1 | cut -c1-60))"
  # after_scenario removes the drop-in and the keys.
  set_config vcan0; systemctl restart pmu-service
}

# A newer version of the same package: the operator's edited conffile stays, without a
# prompt, and the service is restarted.
scenario_upgrade() {
  need_service
  echo "# edited by the operator (systemd_vm test) $$" >>"$CONF"
  cp "$CONF" "$WORK/edited.yaml"
  pid=$(prop MainPID); v0=$(dpkg-query -W -f='${Version}' pmu-dds)
  t=$(hires)
  dpkg -i "$PAY"/upgrade/pmu-dds_*.deb </dev/null >"$WORK/$SCEN.out" 2>&1 ||
    fail "dpkg -i of the upgrade failed: $(tail -n 3 "$WORK/$SCEN.out" | tr '\n' ' ')"
  secs=$(elapsed "$t")
  v1=$(dpkg-query -W -f='${Version}' pmu-dds)
  [ "$v1" != "$v0" ] || fail "version still $v0 after the upgrade"
  cmp -s "$CONF" "$WORK/edited.yaml" || fail "the edited $CONF was changed by the upgrade"
  leftovers=$(ls /etc/pmu-dds | grep -E '\.dpkg-(new|dist|old|tmp)$' || true)
  [ -z "$leftovers" ] || fail "dpkg left $leftovers in /etc/pmu-dds"
  wait_until 20 restarted_from "$pid" || fail "MainPID still $pid (or not active) after the upgrade: not restarted"
  detail "$v0 -> $v1 in $secs s, edited config kept (no prompt), restarted: pid $pid -> $(prop MainPID)"
  rm -f "$WORK/edited.yaml"
}

# dpkg -r stops the service; the configuration stays until purge.
scenario_remove() {
  need_service
  pid=$(prop MainPID)
  pkgs=pmu-dds
  # The tools cannot stay without the daemon if they depend on it.
  dpkg-query -W -f='${Depends}' pmu-dds-tools | grep -qw pmu-dds && pkgs="pmu-dds-tools pmu-dds"
  # shellcheck disable=SC2086
  dpkg -r $pkgs </dev/null >"$WORK/$SCEN.out" 2>&1 || fail "dpkg -r $pkgs failed: $(tail -n 3 "$WORK/$SCEN.out" | tr '\n' ' ')"
  wait_until 10 sh -c '! kill -0 '"$pid"' 2>/dev/null' || fail "pid $pid still runs after dpkg -r"
  st=$(prop ActiveState)
  [ "$st" = inactive ] || fail "unit $st after dpkg -r, not inactive"
  [ -z "$(service_procs)" ] || fail "pmu-service processes left: $(service_procs)"
  [ -f "$CONF" ] || fail "$CONF removed by dpkg -r (conffiles stay until purge)"
  detail "dpkg -r $pkgs: pid $pid gone, unit $st, $CONF kept"
}

# dpkg -P deletes /etc/pmu-dds.
scenario_purge() {
  installed pmu-dds && { dpkg -r pmu-dds-tools pmu-dds </dev/null >/dev/null 2>&1 || fail "dpkg -r before purge failed"; }
  dpkg-query -W -f='${Status}' pmu-dds 2>/dev/null | grep -q config-files || fail "pmu-dds is not in state config-files before purge: $(dpkg-query -W -f='${Status}' pmu-dds 2>&1)"
  dpkg -P pmu-dds </dev/null >"$WORK/$SCEN.out" 2>&1 || fail "dpkg -P pmu-dds failed: $(tail -n 3 "$WORK/$SCEN.out" | tr '\n' ' ')"
  [ ! -e /etc/pmu-dds ] || fail "/etc/pmu-dds still there after purge: $(ls -A /etc/pmu-dds | tr '\n' ' ')"
  for d in /var/lib/pmu-dds /var/lib/private/pmu-dds; do
    [ ! -e "$d" ] && [ ! -L "$d" ] || fail "$d (the service's state) still there after purge"
  done
  st=$(systemctl is-enabled pmu-service 2>&1)
  detail "/etc/pmu-dds and the state directory deleted; is-enabled: $st"
}

# ---- driver ----------------------------------------------------------------------------

scenario_limit() {
  case "$1" in
    pmuctl_user|security) echo 240 ;;
    install|other_iface|upgrade|watchdog) echo 120 ;;
    *) echo 90 ;;
  esac
}
# What a failed scenario may have left behind that would break the next ones (each
# scenario's need_* helpers restore the rest: config, service, pmu-sim on vcan0).
after_scenario() {
  if [ -f "$SECURITY_DROPIN" ]; then
    rm -f "$SECURITY_DROPIN"; rmdir "${SECURITY_DROPIN%/*}" 2>/dev/null
    systemctl daemon-reload
  fi
  rm -rf /etc/pmu-dds/security
  loginctl disable-linger "$OPUSER" 2>/dev/null
  [ -d "/home/$OPUSER/security" ] && rm -rf "/home/$OPUSER/security"
  systemctl stop pmu-sim-vcan1 2>/dev/null; systemctl reset-failed pmu-sim-vcan1 2>/dev/null
  ip link del vcan1 2>/dev/null
  true
}

case "${1:-all}" in
  all) pick_scenarios; run_list $SCENARIOS ;;
  one) run_scenario "$2" ;;
  *) echo "usage: $0 all | one NAME" >&2; exit 2 ;;
esac
