#!/usr/bin/env bash
# pmuctl record against pmu-service on the simulated power system: stopped by SIGINT the
# file has a summary and @mcap/core reads it; killed with SIGKILL the stream reader still
# reads its complete chunks; an unwritable path and a full disk are refused with what and where.
#   record_test.sh PMU-SERVICE PMUCTL SOURCE-DIR
set -uo pipefail
svc=$1 ctl=$2 src=$3
. "$(dirname "$0")/mcap_env.sh"
. "$src/tests/support/dds_domain.sh"
pmu_test_dds_domain || exit 1
domain=$PMU_TEST_DDS_DOMAIN
export PMU_QOS_FILE="$src/deploy/qos.xml"
work=$(mktemp -d)
pid=
trap '[ -n "$pid" ] && kill "$pid" 2>/dev/null; wait 2>/dev/null; umount "$work/small" 2>/dev/null; rm -rf "$work"' EXIT
"$svc" --config "$src/deploy/examples/sim-power-system.yaml" --domain "$domain" >"$work/service.log" 2>&1 &
pid=$!
failures=0
fail() { echo "FAIL: $*" >&2; failures=$((failures + 1)); }

# 1. SIGINT: a complete file.
"$ctl" --domain "$domain" record "$work/rec.mcap" 2>"$work/rec.err" &
rec=$!
sleep 5
kill -INT "$rec"
wait "$rec"; status=$?
[ $status -eq 0 ] || fail "record exited $status: $(cat "$work/rec.err")"
grep -q "messages, .* written to $work/rec.mcap" "$work/rec.err" || fail "no final line: $(cat "$work/rec.err")"
if read_mcap "$work/rec.mcap" >"$work/rec.jsonl"; then
  node "$MCAP_TESTS_DIR/check_recording.mjs" "$work/rec.jsonl" || fail "recording (indexed reader)"
else
  fail "@mcap/core's indexed reader refused the file"
fi

# 2. SIGKILL: what a crash leaves is read up to the last complete chunk.
"$ctl" --domain "$domain" record --topic voltages --topic battery --topic pmu/mppt --topic health "$work/crash.mcap" 2>/dev/null &
rec=$!
sleep 4.5
kill -KILL "$rec"
wait "$rec" 2>/dev/null
if read_mcap --stream "$work/crash.mcap" >"$work/crash.jsonl"; then
  node "$MCAP_TESTS_DIR/check_recording.mjs" "$work/crash.jsonl" --crashed || fail "crashed recording (stream reader)"
else
  fail "@mcap/core's stream reader refused the crashed file"
fi

# 3. Bad input: an unknown topic, a path that cannot be created.
"$ctl" --domain "$domain" record --topic nonsense "$work/x.mcap" 2>"$work/err"; status=$?
[ $status -eq 2 ] && grep -q "topic nonsense is not a topic of the contract" "$work/err" || fail "unknown topic: $status $(cat "$work/err")"
"$ctl" --domain "$domain" record "$work/missing/x.mcap" 2>"$work/err"; status=$?
[ $status -eq 2 ] && grep -q "cannot create $work/missing/x.mcap: No such file or directory" "$work/err" ||
  fail "unwritable path: $status $(cat "$work/err")"

"$ctl" --domain "$domain" --bus sim0 record "$work/x.mcap" 2>"$work/err"; status=$?
[ $status -eq 2 ] && grep -q "bus and --address do not apply" "$work/err" && [ ! -e "$work/x.mcap" ] ||
  fail "--bus: $status $(cat "$work/err")"

# 4. Disk full while recording (root: a small tmpfs, nearly filled).
if [ "$(id -u)" -ne 0 ]; then
  echo "note: disk-full case skipped: mounting a small tmpfs needs root"
else
  mkdir "$work/small" && mount -t tmpfs -o size=64k tmpfs "$work/small"
  # the file's first chunk (schemas and channels) is about 35 kB: room for it and a few seconds more
  head -c 16384 /dev/zero >"$work/small/filler"
  timeout 60 "$ctl" --domain "$domain" record "$work/small/full.mcap" 2>"$work/full.err"; status=$?
  [ $status -eq 1 ] || fail "record on a full disk exited $status: $(cat "$work/full.err")"
  grep -q "writing $work/small/full.mcap: No space left on device (disk full)" "$work/full.err" ||
    fail "disk full message: $(cat "$work/full.err")"
  if read_mcap --stream "$work/small/full.mcap" >"$work/full.jsonl"; then
    grep -q '"footer":true' "$work/full.jsonl" || fail "the full file was not ended"
  else
    fail "the stream reader refused the file the full disk left"
  fi
  # Full before the first chunk: nothing that looks like a recording stays.
  "$ctl" --domain "$domain" record "$work/small/start.mcap" 2>"$work/start.err"; status=$?
  [ $status -eq 1 ] && grep -q "No space left on device (disk full)" "$work/start.err" && [ ! -e "$work/small/start.mcap" ] ||
    fail "record onto a full disk: $status, $(ls "$work/small"), $(cat "$work/start.err")"
fi
[ $failures -eq 0 ] || { tail -n 20 "$work/service.log" >&2; exit 1; }
echo "record: PASS"
