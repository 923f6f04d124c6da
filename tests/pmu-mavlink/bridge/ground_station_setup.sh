# Sourced by the end-to-end scripts of this folder, after they set `src`: the skip when
# Node.js or node-mavlink is missing (exit 77), an exclusive DDS domain ($domain), the QoS
# file, a work folder ($work) removed at exit with every process listed in `pids`, and
# fail(), which counts into $failures.
here="$src/tests/pmu-mavlink/bridge"
if ! command -v node >/dev/null; then echo "SKIP: node is not installed (scripts/setup.sh installs it)"; exit 77; fi
if [ ! -d "$src/tests/mavlink/node_modules/node-mavlink" ]; then
  echo "SKIP: node-mavlink is not installed (scripts/setup.sh runs npm ci in tests/mavlink)"; exit 77
fi
. "$src/tests/support/dds_domain.sh"
pmu_test_dds_domain || exit 1
domain=$PMU_TEST_DDS_DOMAIN
export PMU_QOS_FILE="$src/deploy/qos.xml"
work=$(mktemp -d)
pids=()
trap 'for p in "${pids[@]}"; do kill "$p" 2>/dev/null; done; wait 2>/dev/null; rm -rf "$work"' EXIT
failures=0
fail() { echo "FAIL: $*" >&2; failures=$((failures + 1)); }
