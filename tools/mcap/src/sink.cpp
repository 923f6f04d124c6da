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
  if (stream) return ESPIPE;
  if (size < bytes.size()) bytes.resize(static_cast<std::size_t>(size));
  reserved = std::min(reserved, static_cast<std::size_t>(size));  // as ftruncate(2) frees blocks past the end
  return 0;
}

int MemorySink::reserve(std::uint64_t offset, std::uint64_t length) {
  if (stream) return 0;
  const std::uint64_t end = offset + length;
  if (end <= reserved) return 0;
  if (end > capacity) return ENOSPC;
  reserved = static_cast<std::size_t>(end);
  return 0;
}

FileSink::~FileSink() {
  if (fd_ >= 0) ::close(fd_);
}

FileSink::FileSink(FileSink&& o) noexcept : fd_(std::exchange(o.fd_, -1)), own_(o.own_), can_reserve_(o.can_reserve_) {}

FileSink& FileSink::operator=(FileSink&& o) noexcept {
  if (this != &o) {
    if (fd_ >= 0) ::close(fd_);
    fd_ = std::exchange(o.fd_, -1);
    own_ = o.own_;
    can_reserve_ = o.can_reserve_;
  }
  return *this;
}

void FileSink::take(int fd, bool own) {
  if (fd_ >= 0) ::close(fd_);
  fd_ = fd;
  own_ = own;
  can_reserve_ = own;
}

int FileSink::create(const std::string& path) {
  // O_EXCL: a file that exists (or a device, FIFO or symlink of that name) is never truncated.
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
  if (fd < 0) return errno;
  take(fd, true);
  return 0;
}

void FileSink::adopt_own(int fd) { take(fd, true); }

void FileSink::adopt_stream(int fd) { take(fd, false); }

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
  if (!own_) return ESPIPE;  // bytes a stream took are gone; a file not ours is not cut
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
  // EINVAL, EROFS: a pipe or a device, which has nothing to synchronise.
  int err = ::fsync(fd_) != 0 && errno != EINVAL && errno != EROFS ? errno : 0;
  if (::close(fd_) != 0 && err == 0) err = errno;
  fd_ = -1;
  return err;
}

}  // namespace pmu::mcap
