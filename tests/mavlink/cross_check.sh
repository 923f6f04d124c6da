#!/usr/bin/env bash
# pmu::mavlink against node-mavlink, both ways: the frames mavlink_cross_frames writes are
# read by node-mavlink (ids, lengths, CRCs, CRC_EXTRA, signatures, field values), and the
# frames node-mavlink writes are read by mavlink_cross_frames. Exit 77 (ctest: skipped) with
# the reason when Node.js or the npm package (scripts/setup.sh: npm ci in tests/mavlink) is
# missing.
#   cross_check.sh MAVLINK_CROSS_FRAMES
set -euo pipefail
tool=$1
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
if ! command -v node >/dev/null; then
  echo "SKIP: node is not installed (scripts/setup.sh installs it)"; exit 77
fi
if [ ! -d "$here/node_modules/node-mavlink" ]; then
  echo "SKIP: node-mavlink is not installed (scripts/setup.sh runs npm ci in tests/mavlink)"; exit 77
fi
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
# A 32-byte key, the same on both sides.
key=000102030405060708090a0b0c0d0e0f101112131415161718191a1b1c1d1e1f

"$tool" write "$key" >"$work/ours.jsonl"
node "$here/cross_check.mjs" decode "$key" "$work/ours.jsonl"

node "$here/cross_check.mjs" encode "$key" >"$work/theirs.jsonl"
"$tool" read "$key" "$work/theirs.jsonl"
