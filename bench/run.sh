#!/usr/bin/env bash
# Every benchmark in one go: builds Release into build/bench, runs the codec benchmark,
# the offline decoder against a python-can reference, and the service benchmarks against
# bare Fast DDS (bench/driver), then prints the machine and one markdown table in which
# each figure stands beside its reference from this same run.
#   bench/run.sh [--quick] [--build-dir DIR] [--no-build]
#     --quick      one short pass of everything (what the test command runs)
#     --no-build   use the binaries already in the build folder
# Its time in full is in bench/README.md (the zero-loss search runs 30 s per rate tried, the realistic
# rate 60 s for the service, the bare writer and the socketpair hop each; the scale
# rows, 1-100 PMUs and 1-16 subscriber processes, about 3.5 minutes).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
# pmu_bench, pmu-service and pmuctl from a build tree look for qos.xml only where it is
# installed; the benchmarks use the source tree's.
export PMU_QOS_FILE=${PMU_QOS_FILE:-$root/deploy/qos.xml}
build="$root/build/bench"
quick=0
build_it=1
while [ $# -gt 0 ]; do
  case "$1" in
    --quick) quick=1; shift ;;
    --build-dir) build=$2; shift 2 ;;
    --no-build) build_it=0; shift ;;
    *) echo "bench/run.sh: unknown option $1 (known: --quick, --build-dir DIR, --no-build)" >&2; exit 2 ;;
  esac
done

if [ "$build_it" = 1 ]; then
  "$root/scripts/setup.sh" >&2
  cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release -DPMU_BUILD_TESTS=OFF -DPMU_BUILD_BENCH=ON >/dev/null
  cmake --build "$build" -j"$(nproc)" --target pmu-service pmuctl pmu_bench codec_bench make_candump_log >&2
fi
for b in service/pmu-service tools/pmuctl bench/pmu_bench bench/codec_bench bench/make_candump_log; do
  [ -x "$build/$b" ] || { echo "bench/run.sh: $build/$b is not built (drop --no-build)" >&2; exit 2; }
done

# CPU time the hypervisor gave to others ("steal", /proc/stat) during the run: on a shared
# virtual machine it delays every thread and turns up in every latency.
steal() { awk '/^cpu / {print $9, $2 + $3 + $4 + $5 + $6 + $7 + $8 + $9}' /proc/stat; }
read -r steal0 total0 < <(steal)
rows=$(mktemp)
trap 'rm -f "$rows"' EXIT
if [ "$quick" = 1 ]; then frames=20000; min_time=0.01; quick_flag=--quick; else frames=1000000; min_time=0.5; quick_flag=; fi

echo "pmu_bench: codec (Google Benchmark)" >&2
"$build/bench/codec_bench" --benchmark_min_time="$min_time" --benchmark_format=json 2>/dev/null |
  python3 "$root/bench/codec_rows.py" >>"$rows"
echo "pmu_bench: offline decode of $frames frames" >&2
"$root/bench/offline_decode.sh" --frames "$frames" --pmuctl "$build/tools/pmuctl" \
  --make-log "$build/bench/make_candump_log" >>"$rows"
"$build/bench/pmu_bench" run --service "$build/service/pmu-service" $quick_flag >>"$rows"

cpu=$(sed -n 's/^model name[[:space:]]*: //p' /proc/cpuinfo | head -n1)
mem=$(awk '/MemTotal/ {printf "%.0f GiB", $2 / 1048576}' /proc/meminfo)
# One line per architecture installed (the arm64 cross-build adds one): the first will do.
fastdds=$(dpkg-query -W -f='${Version}\n' libfastrtps2.9 2>/dev/null | head -n1)
fastdds=${fastdds:-unknown}
echo "Machine: $cpu, $(nproc) cores, $mem; $(uname -sr); Fast DDS $fastdds; $(date -u +%Y-%m-%d)"
read -r steal1 total1 < <(steal)
echo "CPU steal during the run: $(awk -v s=$((steal1 - steal0)) -v t=$((total1 - total0)) 'BEGIN {printf "%.1f", t ? 100 * s / t : 0}') % of the machine's CPU time (time the hypervisor gave to other guests)"
echo "Command: bench/run.sh${quick_flag:+ --quick} (commit $(git -C "$root" rev-parse --short HEAD 2>/dev/null || echo unknown))"
echo
python3 "$root/bench/report.py" "$rows"
