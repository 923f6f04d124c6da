#!/bin/bash
# How long `pmuctl config apply` takes to write a whole PMU configuration (docs/interface.md
# 4.6) on the built-in simulator, as an operator sees it: from launching pmuctl to its exit,
# for a file that differs in all thirteen settings (each change verified by the service's
# read-back; can_address last), and for the file applied back. The reference, measured in the
# same run against the same service, is one plain command (`outputs get`), which pays the same
# participant start and discovery.
#
#   bench/config_apply.sh [--build-dir DIR] [--runs N]     (default build/dev, 5 runs)
#
# One service for all runs; prints one row per run and the medians.
set -euo pipefail
source "$(dirname "$0")/pmuctl_runs.sh"
trap 'kill "$svc" 2>/dev/null || true; rm -rf "$work"' EXIT
cat >"$work/service.yaml" <<YAML
domain: $domain
buses:
  - interface: sim
    devices:
      - address: 1
        period: 0.5
YAML
changed=$here/tests/data/config_every_setting.yaml

ms() { local s; s=$(date +%s%N); "$@" >/dev/null 2>"$work/err" || { cat "$work/err" >&2; return 1; }; echo $(( ($(date +%s%N) - s) / 1000000 )); }

"$service" --config "$work/service.yaml" >"$work/service.log" 2>&1 &
svc=$!
"$ctl" --domain "$domain" --timeout 30 --address 1 config snapshot "$work/factory.yaml" 2>/dev/null
# diff exits 1 when the PMU differs, as it must here.
"$ctl" --domain "$domain" --json --address 1 config diff "$changed" >"$work/diff" 2>/dev/null || true
changes=$(grep -o '"name":' "$work/diff" | wc -l)
echo "| run | outputs get (ms) | apply $changes changes (ms) | apply back (ms) |"
echo "|---|---|---|---|"
: >"$work/rows"
for run in $(seq 1 "$runs"); do
  ref=$(ms "$ctl" --domain "$domain" --timeout 10 --address 1 outputs get)
  forth=$(ms "$ctl" --domain "$domain" --timeout 10 --address 1 --confirm config apply "$changed")
  back=$(ms "$ctl" --domain "$domain" --timeout 10 --address 9 --confirm config apply "$work/factory.yaml")
  echo "| $run | $ref | $forth | $back |"
  echo "$ref $forth $back" >>"$work/rows"
done
ref=$(awk '{print $1}' "$work/rows" | median)
forth=$(awk '{print $2}' "$work/rows" | median)
back=$(awk '{print $3}' "$work/rows" | median)
echo
echo "medians: outputs get $ref ms; apply of $changes changes $forth ms" \
  "($(awk -v a="$forth" -v r="$ref" 'BEGIN {printf "%.2f", a / r}') x outputs get); apply back $back ms" \
  "($(awk -v a="$back" -v r="$ref" 'BEGIN {printf "%.2f", a / r}') x)"
