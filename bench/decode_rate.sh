#!/usr/bin/env bash
# Offline decode rate of `pmuctl decode` on a synthetic candump -L log.
#   bench/decode_rate.sh [--frames N] [--pmuctl PATH] [--make-log PATH]
# Prints frames/s for --json and for the table form. A saturated 1 Mbit/s bus carries
# 7,634 8-byte frames/s; the decoder must be far above that.
set -euo pipefail
frames=1000000
here=$(cd "$(dirname "$0")" && pwd)
pmuctl="$here/../build/release/tools/pmuctl"
make_log="$here/../build/release/bench/make_candump_log"
while [ $# -gt 0 ]; do
  case "$1" in
    --frames) frames=$2; shift 2 ;;
    --pmuctl) pmuctl=$2; shift 2 ;;
    --make-log) make_log=$2; shift 2 ;;
    *) echo "decode_rate.sh: unknown option $1" >&2; exit 2 ;;
  esac
done
for tool in "$pmuctl" "$make_log"; do
  [ -x "$tool" ] || { echo "decode_rate.sh: $tool not built (run scripts/test.sh or cmake --build build/release)" >&2; exit 2; }
done
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
"$make_log" "$frames" > "$tmp/log"

rate() {  # rate LABEL ARGS...: runs pmuctl, checks every line came out, prints frames/s
  local label=$1; shift
  local start end out_lines
  start=$(date +%s.%N)
  "$pmuctl" "$@" "$tmp/log" > "$tmp/out" 2>/dev/null
  end=$(date +%s.%N)
  out_lines=$(wc -l < "$tmp/out")
  python3 - "$label" "$frames" "$start" "$end" "$out_lines" <<'PY'
import sys
label, n, start, end, out = sys.argv[1], int(sys.argv[2]), float(sys.argv[3]), float(sys.argv[4]), int(sys.argv[5])
secs = end - start
print(f"| {label} | {n} | {secs:.3f} s | {n/secs:,.0f} frames/s | {n/secs/7634:,.0f}x a saturated bus |")
PY
  if [ "$label" = "decode --json" ] && [ "$out_lines" -ne "$frames" ]; then
    echo "decode_rate.sh: $out_lines output lines for $frames input lines" >&2; exit 1
  fi
}
echo "| mode | frames | time | rate | vs 7,634 frames/s |"
echo "|---|---|---|---|---|"
rate "decode --json" decode --json
rate "decode (table)" decode
