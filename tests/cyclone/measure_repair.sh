#!/usr/bin/env bash
# measure_repair.sh [--build-dir DIR] [--qos FILE] [--runs N] [CLIENT OPTIONS...]
# How fast reliable data reaches a Cyclone DDS late joiner: runs crossvendor.sh (one
# pmu-service --bus sim, then the Cyclone client N times, each a new late joiner) with no
# limits on the client, and prints the time from matching to all of pmu/config, pmu/info
# and pmu/health (median, slowest, runs over 1 s), the first replies lost (with how many a
# resend of the same request id recovered) and the slowest reply.
# The figures of deploy/README.md, "QoS: capacity and repair times" (--qos FILE for another qos.xml, e.g. git show REV:deploy/qos.xml):
#   tests/cyclone/measure_repair.sh --runs 20 --resend-ms 0
#   tests/cyclone/measure_repair.sh --runs 20 --resend-ms 0 --command-delay-ms 1500
#   tests/cyclone/measure_repair.sh --runs 20
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
build=$here/../../build/release qos=$here/../../deploy/qos.xml runs=20
while [ $# -gt 0 ]; do
  case $1 in
    --build-dir) build=$2; shift 2 ;;
    --qos) qos=$2; shift 2 ;;
    --runs) runs=$2; shift 2 ;;
    *) break ;;
  esac
done
out=$(bash "$here/crossvendor.sh" "$build/service/pmu-service" "$build/tools/pmuctl" \
  "$build/tests/cyclone/cyclone_client" "$qos" "$runs" --state-ms 10000 --reply-ms 10000 "$@" 2>&1 || true)
summaries=$(grep -o 'summary .*' <<<"$out" || true)
if [ -z "$summaries" ]; then echo "no client run reported; crossvendor.sh said:"; echo "$out"; exit 1; fi
echo "$summaries"
field() { grep -o "$1=[-0-9]*" <<<"$summaries" | cut -d= -f2; }
state=$(field state_after_match_ms | sort -n)
n=$(wc -l <<<"$state")
median=$(sed -n "$(((n + 1) / 2))p" <<<"$state")
slowest=$(tail -1 <<<"$state")
over=$(awk '$1 > 1000' <<<"$state" | wc -l)
lost=$(field replies_lost | awk '{ s += $1 } END { print s + 0 }')
resent=$(field resent | awk '{ s += $1 } END { print s + 0 }')
reply_worst=$(field reply_worst_ms | sort -n | tail -1)
reply_late=$(field reply_worst_ms | awk '$1 > 1000' | wc -l)
echo "QoS $qos, $n late-joiner runs:"
echo "  state (config, info, health) after matching: median $median ms, slowest $slowest ms, $over run(s) over 1 s"
echo "  replies: $((lost + resent)) of $((3 * n)) first replies lost; $resent of them answered to a resend (same id), $lost never"
echo "  slowest reply $reply_worst ms (from the first send); $reply_late run(s) with a reply over 1 s"
