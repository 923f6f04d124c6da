#!/usr/bin/env bash
# Quick start: installs what is missing (scripts/setup.sh run), builds, starts pmu-service on
# the built-in simulated power system (a PMU, the battery's BMS and two MPPTs:
# deploy/examples/sim-power-system.yaml) and shows its live telemetry with `pmuctl watch`
# (Ctrl-C stops both).
#   scripts/run.sh [--domain N] [extra pmuctl watch options, e.g. --json --count 20]
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"
# A binary from the build tree looks for qos.xml only where it is installed.
export PMU_QOS_FILE=${PMU_QOS_FILE:-$root/deploy/qos.xml}
domain=0
if [ "${1:-}" = "--domain" ]; then domain=$2; shift 2; fi

# The run set is enough: a fresh tree has tests and benchmarks off (a tree that
# scripts/test.sh configured keeps them on, and its packages are there).
"$root/scripts/setup.sh" run
# A tree made here is a unity build with line tables only (-g1): on a fresh 2-core machine
# pmu-service and pmuctl compile in 64 s instead of 160 s (README.md, Quick start). A tree
# that already exists is built as it was configured; the presets of scripts/test.sh set
# both options back.
if [ ! -f build/release/CMakeCache.txt ]; then
  cmake -S . -B build/release -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_UNITY_BUILD=ON \
    -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O2 -g1 -DNDEBUG" >/dev/null
fi
cmake --build build/release -j"$(nproc)" --target pmu-service pmuctl

log=$(mktemp -t pmu-service.XXXXXX.log)
build/release/service/pmu-service --config deploy/examples/sim-power-system.yaml --domain "$domain" >"$log" 2>&1 &
service=$!
trap 'kill -TERM $service 2>/dev/null; wait $service 2>/dev/null || true; echo "pmu-service log: $log"' EXIT
echo "pmu-service (pid $service) runs on the simulated PMU, battery and MPPTs, DDS domain $domain; log: $log"
sleep 1
kill -0 $service 2>/dev/null || { cat "$log"; exit 1; }
build/release/tools/pmuctl --domain "$domain" list
build/release/tools/pmuctl --domain "$domain" watch "$@"
