#!/usr/bin/env bash
# Test of the report path (ctest bench_smoke_report): a brief real codec_bench run through
# bench/codec_rows.py, plus the fixed rows of bench/testdata/rows.jsonl, through
# bench/report.py; checks the header, one table row per input row in order, the results,
# the footnotes, and that a malformed row fails.
#   bench/report_smoke.sh CODEC_BENCH
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
codec_bench=${1:?usage: report_smoke.sh CODEC_BENCH}
fail() { echo "report_smoke.sh: FAILED: $*" >&2; exit 1; }
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

"$codec_bench" --benchmark_min_time=0.01 --benchmark_format=json > "$tmp/codec.json" 2> /dev/null
python3 "$here/codec_rows.py" "$tmp/codec.json" > "$tmp/codec.rows"
for title in "decode one PMU frame" "encode one PMU frame" "parse one candump -L line"; do
  grep -q "\"codec: $title\"" "$tmp/codec.rows" || fail "codec_rows.py gave no \"$title\" row"
done
python3 "$here/report.py" "$here/testdata/rows.jsonl" "$tmp/codec.rows" > "$tmp/report.md"
cat "$tmp/report.md"

want_header='| benchmark | pmu-dds | reference (same run) | ratio | target | result |'
[ "$(sed -n 1p "$tmp/report.md")" = "$want_header" ] || fail "wrong header"
[ "$(sed -n 2p "$tmp/report.md")" = '|---|---|---|---|---|---|' ] || fail "wrong separator line"
rows_in=$(cat "$here/testdata/rows.jsonl" "$tmp/codec.rows" | grep -c .)
rows_out=$(sed -n '3,$p' "$tmp/report.md" | grep -c '^| ')
[ "$rows_out" -eq "$rows_in" ] || fail "$rows_out table rows for $rows_in input rows"
sed -n 4p "$tmp/report.md" | grep -qF '| 85.2 µs | 70.1 µs (candump -> UDP socket) | 1.22 | ratio <= 1.25 | met |' ||
  fail "row 2 of rows.jsonl is not formatted as expected"
grep -qF '| 268,801 frames/s | 52,000 frames/s (python-can reader + struct) | 5.17 |  |  |' "$tmp/report.md" ||
  fail "frames/s row not formatted as expected"
[ "$(grep -c '| MISSED |$' "$tmp/report.md")" -eq 1 ] || fail "expected exactly one MISSED"
[ "$(grep -c '| met |$' "$tmp/report.md")" -eq 2 ] || fail "expected exactly two met"
notes_in=$(cat "$here/testdata/rows.jsonl" "$tmp/codec.rows" | grep -c '"note": "[^"]')
notes_out=$(grep -c '^[0-9]*\. ' "$tmp/report.md")
[ "$notes_out" -eq "$notes_in" ] || fail "$notes_out footnotes for $notes_in notes"
if echo '{"value": 1}' | python3 "$here/report.py" > /dev/null 2>&1; then fail "report.py accepted a row without a benchmark"; fi
echo "report_smoke.sh: ok ($rows_out rows, $notes_out notes)"
