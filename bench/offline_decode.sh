#!/usr/bin/env bash
# Offline decoding benchmark (benchmark issue item 7): `pmuctl decode --json` against the
# decoder a user would write with python-can (bench/python_can_decode.py: Debian's
# python3-can log reader + struct), on the same N-frame candump -L log, in the same run.
#   bench/offline_decode.sh [--frames N] [--runs R] [--pmuctl PATH] [--make-log PATH] [--python PATH]
# First checks that both decoders agree (the first 5,000 lines of the log and
# bench/testdata/all_packets.log, which has every packet, old firmware and bad frames) and
# that the check rejects a corrupted value: a wrong reference would make the ratio
# meaningless. Then times both (wall, user+sys; R alternating runs, default 3, the best
# counts), checks one output line per input line each time, and prints one result row
# (JSON, for bench/report.py) on stdout; progress on stderr.
# Target (bench/README.md): >= 1,000,000 frames/s on the 1,000,000-frame log; the
# python-can reference is there to show the figure is not the machine's alone.
set -euo pipefail
frames=1000000
check_lines=5000
runs=3
here=$(cd "$(dirname "$0")" && pwd)
pmuctl="$here/../build/release/tools/pmuctl"
make_log="$here/../build/release/bench/make_candump_log"
python=""
decoder="$here/python_can_decode.py"
while [ $# -gt 0 ]; do
  case "$1" in
    --frames) frames=$2; shift 2 ;;
    --pmuctl) pmuctl=$2; shift 2 ;;
    --make-log) make_log=$2; shift 2 ;;
    --python) python=$2; shift 2 ;;
    --runs) runs=$2; shift 2 ;;
    *) echo "offline_decode.sh: unknown option $1" >&2; exit 2 ;;
  esac
done
fail() { echo "offline_decode.sh: FAILED: $*" >&2; exit 1; }
say() { echo "offline_decode.sh: $*" >&2; }
[[ $frames =~ ^[1-9][0-9]*$ && $runs =~ ^[1-9][0-9]*$ ]] || { echo "offline_decode.sh: --frames and --runs take a positive number" >&2; exit 2; }
for tool in "$pmuctl" "$make_log"; do
  [ -x "$tool" ] || { echo "offline_decode.sh: $tool not built (cmake --build build/release)" >&2; exit 2; }
done
# Debian's python3-can lives in /usr/bin/python3; a python3 earlier in PATH (pyenv) may lack it.
if [ -z "$python" ]; then
  for p in /usr/bin/python3 python3; do
    if "$p" -c 'import can' 2>/dev/null; then python=$p; break; fi
  done
  [ -n "$python" ] || fail "no python3 with python-can (apt install python3-can), or pass --python"
fi
"$python" -c 'import can' 2>/dev/null || fail "$python cannot import can (python-can)"

tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

say "writing a $frames-frame candump -L log"
"$make_log" "$frames" > "$tmp/frames.log"
[ "$(wc -l < "$tmp/frames.log")" -eq "$frames" ] || fail "make_candump_log wrote the wrong number of lines"

# ---- agreement check ----
check() {  # check LOG LINES: pmuctl's output for LOG vs the reference's, line by line
  "$pmuctl" decode --json "$1" > "$tmp/check.json" 2> "$tmp/check.err" || fail "pmuctl decode: $(cat "$tmp/check.err")"
  "$python" "$decoder" --check "$tmp/check.json" "$1" --lines "$2" ||
    fail "python-can reference and pmuctl decode disagree on $1 (above); the ratio would be meaningless"
}
head -n "$check_lines" "$tmp/frames.log" > "$tmp/head.log"
say "agreement check: first $check_lines lines of the log"
check "$tmp/head.log" "$check_lines"
say "agreement check: bench/testdata/all_packets.log"
check "$here/testdata/all_packets.log" 1000
# The check must catch a wrong value: move the first voltage by 0.1 V and expect a failure.
"$python" - "$tmp/check.json" "$tmp/corrupt.json" <<'PY'
import json, sys
lines = open(sys.argv[1]).read().splitlines()
for i, text in enumerate(lines):
    obj = json.loads(text)
    if obj.get("packet") == "voltages" and "values" in obj:
        obj["values"]["avionics"] += 0.1
        lines[i] = json.dumps(obj)
        break
else:
    sys.exit("offline_decode.sh: no voltages line to corrupt")
open(sys.argv[2], "w").write("\n".join(lines) + "\n")
PY
if "$python" "$decoder" --check "$tmp/corrupt.json" "$here/testdata/all_packets.log" --lines 1000 2> /dev/null; then
  fail "the agreement check accepted a voltage changed by 0.1 V"
fi
say "agreement check: both decoders agree; a 0.1 V difference is caught"

# ---- timing: RUNS alternating runs of each; the best (shortest wall) run of each counts ----
timed() {  # timed NAME OUT CMD...: runs CMD > OUT, appends "wall user sys" seconds to $tmp/NAME.times
  local name=$1 out=$2; shift 2
  local TIMEFORMAT='%R %U %S'
  { time "$@" > "$out" 2> "$tmp/$name.err"; } 2> "$tmp/$name.time" || fail "$name exited non-zero: $(tail -n 5 "$tmp/$name.err")"
  local lines
  lines=$(wc -l < "$out")
  [ "$lines" -eq "$frames" ] || fail "$name printed $lines lines for $frames input lines"
  cat "$tmp/$name.time" >> "$tmp/$name.times"
  say "  $name: $(cat "$tmp/$name.time") s (wall user sys), $lines lines"
}
for run in $(seq 1 "$runs"); do
  say "timing run $run of $runs"
  timed pmuctl "$tmp/pmuctl.json" "$pmuctl" decode --json "$tmp/frames.log"
  # As a user would run it: block-buffered stdout (PYTHONUNBUFFERED, if set, costs ~15 %).
  timed python "$tmp/python.json" env -u PYTHONUNBUFFERED "$python" "$decoder" "$tmp/frames.log"
done

# ---- result row ----
"$python" - "$frames" "$tmp/pmuctl.times" "$tmp/python.times" <<'PY'
import json, platform, sys
import can
frames = int(sys.argv[1])
pm_runs, py_runs = ([tuple(map(float, line.split())) for line in open(path)] for path in sys.argv[2:4])
(pm_wall, pm_user, pm_sys), (py_wall, py_user, py_sys) = min(pm_runs), min(py_runs)
pm_rate, py_rate = frames / pm_wall, frames / py_wall
walls = lambda runs: ", ".join(f"{r[0]:.2f}" for r in runs)
print(json.dumps({
    "benchmark": f"offline decode, {frames:,}-frame candump -L log (pmuctl decode --json)",
    "value": round(pm_rate, 1), "unit": "frames/s",
    "reference": round(py_rate, 1),
    "reference_name": f"python-can {can.__version__} reader + struct",
    "ratio": round(pm_rate / py_rate, 2), "target": ">= 1,000,000 frames/s",
    "met": pm_rate >= 1_000_000 if frames >= 1_000_000 else None,
    "note": (f"Best wall time of {len(pm_runs)} alternating runs each, start-up included, JSON lines written "
             f"to a file: pmuctl {pm_wall:.2f} s (user+sys {pm_user + pm_sys:.2f} s; runs {walls(pm_runs)} s), "
             f"bench/python_can_decode.py on Python {platform.python_version()} {py_wall:.2f} s "
             f"(user+sys {py_user + py_sys:.2f} s; runs {walls(py_runs)} s). Both decoders were checked "
             "to agree before timing."),
}))
PY
