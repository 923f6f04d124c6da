#pragma once
// pmu::test_support: the DDS domain of one test process.
//
// exclusive_dds_domain() returns a DDS domain that no other process using this function (or
// tests/support/dds_domain.sh) holds while this process lives. Each domain N is a lock file,
// /tmp/pmu-dds-test-domain-N.lock, taken with flock(LOCK_EX | LOCK_NB) and never released:
// the kernel drops the lock when the process ends, however it ends (even SIGKILL), so a
// crashed test never leaks its domain. ctest runs one process per test, so every test has a
// domain of its own, whatever -j and however many build trees run tests at once.
//
// A domain whose lock is free but on which some participant already listens (UDP discovery
// port 7400 + 250 N bound: an orphaned pmu-service of a killed test, a test of an older tree
// that does not lock) is skipped too.
//
// The range is kFirstDomain..kLastDomain without pmu_bench's 150..229 (bench/driver picks
// four with no Fast DDS shared-memory port, without locks: bench/driver/domain_pick.hpp) and
// without 0 (the default domain, which scripts/run.sh and people use): 1..149 and 230..232
// (232 is the highest domain Fast DDS's default port mapping allows).
//
//   const int domain = pmu::test::exclusive_dds_domain();   // e.g. 37, the same on every call
//   dds::DdsContext dds(domain, "", "my-test");
//
// Aborts with a message when every domain is held (more than 150 DDS test processes at once).

namespace pmu::test {

inline constexpr int kFirstDomain = 1;
inline constexpr int kLastDomain = 232;
inline constexpr int kBenchFirstDomain = 150;  // pmu_bench's, not handed out
inline constexpr int kBenchLastDomain = 229;

// The domain this process holds, taken on the first call.
int exclusive_dds_domain();

}  // namespace pmu::test
