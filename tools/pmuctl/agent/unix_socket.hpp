#pragma once
// The few socket calls between pmuctl and its agent: a Unix SOCK_SEQPACKET socket, one
// message per call each way, file descriptors passed with SCM_RIGHTS. Plain POSIX, no
// exceptions; errno says why a call failed.
// Threads: any; each function uses only its arguments.

#include <string>
#include <vector>

namespace pmu::tools {

// An owned file descriptor, closed when it goes.
class UniqueFd {
 public:
  UniqueFd() = default;
  explicit UniqueFd(int fd) : fd_(fd) {}
  ~UniqueFd() { reset(); }
  UniqueFd(UniqueFd&& o) noexcept : fd_(o.release()) {}
  UniqueFd& operator=(UniqueFd&& o) noexcept {
    if (this != &o) {
      reset();
      fd_ = o.release();
    }
    return *this;
  }
  int get() const noexcept { return fd_; }
  explicit operator bool() const noexcept { return fd_ >= 0; }
  int release() noexcept {
    const int fd = fd_;
    fd_ = -1;
    return fd;
  }
  void reset() noexcept;

 private:
  int fd_ = -1;
};

// A connected socket, or an empty one when nothing listens at `path`.
UniqueFd connect_unix(const std::string& path);
// One message with `fds` attached. False on failure.
bool send_with_fds(int socket, const std::string& bytes, const std::vector<int>& fds);
// One message of at most 64 KiB, and the descriptors that came with it (owned by the caller
// afterwards). False when the peer closed, the message was cut or it failed.
bool receive(int socket, std::string& bytes, std::vector<UniqueFd>* fds = nullptr);

}  // namespace pmu::tools
