# Sourced by the MCAP tests: exit 77 (ctest: skipped) with a reason when Node.js or the
# npm packages (scripts/setup.sh: npm ci in tests/mcap) are missing.
MCAP_TESTS_DIR="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
if ! command -v node >/dev/null; then
  echo "SKIP: node is not installed (scripts/setup.sh installs it)"; exit 77
fi
if [ ! -d "$MCAP_TESTS_DIR/node_modules/@mcap/core" ] || [ ! -d "$MCAP_TESTS_DIR/node_modules/@foxglove/omgidl-serialization" ]; then
  echo "SKIP: the npm packages of tests/mcap are not installed (scripts/setup.sh runs npm ci there)"; exit 77
fi
read_mcap() { node "$MCAP_TESTS_DIR/read_mcap.mjs" "$@"; }
