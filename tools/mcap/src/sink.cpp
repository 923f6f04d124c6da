#include "pmu/mcap/sink.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <utility>

namespace pmu::mcap {

int MemorySink::write(const std::uint8_t* data, std::size_t size) {
  const std::size_t room = std::max(capacity, reserved);
  if (bytes.size() + size > room) {
    bytes.insert(bytes.end(), data, data + (room - std::min(room, bytes.size())));
    return ENOSPC;
  }
  bytes.insert(bytes.end(), data, data + size);
  return 0;
}

int MemorySink::truncate(std::uint64_t size) {
  if (size < bytes.size()) bytes.resize(static_cast<std::size_t>(size));
  reserved = std::min(reserved, static_cast<std::size_t>(size));  // as ftruncate(2) frees blocks past the end
  return 0;
}

int MemorySink::reserve(std::uint64_t offset, std::uint64_t length) {
  const std::uint64_t end = offset + length;
  if (end <= reserved) return 0;
  if (end > capacity) return ENOSPC;
  reserved = static_cast<std::size_t>(end);
  return 0;
}

FileSink::~FileSink() {
  if (fd_ >= 0) ::close(fd_);
}

FileSink::FileSink(FileSink&& o) noexcept : fd_(std::exchange(o.fd_, -1)), can_reserve_(o.can_reserve_) {}

FileSink& FileSink::operator=(FileSink&& o) noexcept {
  if (this != &o) {
    if (fd_ >= 0) ::close(fd_);
    fd_ = std::exchange(o.fd_, -1);
    can_reserve_ = o.can_reserve_;
  }
  return *this;
}

int FileSink::open(const std::string& path) {
  if (fd_ >= 0) ::close(fd_);
  fd_ = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  can_reserve_ = true;
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

int FileSink::reserve(std::uint64_t offset, std::uint64_t length) {
  if (fd_ < 0) return EBADF;
  if (!can_reserve_) return 0;
  int r;
  do r = ::fallocate(fd_, FALLOC_FL_KEEP_SIZE, static_cast<off_t>(offset), static_cast<off_t>(length));
  while (r != 0 && errno == EINTR);
  if (r == 0) return 0;
  if (errno == EOPNOTSUPP || errno == ENOSYS) {  // e.g. some FUSE and network file systems
    can_reserve_ = false;
    return 0;
  }
  return errno;
}

int FileSink::close() {
  if (fd_ < 0) return 0;
  int err = ::fsync(fd_) != 0 && errno != EINVAL ? errno : 0;
  if (::close(fd_) != 0 && err == 0) err = errno;
  fd_ = -1;
  return err;
}

}  // namespace pmu::mcap
