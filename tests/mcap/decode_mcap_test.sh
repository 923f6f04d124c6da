#!/usr/bin/env bash
# pmuctl decode --mcap, read back by @mcap/core and decoded by the omgidl packages, gives the
# values pmuctl decode --json prints, each type with its own schema (check_schemas.mjs), also
# from standard output (-) through a pipe; bad outputs are refused with nothing left behind.
#   decode_mcap_test.sh PMUCTL DATA_DIR
set -euo pipefail
PMUCTL=$1 DATA=$2
. "$(dirname "$0")/mcap_env.sh"
work=$(mktemp -d)
trap 'umount "$work/small" "$work/ro" 2>/dev/null || true; rm -rf "$work"' EXIT

"$PMUCTL" decode --mcap "$work/every.mcap" "$DATA/every_packet.log"
read_mcap "$work/every.mcap" > "$work/indexed.jsonl"
read_mcap --stream "$work/every.mcap" > "$work/stream.jsonl"
"$PMUCTL" decode --json "$DATA/every_packet.log" > "$work/decode.jsonl" 2>/dev/null
node "$MCAP_TESTS_DIR/compare_decode.mjs" "$work/indexed.jsonl" "$work/decode.jsonl"
node "$MCAP_TESTS_DIR/compare_decode.mjs" "$work/stream.jsonl" "$work/decode.jsonl"
# Each schema is its type's definition and what it uses, each once.
node "$MCAP_TESTS_DIR/check_schemas.mjs" "$work/every.mcap"
tail -1 "$work/indexed.jsonl" | grep -q '"statistics":{"message_count":"5"' || { echo "FAIL: summary"; tail -1 "$work/indexed.jsonl"; exit 1; }
schemas=$(grep -o '"schema":"[^"]*"' "$work/indexed.jsonl" | sort -u | tr '\n' ' ')
[ "$schemas" = '"schema":"pmu::v5::BatteryEnergy" "schema":"pmu::v5::Currents" "schema":"pmu::v5::Status" "schema":"pmu::v5::Temperatures" "schema":"pmu::v5::Voltages" ' ] \
  || { echo "FAIL: schema names $schemas"; exit 1; }

# "No reading" (generator rpm 0xFFFF on the wire) is NaN in the sample (docs/interface.md 1.1),
# which omgidl decodes as NaN and JSON prints as null; a reading stays a number.
printf '(1700000000.000000) can0 1E040001#FFFFD08003\n(1700000000.010000) can0 1E040002#0FA0D08003\n' > "$work/rpm.log"
"$PMUCTL" decode --mcap "$work/rpm.mcap" "$work/rpm.log"
read_mcap "$work/rpm.mcap" > "$work/rpm.jsonl"
node -e '
  const lines = require("fs").readFileSync(process.argv[1], "utf8").split("\n").filter(Boolean).map(JSON.parse);
  const rpm = Object.fromEntries(lines.filter((l) => l.topic === "pmu/status").map((l) => [l.values.address, l.values.generator_rpm]));
  if (rpm[1] !== null || rpm[2] !== 4000) { console.error("FAIL: generator_rpm " + JSON.stringify(rpm)); process.exit(1); }
' "$work/rpm.jsonl"

# Undecodable lines are named (FILE:LINE: reason) and the rest is written.
"$PMUCTL" decode --mcap "$work/bad.mcap" "$DATA/bad_lines.log" 2> "$work/err" || { echo "FAIL: bad_lines.log: $(cat "$work/err")"; exit 1; }
grep -q "bad_lines.log:4: unknown packet 0x05 in id 1E050001" "$work/err" || { echo "FAIL: message: $(cat "$work/err")"; exit 1; }
[ "$(read_mcap "$work/bad.mcap" | grep -c '"topic"')" -eq 2 ] || { echo "FAIL: bad_lines.log should give 2 messages"; exit 1; }

# "-": the file on standard output, read from a pipe by both readers; the stderr line gives
# the size the reader got.
"$PMUCTL" decode --mcap - "$DATA/every_packet.log" 2> "$work/err" | read_mcap - > "$work/dash.jsonl" \
  || { echo "FAIL: decode --mcap - | read_mcap -: $(cat "$work/err")"; exit 1; }
node "$MCAP_TESTS_DIR/compare_decode.mjs" "$work/dash.jsonl" "$work/decode.jsonl"
"$PMUCTL" decode --mcap - "$DATA/every_packet.log" 2>/dev/null | read_mcap --stream - > "$work/dash-stream.jsonl"
tail -1 "$work/dash-stream.jsonl" | grep -q '"footer":true,"complete":true' || { echo "FAIL: stream of -"; exit 1; }
size=$("$PMUCTL" decode --mcap - "$DATA/every_packet.log" 2>&1 >/dev/null | grep -o '([0-9]* bytes)')
[ "$size" = "($(stat -c %s "$work/every.mcap") bytes)" ] || { echo "FAIL: size printed $size"; exit 1; }

# An output that cannot be created: named, exit 2, nothing written.
status=0
"$PMUCTL" decode --mcap "$work/no/such/dir/x.mcap" "$DATA/every_packet.log" 2> "$work/err" || status=$?
[ $status -eq 2 ] || { echo "FAIL: decode --mcap into a missing folder exited $status"; exit 1; }
grep -q "cannot create $work/no/such/dir/x.mcap: No such file or directory" "$work/err" \
  || { echo "FAIL: message: $(cat "$work/err")"; exit 1; }

# A folder that cannot be written (a read-only tmpfs, root only): exit 2, named.
if [ "$(id -u)" -eq 0 ]; then
  mkdir "$work/ro" && mount -t tmpfs -o ro tmpfs "$work/ro"
  status=0
  "$PMUCTL" decode --mcap "$work/ro/x.mcap" "$DATA/every_packet.log" 2> "$work/err" || status=$?
  umount "$work/ro"
  [ $status -eq 2 ] && grep -q "cannot create $work/ro/x.mcap: Read-only file system" "$work/err" \
    || { echo "FAIL: read-only folder: $status $(cat "$work/err")"; exit 1; }
fi

# A full disk: a 64 kB tmpfs (root only). The error names the file and the cause, and
# neither OUT nor a partial file remains.
if [ "$(id -u)" -ne 0 ]; then
  echo "note: disk-full case skipped: mounting a small tmpfs needs root"
else
  mkdir "$work/small"
  mount -t tmpfs -o size=64k tmpfs "$work/small"
  for _ in $(seq 400); do cat "$DATA/every_packet.log"; done > "$work/big.log"
  if "$PMUCTL" decode --mcap "$work/small/big.mcap" "$work/big.log" 2> "$work/err"; then
    echo "FAIL: decode --mcap onto a full disk succeeded"; exit 1
  fi
  grep -q "writing $work/small/big.mcap: No space left on device (disk full)" "$work/err" \
    || { echo "FAIL: message: $(cat "$work/err")"; exit 1; }
  grep -q "big.mcap not written" "$work/err" || { echo "FAIL: message: $(cat "$work/err")"; exit 1; }
  [ -z "$(ls -A "$work/small")" ] || { echo "FAIL: left behind: $(ls -A "$work/small")"; exit 1; }
fi
echo "PASS"
