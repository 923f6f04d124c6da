#!/usr/bin/env bash
# pmuctl record against pmu-service on the simulated power system: stopped by SIGINT the
# file has a summary, @mcap/core reads it and each schema is its type's own; killed with
# SIGKILL the stream reader still reads its complete chunks; a recorder started late logs the
# state published before it at its start (publish time kept); an unwritable path and a full
# disk are refused with what and where; onto each kind of path (interface.md section 9.1,
# "Where the file goes") nothing record did not create is removed, renamed over or
# truncated; `record -` pipes the file into a reader.
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
# A recorder is stopped once its output holds what is checked, not after a fixed time: when its
# first samples come is up to DDS discovery. Fast DDS 2.9 (RTPSParticipantImpl::enable) sends a
# new participant's first announcement before it listens, so the service's immediate reply can
# be dropped; the recorder then finds the service at the service's next periodic announcement,
# up to 3 s later. The bound only turns "never" into a FAIL line.
#   within SECONDS COMMAND...: COMMAND succeeded before SECONDS passed
within() {
  local end=$((SECONDS + $1))
  shift
  until "$@"; do
    ((SECONDS < end)) || return 1
    sleep 0.5
  done
}
# holds_recording FILE: the complete chunks of FILE (a recorder's temporary file, which it
# flushes every second) hold what check_recording.mjs looks for
holds_recording() {
  local f
  f=$(ls "$1".partial-* 2>/dev/null) && [ -n "$f" ] && read_mcap --stream "$f" >"$work/poll.jsonl" 2>/dev/null &&
    node "$MCAP_TESTS_DIR/check_recording.mjs" "$work/poll.jsonl" --crashed >/dev/null 2>&1
}

# 1. SIGINT: a complete file.
"$ctl" --domain "$domain" record "$work/rec.mcap" 2>"$work/rec.err" &
rec=$!
within 30 holds_recording "$work/rec.mcap" || fail "after 30 s the recording holds no voltages, battery, mppt and health"
kill -INT "$rec"
wait "$rec"; status=$?
[ $status -eq 0 ] || fail "record exited $status: $(cat "$work/rec.err")"
grep -q "messages, .* written to $work/rec.mcap" "$work/rec.err" || fail "no final line: $(cat "$work/rec.err")"
# The size printed is the file's, summary included.
[ "$(grep -o '([0-9]* bytes)' "$work/rec.err")" = "($(stat -c %s "$work/rec.mcap") bytes)" ] ||
  fail "size printed: $(tail -1 "$work/rec.err"), file: $(stat -c %s "$work/rec.mcap")"
if read_mcap "$work/rec.mcap" >"$work/rec.jsonl"; then
  node "$MCAP_TESTS_DIR/check_recording.mjs" "$work/rec.jsonl" || fail "recording (indexed reader)"
  # The 16 default topics' schemas: each its type's definition and what it uses, each once;
  # together about 16 kB (interface.md 9.1).
  node "$MCAP_TESTS_DIR/check_schemas.mjs" "$work/rec.mcap" --max-total 20000 || fail "schemas of the recording"
else
  fail "@mcap/core's indexed reader refused the file"
fi

# 1b. A recording started long after the service published its state: pmu/config and pmu/info
# (TRANSIENT_LOCAL, published at the service's start) come first with that old source time as
# their publish time, but no message is logged before the recording started, so a player's
# timeline begins with the recording.
start_ns=$(date +%s%N)
"$ctl" --domain "$domain" record --topic config --topic info --topic voltages "$work/late.mcap" 2>"$work/late.err" &
rec=$!
late_holds() {
  local f
  f=$(ls "$work"/late.mcap.partial-* 2>/dev/null) && [ -n "$f" ] && read_mcap --stream "$f" >"$work/late_poll.jsonl" 2>/dev/null &&
    grep -q '"pmu/voltages"' "$work/late_poll.jsonl" && grep -q '"pmu/info"' "$work/late_poll.jsonl"
}
within 30 late_holds || fail "after 30 s the late recording holds no voltages and info"
kill -INT "$rec"
wait "$rec" || fail "late record: $(cat "$work/late.err")"
if read_mcap "$work/late.mcap" >"$work/late.jsonl"; then
  node -e '
    const [file, start] = [process.argv[1], BigInt(process.argv[2])];
    const lines = require("fs").readFileSync(file, "utf8").split("\n").filter((l) => l.trim()).map((l) => JSON.parse(l));
    const messages = lines.filter((l) => !l.end);
    const problems = [];
    for (const m of messages) {
      const [log, pub] = [BigInt(m.log_time), BigInt(m.publish_time)];
      if (log < start) problems.push(`${m.topic}: logged at ${log}, before the recording started (${start})`);
      if (pub > log) problems.push(`${m.topic}: published at ${pub}, after its log time ${log}`);
      if (pub < log && log - start > 5000000000n) problems.push(`${m.topic}: log time ${log} is neither its publish time nor the start`);
    }
    for (const topic of ["pmu/config", "pmu/info"]) {
      const state = messages.filter((m) => m.topic === topic);
      if (!state.length) problems.push(`no ${topic}`);
      for (const m of state)
        if (BigInt(m.publish_time) >= start) problems.push(`${topic}: published at ${m.publish_time}, not before the recording`);
    }
    if (problems.length) { console.error(problems.slice(0, 10).join("\n")); process.exit(1); }' \
    "$work/late.jsonl" "$start_ns" || fail "late recording times"
