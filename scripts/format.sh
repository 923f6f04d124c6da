#!/bin/bash
# The project's C++ laid out by .clang-format (clang-format 14, Debian bookworm's), or with
# --check only said: the files that differ, and exit 1 when there are any.
# Usage: scripts/format.sh [--check] [SOURCE_DIR]
set -euo pipefail

check=0
if [ "${1:-}" = "--check" ]; then
  check=1
  shift
fi
cd "${1:-$(dirname "$0")/..}"

clang_format=$(command -v clang-format-14 || command -v clang-format || true)
if [ -z "$clang_format" ]; then
  echo "format: no clang-format (scripts/setup.sh test installs clang-format-14)" >&2
  exit 2
fi

# The first-party C++: what git tracks, or in a tree without .git every such file outside
# build output and npm's packages.
if [ -d .git ] || git rev-parse --git-dir >/dev/null 2>&1; then
  mapfile -t files < <(git ls-files -- '*.cpp' '*.hpp' '*.h')
else
  mapfile -t files < <(find . \( -path ./build -o -name node_modules \) -prune -o \
    \( -name '*.cpp' -o -name '*.hpp' -o -name '*.h' \) -type f -print | sed 's|^\./||' | sort)
fi

if [ "$check" = 0 ]; then
  "$clang_format" -i --style=file "${files[@]}"
  exit 0
fi
# One process for every file; --ferror-limit=1: a line for each file that differs.
if "$clang_format" --style=file --dry-run -Werror --ferror-limit=1 "${files[@]}" 2>"${TMPDIR:-/tmp}/format-check.$$"; then
  rm -f "${TMPDIR:-/tmp}/format-check.$$"
  exit 0
fi
grep -E '^[^ :]+:[0-9]+:[0-9]+: (error|warning)' "${TMPDIR:-/tmp}/format-check.$$" | cut -d: -f1,2 | sed 's/$/: differs from the layout of .clang-format (scripts\/format.sh lays it out)/'
rm -f "${TMPDIR:-/tmp}/format-check.$$"
exit 1
