# Sourced by the benchmarks that time pmuctl against a pmu-service on the built-in simulator
# (engine_start.sh, config_apply.sh): their options, the programs, a domain and a work folder
# of their own, and the median of their rows.
#
#   --build-dir DIR (default build/dev), --runs N (default 5)
# Sets: here, build, runs, service, ctl, domain, work; exports PMU_QOS_FILE. The caller's
# EXIT trap removes $work (and stops what it started).
build=build/dev
runs=5
while [ $# -gt 0 ]; do
  case "$1" in
    --build-dir) build=$2; shift 2 ;;
    --runs) runs=$2; shift 2 ;;
    *) echo "usage: $0 [--build-dir DIR] [--runs N]" >&2; exit 2 ;;
  esac
done
here=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
service=$build/service/pmu-service
ctl=$build/tools/pmuctl
[ -x "$service" ] && [ -x "$ctl" ] || { echo "$(basename "$0"): build $build first (pmu-service, pmuctl)" >&2; exit 2; }
export PMU_QOS_FILE=$here/deploy/qos.xml
domain=$((150 + RANDOM % 50))
work=$(mktemp -d)

median() { sort -n | awk '{a[NR]=$1} END {print (NR % 2) ? a[(NR + 1) / 2] : (a[NR / 2] + a[NR / 2 + 1]) / 2}'; }
