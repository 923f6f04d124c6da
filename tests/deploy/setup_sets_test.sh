#!/bin/bash
# setup_sets_test.sh REPO_ROOT
#
# Checks the two install sets of scripts/setup.sh and what a plain configure needs:
#   1. bad arguments exit 2 with the usage; --list run and --list test print one package a
#      line, and the run set is a subset of the test set;
#   2. every package of both sets exists in Debian's archive for this machine (apt-cache show,
#      nothing installed); a package of a foreign architecture that dpkg is not set up for
#      (arm64 before scripts/setup.sh test adds it) is looked up for this architecture;
#   3. a plain `cmake -S . -B DIR` (no options) turns tests and benchmarks off and looks for
#      none of GTest, Google Benchmark or Cyclone DDS: the run set is enough for it.
# Exits 77 (skipped) when apt has no package lists, after checks 1 and 3 passed.

set -euo pipefail

if [ $# -ne 1 ]; then
  echo "usage: $0 REPO_ROOT" >&2
  exit 2
fi
repo=$(cd "$1" && pwd)
setup="$repo/scripts/setup.sh"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }

# 1. Arguments and the two lists.
for args in "bogus" "--list" "--list bogus" "run test" "--list run extra"; do
  # shellcheck disable=SC2086 # the cases are word lists
  if "$setup" $args >"$work/out" 2>"$work/err"; then status=0; else status=$?; fi
  [ "$status" -eq 2 ] || fail "setup.sh $args: exit $status, expected 2"
  grep -q '^usage: ' "$work/err" || fail "setup.sh $args: no usage on stderr: $(cat "$work/err")"
  [ ! -s "$work/out" ] || fail "setup.sh $args: printed on stdout: $(cat "$work/out")"
done
for set in run test; do
  "$setup" --list "$set" >"$work/$set" || fail "setup.sh --list $set: exit $?"
  [ -s "$work/$set" ] || fail "setup.sh --list $set printed nothing"
  if grep -vqE '^[a-z0-9][a-z0-9+.-]+(:[a-z0-9]+)?$' "$work/$set"; then
    fail "setup.sh --list $set: not one package name a line: $(grep -vE '^[a-z0-9][a-z0-9+.-]+(:[a-z0-9]+)?$' "$work/$set" | head -n3)"
  fi
  dups=$(sort "$work/$set" | uniq -d)
  [ -z "$dups" ] || fail "setup.sh --list $set names twice: $dups"
done
not_in_test=$(sort -u "$work/run" | comm -23 - <(sort -u "$work/test"))
[ -z "$not_in_test" ] || fail "in the run set but not in the test set: $not_in_test"
echo "ok: run set ($(wc -l <"$work/run") packages) within the test set ($(wc -l <"$work/test"))"

# 3. A plain configure (before 2, which may skip).
if ! cmake -S "$repo" -B "$work/plain" >"$work/configure.log" 2>&1; then
  cat "$work/configure.log" >&2
  fail "plain cmake -S $repo -B DIR failed"
fi
cache="$work/plain/CMakeCache.txt"
for option in PMU_BUILD_TESTS PMU_BUILD_BENCH; do
  grep -qx "$option:BOOL=OFF" "$cache" || fail "plain configure: $(grep "^$option:" "$cache" || echo "$option unset"), expected OFF"
done
for var in GTest_DIR benchmark_DIR CycloneDDS_DIR GTEST_INCLUDE_DIR; do
  if grep -q "^$var:" "$cache"; then fail "plain configure looked for a test dependency: $(grep "^$var:" "$cache")"; fi
done
echo "ok: a plain configure has tests and benchmarks off and looks for no GTest, benchmark or CycloneDDS"

# 2. Every package in Debian's archive.
if ! compgen -G '/var/lib/apt/lists/*_Packages*' >/dev/null; then
  echo "SKIP: apt has no package lists (run apt-get update): the packages' existence is not checked"
  exit 77
fi
# One apt-cache call (each one reads every package list): it prints the packages it found
# and passes over the others, so the missing ones are the names its output lacks.
foreign=$(dpkg --print-foreign-architectures)
names=()
while read -r pkg; do
  arch=${pkg#*:}
  if [ "$arch" != "$pkg" ] && ! grep -qx "$arch" <<<"$foreign"; then pkg=${pkg%%:*}; fi
  names+=("$pkg")
done < <(sort -u "$work/run" "$work/test")
apt-cache show --no-all-versions "${names[@]}" 2>/dev/null |
  awk '/^Package: / {p = $2} /^Architecture: / {print p; print p ":" $2}' | sort -u >"$work/found" || true
missing=$(printf '%s\n' "${names[@]}" | sort -u | comm -23 - "$work/found")
[ -z "$missing" ] || fail "not in this machine's Debian archive (apt-cache show): $(tr '\n' ' ' <<<"$missing")"
echo "ok: all ${#names[@]} packages exist in the archive"
