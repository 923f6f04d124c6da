#!/usr/bin/env bash
# A profile of pmu-service at a saturated bus (7,634 frames/s over SHM), kept with the
# benchmark so the next person starts from data:
#   sudo bench/profile.sh [--build-dir build/bench] [--out bench/profile] [--seconds 8]
# Runs `pmu_bench run --latency-only` and, while the service's 7,634 frames/s stream runs,
# records with perf (DWARF call graphs: Debian's Fast DDS has no frame pointers), counts
# each thread's context switches per frame, where the busy threads are switched out
# (bench/switch_sites.py) and the syscalls per frame (strace -c, a separate window: strace
# slows the process), then the same counts for the bare Fast DDS writer.
# Writes OUT/service-7634.txt (the report), OUT/rows.jsonl (the run's result rows) and
# OUT/perf.data (not kept in git: `perf report -i OUT/perf.data` to browse it).
# Needs perf (linux-perf) and strace, and perf_event_paranoid <= 1 or root.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build="$root/build/bench"
out="$root/bench/profile"
seconds=8
while [ $# -gt 0 ]; do
  case "$1" in
    --build-dir) build=$2; shift 2 ;;
    --out) out=$2; shift 2 ;;
    --seconds) seconds=$2; shift 2 ;;
    *) echo "bench/profile.sh: unknown option $1 (known: --build-dir DIR, --out DIR, --seconds N)" >&2; exit 2 ;;
  esac
done
for tool in perf strace; do
  command -v "$tool" >/dev/null || { echo "bench/profile.sh: $tool is not installed (apt-get install linux-perf strace)" >&2; exit 2; }
done
for b in service/pmu-service bench/pmu_bench; do
  [ -x "$build/$b" ] || { echo "bench/profile.sh: $build/$b is not built (bench/run.sh builds it)" >&2; exit 2; }
done
export PMU_QOS_FILE=${PMU_QOS_FILE:-$root/deploy/qos.xml}
mkdir -p "$out"
tmp=$(mktemp -d)
bench_pid=
# pmu_bench runs in a session of its own, so that an interrupted profile stops its
# services and peers too.
cleanup() { [ -n "$bench_pid" ] && kill -- -"$bench_pid" 2>/dev/null; rm -rf "$tmp"; }
trap cleanup EXIT
say() { echo "bench/profile.sh: $*" >&2; }

# The stream must outlast the three windows below (perf, switches, strace) and their lead.
stream=$((3 * seconds + 16))
setsid "$build/bench/pmu_bench" run --service "$build/service/pmu-service" --latency-only \
  --latency-seconds "$stream" --realistic-seconds 10 > "$out/rows.jsonl" 2> "$tmp/bench.err" &
bench_pid=$!

wait_for() {  # wait_for PATTERN PGREP-PATTERN: the pid once the bench has said PATTERN
  for _ in $(seq 120); do
    grep -q "$1" "$tmp/bench.err" && { pgrep -n -s "$bench_pid" -f "$2"; return; }
    kill -0 "$bench_pid" 2>/dev/null || { echo "bench/profile.sh: pmu_bench failed: $(tail -n 5 "$tmp/bench.err")" >&2; exit 1; }
    sleep 0.5
  done
  echo "bench/profile.sh: pmu_bench never reached '$1'" >&2
  exit 1
}

