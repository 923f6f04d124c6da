#include "domain.hpp"

#include "udp_ports.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <string>

namespace pmu::test {

namespace {

bool usable(int d) { return d >= kFirstDomain && d <= kLastDomain && (d < kBenchFirstDomain || d > kBenchLastDomain); }

int take_one() {
  constexpr int span = kLastDomain - kFirstDomain + 1;
  // Start at a pid-derived place so that concurrent processes rarely try the same file first.
  const int first = static_cast<int>(::getpid() % span);
  for (int i = 0; i < span; ++i) {
    const int d = kFirstDomain + (first + i) % span;
    if (!usable(d)) continue;
    const std::string path = "/tmp/pmu-dds-test-domain-" + std::to_string(d) + ".lock";
    const int fd = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0666);
    if (fd < 0) continue;
    if (::flock(fd, LOCK_EX | LOCK_NB) == 0) {
      if (dds_discovery_port_free(d)) return d;  // fd stays open: the lock stays held
      ::flock(fd, LOCK_UN);                      // in use by someone who does not lock: leave it alone
    }
    ::close(fd);
  }
  std::fprintf(stderr, "pmu::test::exclusive_dds_domain: every test DDS domain is held by another process\n");
  std::abort();
}

}  // namespace

int exclusive_dds_domain() {
  static const int domain = take_one();
  return domain;
}

}  // namespace pmu::test
