#!/usr/bin/env bash
# The latency from a CAN frame to its MAVLink message, beside the same frame's DDS sample:
# `pmu_bench mavlink-latency` (bench/driver/mavlink_latency.hpp says how), then the machine,
# the CPU steal during the run, the command and one markdown table. Needs a build with the
# benchmarks (PMU_BUILD_BENCH=ON: bench/run.sh's build/bench, or the release preset):
#   cmake --build build/bench --target pmu-service pmu-mavlink pmu_bench
#   bench/mavlink_latency.sh [--build-dir DIR] [--seconds N]
set -uo pipefail
src="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="$src/build/bench" seconds=60
while [ $# -gt 0 ]; do
  case "$1" in
    --build-dir) build=$2; shift 2 ;;
    --seconds) seconds=$2; shift 2 ;;
    *) echo "usage: $0 [--build-dir DIR] [--seconds N]" >&2; exit 2 ;;
  esac
done
find_exe() { find "$build" -name "$1" -type f -perm -u+x 2>/dev/null | head -n1; }
svc=$(find_exe pmu-service) bridge=$(find_exe pmu-mavlink) bench=$(find_exe pmu_bench)
[ -x "$svc" ] && [ -x "$bridge" ] && [ -x "$bench" ] ||
  { echo "build pmu-service, pmu-mavlink and pmu_bench in $build first (PMU_BUILD_BENCH=ON)" >&2; exit 2; }
export PMU_QOS_FILE="$src/deploy/qos.xml"

steal() { awk '/^cpu / {print $9, $2 + $3 + $4 + $5 + $6 + $7 + $8 + $9}' /proc/stat; }
read -r steal0 total0 < <(steal)
rows=$(mktemp)
trap 'rm -f "$rows"' EXIT
"$bench" mavlink-latency --service "$svc" --bridge "$bridge" --seconds "$seconds" --qos "$PMU_QOS_FILE" >"$rows" || exit 1
read -r steal1 total1 < <(steal)
cpu=$(sed -n 's/^model name[[:space:]]*: //p' /proc/cpuinfo | head -n1)
echo "Machine: $cpu, $(nproc) cores; $(uname -sr); load $(cut -d' ' -f1-3 /proc/loadavg); $(date -u +%Y-%m-%d)"
echo "CPU steal during the run: $(awk -v s=$((steal1 - steal0)) -v t=$((total1 - total0)) 'BEGIN {printf "%.1f", t ? 100 * s / t : 0}') %"
echo "Command: bench/mavlink_latency.sh --build-dir ${build#"$src"/} --seconds $seconds (commit $(git -C "$src" rev-parse --short HEAD 2>/dev/null || echo unknown))"
echo
python3 "$src/bench/report.py" "$rows"