else
  fail "@mcap/core refused the late recording"
fi

# 2. SIGKILL: what a crash leaves is read up to the last complete chunk. It is the temporary
# file; FILE, which existed, is as it was.
echo "an earlier recording" >"$work/crash.mcap"
"$ctl" --domain "$domain" record --topic voltages --topic battery --topic pmu/mppt --topic health "$work/crash.mcap" 2>/dev/null &
rec=$!
within 30 holds_recording "$work/crash.mcap" || fail "after 30 s the recording holds no voltages, battery, mppt and health"
kill -KILL "$rec"
wait "$rec" 2>/dev/null
[ "$(cat "$work/crash.mcap")" = "an earlier recording" ] || fail "a killed recorder changed the file it was to replace"
partial=$(ls "$work"/crash.mcap.partial-* 2>/dev/null)
[ -n "$partial" ] || fail "a killed recorder left no temporary file: $(ls "$work")"
if read_mcap --stream "$partial" >"$work/crash.jsonl"; then
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

# 4. Each kind of path. `kinds` lists what the folder holds (name, type, inode, size): it must
# not change, except the one file a recording is renamed onto.
kinds() { (cd "$1" && find . -mindepth 1 -printf '%p %y %i %s\n' | sort); }
# record_into PATH: a short recording of voltages, stopped by SIGINT; $status, $work/one.err
record_into() {
  "$ctl" --domain "$domain" record --topic voltages "$1" 2>"$work/one.err" &
  local r=$!
  sleep 2.5
  kill -INT "$r"
  wait "$r"; status=$?
}
paths="$work/paths"
mkdir "$paths" "$paths/dir"
echo keep >"$paths/dir/inside"
mkfifo "$paths/fifo"
python3 -c 'import socket, sys; socket.socket(socket.AF_UNIX).bind(sys.argv[1])' "$paths/sock"
ln -s target "$paths/link"
echo "old target" >"$paths/target"
if [ "$(id -u)" -eq 0 ]; then
  mknod "$paths/full" c 1 7 && mknod "$paths/null" c 1 3 && mknod "$paths/block" b 7 0
else
  echo "note: device-node cases skipped: mknod needs root"
