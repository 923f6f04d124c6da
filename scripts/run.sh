#!/usr/bin/env bash
# Quick start: installs what is missing, builds, and shows decoded PMU traffic.
# Until pmu-service lands this decodes the shipped sample bus log with pmuctl.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"
"$root/scripts/setup.sh"
cmake -S . -B build/release -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo >/dev/null
cmake --build build/release -j"$(nproc)" --target pmuctl
echo
echo "Decoding deploy/examples/sample-candump.log (every packet of protocol v1.9):"
exec build/release/tools/pmuctl decode deploy/examples/sample-candump.log
