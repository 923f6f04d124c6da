# Sourced by shell-driven tests: the shell side of tests/support/domain.hpp.
#
#   . "$(dirname "${BASH_SOURCE[0]}")/../support/dds_domain.sh"
#   pmu_test_dds_domain || exit 1      # sets PMU_TEST_DDS_DOMAIN, holds its lock on fd 9
#   pmu-service --domain "$PMU_TEST_DDS_DOMAIN" ...
#
# Takes the same lock files as exclusive_dds_domain() (/tmp/pmu-dds-test-domain-N.lock, flock
# on fd 9 of this shell) over the same range (1..149 and 230..232; 150..229 are pmu_bench's),
# and holds the lock until the shell exits. Children inherit fd 9, so the lock also lives as
# long as any child started meanwhile: the domain is not handed out while one still runs.
pmu_test_dds_domain() {
  local span=232 i d
  for ((i = 0; i < span; i++)); do
    d=$((1 + ($$ + i) % span))
    if ((d >= 150 && d <= 229)); then continue; fi
    exec 9>>"/tmp/pmu-dds-test-domain-$d.lock" || continue
    if flock -n 9; then
      # Skipped when a participant outside the locks already listens on its discovery port
      # (as domain.cpp does).
      if ! command -v ss >/dev/null || [ -z "$(ss -Huln "sport = :$((7400 + 250 * d))" 2>/dev/null)" ]; then
        PMU_TEST_DDS_DOMAIN=$d
        return 0
      fi
      flock -u 9
    fi
    exec 9>&-
  done
  echo "pmu_test_dds_domain: every test DDS domain is held by another process" >&2
  return 1
}