fi
before=$(kinds "$paths")
# Refused before any participant (exit 2), or failing at the header (exit 1): nothing changes.
for c in "dir 2 is a directory" "fifo 2 is a FIFO that nobody reads" "sock 2 is a socket" "block 2 is a block device" \
         "full 1 No space left on device"; do
  set -- $c
  name=$1 want=$2 text=${c#* * }
  [ -e "$paths/$name" ] || continue
  # SIGKILL after 20 s: a recorder blocked opening a FIFO ignores SIGTERM (it takes it by sigwait)
  timeout -s KILL 20 "$ctl" --domain "$domain" record "$paths/$name" 2>"$work/err"; status=$?
  [ $status -eq "$want" ] && grep -q "$paths/$name.*$text" "$work/err" || fail "record onto $name: $status $(cat "$work/err")"
  [ "$(kinds "$paths")" = "$before" ] || fail "record onto $name changed $paths: $(kinds "$paths")"
done
# A character device is written in place; it stays the device.
if [ -e "$paths/null" ]; then
  record_into "$paths/null"
  [ $status -eq 0 ] || fail "record onto a character device exited $status: $(cat "$work/one.err")"
  [ "$(kinds "$paths")" = "$before" ] || fail "record onto null changed $paths: $(kinds "$paths")"
fi
# A symlink stays a link; its target gets the recording.
record_into "$paths/link"
[ $status -eq 0 ] && [ -L "$paths/link" ] && [ "$(readlink "$paths/link")" = target ] ||
  fail "record onto a symlink: $status, $(ls -l "$paths/link"), $(cat "$work/one.err")"
read_mcap "$paths/target" >/dev/null || fail "the symlink's target is no recording"
[ "$(kinds "$paths" | grep -v '^./target ')" = "$(echo "$before" | grep -v '^./target ')" ] ||
  fail "record onto a symlink changed $paths: $(kinds "$paths")"
# A FIFO with a reader is written in place, as a stream. The reader's open(2) may come after
# record's: retry while record says nobody reads.
read_mcap --stream - <"$paths/fifo" >"$work/fifo.jsonl" &
reader=$!
for _ in $(seq 100); do
  record_into "$paths/fifo"
  [ $status -eq 2 ] && grep -q "nobody reads" "$work/one.err" || break
done
[ $status -eq 2 ] && kill "$reader"
wait "$reader" || fail "the FIFO's reader refused what it got"
[ $status -eq 0 ] && tail -1 "$work/fifo.jsonl" | grep -q '"footer":true,"complete":true' ||
  fail "record onto a FIFO: $status $(cat "$work/one.err") $(tail -1 "$work/fifo.jsonl")"
[ -p "$paths/fifo" ] || fail "the FIFO is gone: $(ls -l "$paths")"

# 5. `record -`: the file on standard output, piped into @mcap/core's stream reader; status
# lines on stderr. No file named "-". tee keeps a copy, which tells when voltages have come.
( cd "$work" && { "$ctl" --domain "$domain" record --topic voltages - 2>"$work/dash.err" & echo $! >"$work/dash.pid"; wait $!; echo $? >"$work/dash.status"; } ) |
  tee "$work/dash.copy" | read_mcap --stream - >"$work/dash.jsonl" &
pipeline=$!
streamed_voltages() {
  [ -s "$work/dash.pid" ] || return 1
  read_mcap --stream "$work/dash.copy" >"$work/poll.jsonl" 2>/dev/null
  grep -q '"topic":"pmu/voltages"' "$work/poll.jsonl"
}
within 30 streamed_voltages || fail "record -: no voltages after 30 s"
kill -INT "$(cat "$work/dash.pid")"
wait "$pipeline" || fail "the stream reader refused record's standard output: $(cat "$work/dash.err")"
[ "$(cat "$work/dash.status")" = 0 ] || fail "record - exited $(cat "$work/dash.status"): $(cat "$work/dash.err")"
tail -1 "$work/dash.jsonl" | grep -q '"footer":true,"complete":true' || fail "record -: $(tail -1 "$work/dash.jsonl")"
grep -q '"topic":"pmu/voltages"' "$work/dash.jsonl" || fail "record -: no voltages"
grep -q "written to standard output" "$work/dash.err" || fail "record -: $(cat "$work/dash.err")"
[ ! -e "$work/-" ] || fail "record - made a file named -"

# 6. Disk full while recording (root: a small tmpfs, nearly filled).
if [ "$(id -u)" -ne 0 ]; then
  echo "note: disk-full case skipped: mounting a small tmpfs needs root"
else
  # Room for the file's first chunk (its schemas and channels) and a few seconds more. The
  # chunk grows with every topic of the contract, so it is measured: a recording of nothing (a
  # vehicle no service serves) holds it twice (the chunk, and the summary's copy), and little
  # else.
  timeout -s INT 2 "$ctl" --domain "$domain" --vehicle no-such-vehicle record "$work/empty.mcap" 2>/dev/null
  chunk=$(($(stat -c %s "$work/empty.mcap") / 2))
  mkdir "$work/small" && mount -t tmpfs -o size=$(((chunk + 16384 + 12288 + 4095) / 4096 * 4))k tmpfs "$work/small"
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
  # Full before the first chunk: nothing that looks like a recording stays, and record
  # removes nothing but its own temporary file.
  left=$(ls "$work/small")
  "$ctl" --domain "$domain" record "$work/small/start.mcap" 2>"$work/start.err"; status=$?
  [ $status -eq 1 ] && grep -q "No space left on device (disk full)" "$work/start.err" && [ "$(ls "$work/small")" = "$left" ] ||
    fail "record onto a full disk: $status, $(ls "$work/small"), $(cat "$work/start.err")"
fi
[ $failures -eq 0 ] || { tail -n 20 "$work/service.log" >&2; exit 1; }
echo "record: PASS"