# Context switches (voluntary + involuntary) of each thread of PID over SECONDS, per frame.
switches() {  # switches PID SECONDS RATE
  local pid=$1 secs=$2 rate=$3
  snap() { for t in /proc/"$pid"/task/*; do echo "$(basename "$t") $(awk '/ctxt_switches/ {s += $2} END {print s}' "$t/status")"; done | sort; }
  snap > "$tmp/s0"
  sleep "$secs"
  snap > "$tmp/s1"
  join "$tmp/s0" "$tmp/s1" | awk -v s="$secs" -v r="$rate" '
    { d = $3 - $2; total += d; if (d / s > 100) printf "  thread %s: %.0f switches/s = %.2f per frame\n", $1, d / s, d / s / r }
    END { printf "  all threads: %.2f context switches per frame\n", total / s / r }'
}

syscalls() {  # syscalls PID SECONDS RATE: strace -c, calls per frame (strace slows the process)
  local pid=$1 secs=$2 rate=$3
  timeout -s INT "$secs" strace -c -f -p "$pid" -o "$tmp/strace" 2>/dev/null || true
  awk -v s="$secs" -v r="$rate" '$1 ~ /^[0-9.]+$/ && NF >= 5 { name = $NF; printf "  %-16s %8d calls = %.2f per frame\n", name, $4, $4 / s / r }' "$tmp/strace" | head -n 8
}

load=$(cut -d' ' -f1-3 /proc/loadavg)
svc=$(wait_for "latency over SHM" "service-shm.yaml")
say "pmu-service pid $svc: waiting for its 7,634 frames/s stream"
sleep 2.5
say "perf record for $seconds s"
perf record -F 499 --call-graph dwarf,16384 -o "$out/perf.data" -p "$svc" -- sleep "$seconds" 2> "$tmp/perf.err" >/dev/null
say "context switches for $seconds s"
switches "$svc" "$seconds" 7634 > "$tmp/switches"
say "sched_switch call graphs for 1 s"
perf record -e sched:sched_switch --call-graph dwarf,8192 -o "$tmp/switch.data" -p "$svc" -- sleep 1 >/dev/null 2>&1
say "strace -c for $seconds s"
syscalls "$svc" "$seconds" 7634 > "$tmp/syscalls"

ref=$(wait_for "reference: bare writer at 7,634 samples/s over SHM" "peer-writer")
: > "$tmp/ref_switches"
if [ -n "$ref" ]; then
  sleep 1.5
  say "the bare writer's context switches for $seconds s"
  switches "$ref" "$seconds" 7634 > "$tmp/ref_switches"
fi
wait "$bench_pid" || { echo "bench/profile.sh: pmu_bench failed: $(tail -n 5 "$tmp/bench.err")" >&2; exit 1; }
bench_pid=
say "writing the report"
set +o pipefail  # `... | head` ends pipelines early on purpose
{
  echo "# pmu-service at 7,634 frames/s over SHM: where the time goes"
  echo
  echo "Made by: bench/profile.sh (commit $(git -C "$root" rev-parse --short HEAD 2>/dev/null || echo unknown)), $(date -u +%Y-%m-%dT%H:%MZ)"
  echo "Machine: $(sed -n 's/^model name[[:space:]]*: //p' /proc/cpuinfo | head -n1), $(nproc) cores; load average at the start $load; Fast DDS $(dpkg-query -W -f='${Version}\n' libfastrtps2.9 2>/dev/null | head -n1)"
  echo
  echo "## Context switches per frame, pmu-service"
  cat "$tmp/switches"
  echo
  echo "## The bare Fast DDS writer at 7,634 samples/s, for comparison: context switches per sample"
  cat "$tmp/ref_switches"
  echo
  echo "## Where each busy thread of pmu-service was switched out (perf record -e sched:sched_switch, 1 s)"
  perf script -i "$tmp/switch.data" -F tid,ip,sym 2>/dev/null > "$tmp/switch.txt"
  python3 "$root/bench/switch_sites.py" "$tmp/switch.txt"
  echo
  echo "## Syscalls per frame, pmu-service (strace -c; strace slows it, so frames batch more than without)"
  cat "$tmp/syscalls"
  echo
  echo "## CPU by thread and library (perf, $seconds s)"
  perf report -i "$out/perf.data" --no-children --sort pid,dso --stdio 2>/dev/null | grep -E '^ +[0-9]' | head -n 12
  echo
  echo "## Hottest symbols (self)"
  perf report -i "$out/perf.data" --no-children --sort dso,sym --stdio --no-call-graph 2>/dev/null | grep -E '^ +[0-9]' | head -n 30
  echo
  echo "## Call graphs of the service's time (callers, top entries)"
  perf report -i "$out/perf.data" --children --sort sym --stdio -G --percent-limit 4 2>/dev/null | grep -v '^$' | grep -v '^#' | head -n 120
  echo
  echo "## The run's result rows (the latency figures were taken while being profiled)"
  python3 "$root/bench/report.py" "$out/rows.jsonl"
} > "$tmp/report"
cp "$tmp/report" "$out/service-7634.txt"
say "wrote $out/service-7634.txt"
