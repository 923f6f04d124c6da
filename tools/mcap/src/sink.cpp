#include "pmu/mcap/sink.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <utility>

namespace pmu::mcap {

int MemorySink::write(const std::uint8_t* data, std::size_t size) {
  if (bytes.size() + size > capacity) {
    bytes.insert(bytes.end(), data, data + (capacity - bytes.size()));
    return ENOSPC;
  }
  bytes.insert(bytes.end(), data, data + size);
  return 0;
}

int MemorySink::truncate(std::uint64_t size) {
  if (size < bytes.size()) bytes.resize(static_cast<std::size_t>(size));
  return 0;
}

FileSink::~FileSink() {
  if (fd_ >= 0) ::close(fd_);
}

FileSink::FileSink(FileSink&& o) noexcept : fd_(std::exchange(o.fd_, -1)) {}

FileSink& FileSink::operator=(FileSink&& o) noexcept {
  if (this != &o) {
    if (fd_ >= 0) ::close(fd_);
    fd_ = std::exchange(o.fd_, -1);
  }
  return *this;
}

int FileSink::open(const std::string& path) {
  if (fd_ >= 0) ::close(fd_);
  fd_ = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  return fd_ < 0 ? errno : 0;
}

int FileSink::write(const std::uint8_t* data, std::size_t size) {
  if (fd_ < 0) return EBADF;
  while (size > 0) {
    const ssize_t n = ::write(fd_, data, size);
    if (n < 0) {
      if (errno == EINTR) continue;
      return errno;
    }
    data += n;
    size -= static_cast<std::size_t>(n);
  }
  return 0;
}

int FileSink::truncate(std::uint64_t size) {
  if (fd_ < 0) return EBADF;
  if (::ftruncate(fd_, static_cast<off_t>(size)) != 0) return errno;
  return ::lseek(fd_, static_cast<off_t>(size), SEEK_SET) < 0 ? errno : 0;
}

int FileSink::close() {
  if (fd_ < 0) return 0;
  int err = ::fsync(fd_) != 0 && errno != EINVAL ? errno : 0;
  if (::close(fd_) != 0 && err == 0) err = errno;
  fd_ = -1;
  return err;
}

}  // namespace pmu::mcap
