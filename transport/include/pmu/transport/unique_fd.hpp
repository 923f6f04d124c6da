#pragma once
// Owner of one file descriptor. Every fd in transport/ lives in one of these, so no error
// path can leak one and no two owners can close the same number.

#include <utility>

namespace pmu::transport {

class UniqueFd {
 public:
  UniqueFd() noexcept = default;
  explicit UniqueFd(int fd) noexcept : fd_(fd) {}
  ~UniqueFd() { reset(); }

  UniqueFd(const UniqueFd&) = delete;
  UniqueFd& operator=(const UniqueFd&) = delete;
  UniqueFd(UniqueFd&& other) noexcept : fd_(other.release()) {}
  UniqueFd& operator=(UniqueFd&& other) noexcept {
    if (this != &other) reset(other.release());
    return *this;
  }

  int get() const noexcept { return fd_; }
  explicit operator bool() const noexcept { return fd_ >= 0; }
  int release() noexcept { return std::exchange(fd_, -1); }
  // Closes the current fd (errors from close are ignored: the fd is gone either way).
  void reset(int fd = -1) noexcept;

 private:
  int fd_ = -1;
};

}  // namespace pmu::transport
