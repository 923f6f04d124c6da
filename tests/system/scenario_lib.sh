# Sourced by the VM suites (tests/system/scenarios.sh, tests/lab/lab.sh): the helpers and the
# scenario runner they share. Written for busybox ash. run_vm_tests.sh copies it beside the
# suite's script into the VM's root.
#
# A suite defines before sourcing: ALL_SCENARIOS, WORK, log(), diagnose(); and before running:
#   scenario_limit NAME    seconds the scenario may take
#   after_scenario         puts shared state back after each scenario (the bus, the link)
#   before_scenario        (optional) checks that shared state is as a scenario expects, in the
#                          scenario's own shell (it may call detail and fail)
#   FAIL_LOGS              file globs under $WORK/NAME whose tails a failure prints
#   DOMAIN_BASE            the scenarios' DDS domains are DOMAIN_BASE + their index

now() { read -r _up _idle </proc/uptime; echo "$_up"; }          # seconds since boot, 10 ms
since() { awk -v a="$1" -v b="$(now)" 'BEGIN { printf "%.2f", b - a }'; }
calc() { awk "BEGIN { printf \"%.2f\", $* }"; }                     # calc '1 + 2'
true_that() { awk "BEGIN { exit !($*) }"; }                          # true_that '1.5 <= 2'
fail() { echo "$*" >"$WORK/$SCEN.fail"; log "FAIL: $*"; diagnose; exit 1; }
skip() { echo "$*" >"$WORK/$SCEN.skip"; log "SKIP: $*"; exit 77; }
detail() { printf '%s; ' "$*" >>"$WORK/$SCEN.detail"; log "$*"; }

# Value of KEY in one line of JSON (flat or nested, first occurrence), quotes removed.
jv() { printf '%s\n' "$1" | sed -n "s/.*\"$2\":\([^,}]*\).*/\1/p" | tr -d '"'; }
# Numbers compare with a tolerance, everything else as text.
same() {
  awk -v a="$1" -v b="$2" 'BEGIN {
    if (a == b) exit 0
    if (a ~ /^-?[0-9.]+$/ && b ~ /^-?[0-9.]+$/ && (a - b) ^ 2 < 1e-6) exit 0
    exit 1 }'
}

# Runs "$@" every 0.2 s until it succeeds or SECONDS pass.
wait_until() {
  _limit=$1; shift
  _start=$(now)
  while ! "$@"; do
    true_that "$(since "$_start") >= $_limit" && return 1
    sleep 0.2
  done
  return 0
}

before_scenario() { :; }   # a suite that needs it defines its own after sourcing this file

track() { echo "$1" >>"$WORK/pids"; }
alive() { [ -d "/proc/$1" ] && ! grep -q '^State:.*Z' "/proc/$1/status" 2>/dev/null; }

kill_started() {
  [ -f "$WORK/pids" ] || return 0
  for p in $(cat "$WORK/pids"); do kill "$p" 2>/dev/null; done
  _tries=0
  while [ $_tries -lt 30 ]; do
    left=""
    for p in $(cat "$WORK/pids"); do alive "$p" && left="$left $p"; done
    [ -z "$left" ] && break
    sleep 0.1; _tries=$((_tries + 1))
  done
  for p in $left; do kill -9 "$p" 2>/dev/null; done
  rm -f "$WORK/pids"
}

run_one() {  # NAME INDEX: runs a scenario under its time limit and prints its RESULT line
  name=$1
  limit=$(scenario_limit "$name")
  rm -f "$WORK/$name".*
  echo "SCENARIO $name (limit ${limit}s)"
  start=$(now)
  DOMAIN=$((DOMAIN_BASE + $2)) timeout "$limit" sh "$0" one "$name"
  rc=$?
  secs=$(since "$start")
  kill_started
  after_scenario
  rm -f /dev/shm/fastrtps_* /dev/shm/sem.fastrtps_* 2>/dev/null
  d=$(cat "$WORK/$name.detail" 2>/dev/null | sed 's/; $//')
  case $rc in
    0) echo "RESULT $name PASS ${secs}s $d" ;;
    77) echo "RESULT $name SKIP ${secs}s $(cat "$WORK/$name.skip" 2>/dev/null)" ;;
    *)
      if [ -f "$WORK/$name.fail" ]; then why=$(cat "$WORK/$name.fail"); else why="timed out after ${limit}s or crashed (status $rc)"; fi
      for g in $FAIL_LOGS; do
        for f in "$WORK/$name".$g; do
          [ -s "$f" ] && tail -n 8 "$f" | sed "s|^|[$name] $(basename "$f"): |"
        done
      done
      echo "RESULT $name FAIL ${secs}s $why${d:+ (so far: $d)}"
      ;;
  esac
}

# Sets SCENARIOS from pmu.scenarios=a,b on the kernel command line (all when absent) and
# exports pmu.service_log=LEVEL as PMU_SERVICE_LOG_LEVEL. Not in a $(...): the export must stay.
pick_scenarios() {
  _level=$(sed -n 's/.*pmu\.service_log=\([^ ]*\).*/\1/p' /proc/cmdline)
  [ -n "$_level" ] && export PMU_SERVICE_LOG_LEVEL=$_level
  SCENARIOS=$(sed -n 's/.*pmu\.scenarios=\([^ ]*\).*/\1/p' /proc/cmdline | tr ',' ' ')
  [ -n "$SCENARIOS" ] || SCENARIOS=$ALL_SCENARIOS
}

run_list() {  # NAME...: each in turn, a RESULT line for each
  i=0
  for s in "$@"; do
    i=$((i + 1))
    # NAMED_SCENARIOS (a suite may have them): run when named, never by `all`.
    case " $ALL_SCENARIOS ${NAMED_SCENARIOS:-} " in
      *" $s "*) SCEN=$s run_one "$s" "$i" ;;
      *) echo "RESULT $s FAIL 0s no such scenario (known: $ALL_SCENARIOS ${NAMED_SCENARIOS:-})" ;;
    esac
  done
}

# `sh SUITE one NAME` runs one scenario in this shell (what run_one starts under timeout).
run_scenario() {
  SCEN=$1
  : "${DOMAIN:=$DOMAIN_BASE}"
  rm -f "$WORK/pids"
  before_scenario
  "scenario_$SCEN"
  exit 0
}
