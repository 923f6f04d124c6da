#pragma once
// A DDS domain for this test process that no other test using this function holds: each
// domain is a lock file (/tmp/pmu-dds-test-domain-N.lock) taken with flock() for the rest of
// the process's life, so tests running in parallel (ctest -j, one process per test) never
// share one. The kernel drops the lock when the process ends, however it ends.
#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <cstdlib>
#include <string>

namespace pmu::test {

inline int exclusive_dds_domain() {
  static const int domain = [] {
    // Start at a pid-derived place so concurrent processes rarely contend for the same file.
    const int first = static_cast<int>(::getpid() % 200);
    for (int i = 0; i < 200; ++i) {
      const int d = 20 + (first + i) % 200;  // 20..219
      const std::string path = "/tmp/pmu-dds-test-domain-" + std::to_string(d) + ".lock";
      const int fd = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0666);
      if (fd < 0) continue;
      if (::flock(fd, LOCK_EX | LOCK_NB) == 0) return d;  // fd stays open: the lock is held
      ::close(fd);
    }
    std::abort();  // 200 test processes at once: not a situation these tests create
  }();
  return domain;
}

}  // namespace pmu::test
