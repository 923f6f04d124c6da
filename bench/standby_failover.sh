#!/usr/bin/env bash
# Hot-standby failover on real SocketCAN: the standby suite's failover scenarios (kill,
# freeze, bus_loss, handover; tests/standby/README.md) run RUNS times each in one boot of the
# test VM (qemu TCG, Debian's kernel), and one markdown table of what they measured, per
# fault: the takeover (the fault to the consumer's first sample from the new owner's writer),
# the largest telemetry gap of the device around it and the command sent at the fault (to its
# final reply), p50 and max over the runs, beside the PMU's packet period. Goals
# (docs/design.md, "Periods and the failover budget"): first sample within 0.5 s, gap at most
# 1 s, a command accepted within 1 s. Each run's own checks (one owner, one stream per
# device, each command answered and executed once) are the suite's: the table says how many
# runs of each fault passed them, and the failures are printed after it. A run's figures are
# measured before those checks, so they count whether it passed or not; the command column
# counts only runs whose command COMPLETED.
#   bench/standby_failover.sh [--build-dir DIR] [--runs N] [--faults "kill freeze ..."] [--log FILE]
set -uo pipefail
src="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="$src/build/dev" runs=5 faults="kill freeze bus_loss handover" log=""
while [ $# -gt 0 ]; do
  case "$1" in
    --build-dir) build=$2; shift 2 ;;
    --runs) runs=$2; shift 2 ;;
    --faults) faults=$2; shift 2 ;;
    --log) log=$2; shift 2 ;;
    *) echo "usage: $0 [--build-dir DIR] [--runs N] [--faults \"kill freeze bus_loss handover\"] [--log FILE]" >&2; exit 2 ;;
  esac
done
case "$runs" in '' | *[!0-9]* | 0) echo "--runs: a count of 1 or more" >&2; exit 2 ;; esac
[ -n "$log" ] || log="$build/standby-failover-console.log"
args=()
for ((i = 1; i <= runs; i++)); do for f in $faults; do args+=(--scenario "$f"); done; done
# About 45 s a scenario under TCG on the 2-core reference machine, plus the boot.
timeout_s=$((120 + 60 * runs * $(wc -w <<<"$faults")))
echo "standby_failover: $runs run(s) of: $faults (VM timeout ${timeout_s}s, console log $log)" >&2
"$src/tests/system/run_vm_tests.sh" --suite standby --build-dir "$build" --source-dir "$src" \
  --timeout "$timeout_s" --log "$log" "${args[@]}" >&2
status=$?
[ "$status" = 77 ] && { echo "standby_failover: the VM cannot run here (see above)" >&2; exit 77; }
[ -s "$log" ] || { echo "standby_failover: no console log" >&2; exit 1; }

# Each scenario's RESULT line follows its FIGURES line; a run counts when it PASSED.
awk -v faults="$faults" '
  /^FIGURES / {
    set[$2] = ""
    for (i = 3; i <= split($0, parts, " "); i++) {
      split(parts[i], kv, "=")
      if (kv[2] != "-") v[$2, kv[1], ++n[$2, kv[1]]] = kv[2]
      if (kv[1] == "period" || kv[1] == "lease" || kv[1] == "can_silence") set[$2] = set[$2] " " kv[1] " " kv[2]
    }
    next
  }
  /^RESULT / { runs[$2]++; if ($3 == "PASS") passed[$2]++ }
  function pct(name, key, p,   k, m, a, i, j, t, r) {
    m = n[name, key]; if (m == 0) return "-"
    for (i = 1; i <= m; i++) a[i] = v[name, key, i] + 0
    for (i = 2; i <= m; i++) { t = a[i]; for (j = i - 1; j >= 1 && a[j] > t; j--) a[j + 1] = a[j]; a[j + 1] = t }
    r = int(p / 100 * m + 0.999999); if (r < 1) r = 1; if (r > m) r = m
    return sprintf("%.2f", a[r])
  }
  function mark(x, goal) { return x == "-" ? x : (x + 0 <= goal ? x : x " (over " goal ")") }
  END {
    print "| fault | runs measured / passed | takeover s p50 / max (goal 0.5) | telemetry gap s p50 / max (goal 1.0) | command accepted s p50 / max (goal 1.0), runs | settings (s) |"
    print "|---|---|---|---|---|---|"
    k = split(faults, fs, " ")
    for (i = 1; i <= k; i++) {
      f = fs[i]
      printf "| %s | %d of %d / %d | %s / %s | %s / %s | %s / %s, %d | %s |\n", f, n[f, "takeover"], runs[f], passed[f],
        pct(f, "takeover", 50), mark(pct(f, "takeover", 100), 0.5), pct(f, "gap", 50), mark(pct(f, "gap", 100), 1.0),
        pct(f, "command", 50), mark(pct(f, "command", 100), 1.0), n[f, "command"], substr(set[f], 2)
    }
  }' "$log"
grep -E '^RESULT ' "$log" | grep -v ' PASS ' | sed 's/^/failed: /' >&2
exit 0
