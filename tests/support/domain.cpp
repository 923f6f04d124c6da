#include "domain.hpp"

#include <fcntl.h>
#include <netinet/in.h>
#include <sys/file.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

namespace pmu::test {

namespace {

bool usable(int d) { return d >= kFirstDomain && d <= kLastDomain && (d < kBenchFirstDomain || d > kBenchLastDomain); }

// False when a process outside these locks has a Fast DDS participant on domain `d` (an
// orphaned pmu-service whose test was killed, a test of an older tree): with UDP, every
// participant binds the domain's discovery multicast port 7400 + 250 d with SO_REUSEADDR, so
// a bind without it fails. (A participant on shared memory alone is not seen.)
bool nobody_on(int d) {
  const int s = ::socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  if (s < 0) return true;
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_port = htons(static_cast<std::uint16_t>(7400 + 250 * d));
  a.sin_addr.s_addr = htonl(INADDR_ANY);
  const bool free = ::bind(s, reinterpret_cast<sockaddr*>(&a), sizeof a) == 0;
  ::close(s);
  return free;
}

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
      if (nobody_on(d)) return d;  // fd stays open: the lock stays held
      ::flock(fd, LOCK_UN);        // in use by someone who does not lock: leave it alone
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
