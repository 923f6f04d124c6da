#include "pmu/transport/unique_fd.hpp"

#include <unistd.h>

namespace pmu::transport {

void UniqueFd::reset(int fd) noexcept {
  // Never retry close on EINTR: on Linux the fd is released even then, and a retry could
  // close an fd another thread just received.
  if (fd_ >= 0) ::close(fd_);
  fd_ = fd;
}

}  // namespace pmu::transport
