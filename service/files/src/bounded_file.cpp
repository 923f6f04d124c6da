#include "pmu/files/bounded_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace pmu::files {
namespace {

// What a file that is not a regular file is, for the message.
const char* kind_of(mode_t mode) {
  if (S_ISDIR(mode)) return "a directory";
  if (S_ISFIFO(mode)) return "a FIFO";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISSOCK(mode)) return "a socket";
  return "not a file";
}

FileText refused(std::string why, int system_error = 0) { return {{}, std::move(why), system_error}; }
FileText system_refused(int e) { return refused(std::strerror(e), e); }

FileText not_regular(mode_t mode) { return refused(std::string("it is ") + kind_of(mode) + ", not a regular file"); }

FileText too_large(std::size_t max_bytes, std::size_t size) {
  return refused("it is " + size_text(size) + ", larger than the " + size_text(max_bytes) + " bound");
}
FileText grew(std::size_t max_bytes) {
  return refused("it grew past the " + size_text(max_bytes) + " bound while it was read");
}

class Fd {
 public:
  explicit Fd(int fd) noexcept : fd_(fd) {}
  ~Fd() {
    if (fd_ >= 0) ::close(fd_);
  }
  Fd(const Fd&) = delete;
  Fd& operator=(const Fd&) = delete;
  int get() const noexcept { return fd_; }

 private:
  int fd_;
};

}  // namespace

std::string size_text(std::size_t bytes) {
  if (bytes >= (1u << 20) && bytes % (1u << 20) == 0) return std::to_string(bytes >> 20) + " MiB";
  if (bytes >= (1u << 10) && bytes % (1u << 10) == 0) return std::to_string(bytes >> 10) + " KiB";
  return std::to_string(bytes) + (bytes == 1 ? " byte" : " bytes");
}

FileText read_bounded_file(const std::string& path, std::size_t max_bytes) {
  // The type before the open: opening a device can do something of its own (a tape rewinds,
  // a terminal becomes the controlling one), and a FIFO's open would wait for a writer.
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) return system_refused(errno);
  if (!S_ISREG(st.st_mode)) return not_regular(st.st_mode);
  // O_NONBLOCK: the path may have become a FIFO since the stat; its open then returns at
  // once, and fstat says what it is.
  const Fd fd(::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_NOCTTY | O_CLOEXEC));
  if (fd.get() < 0) return system_refused(errno);
  if (::fstat(fd.get(), &st) != 0) return system_refused(errno);
  if (!S_ISREG(st.st_mode)) return not_regular(st.st_mode);
  if (st.st_size < 0 || static_cast<unsigned long long>(st.st_size) > max_bytes)
    return too_large(max_bytes, static_cast<std::size_t>(st.st_size));
  FileText out;
  out.text.resize(static_cast<std::size_t>(st.st_size));
  std::size_t have = 0;
  // Up to one byte past the bound: a file that grew while read is refused, not cut short.
  for (;;) {
    if (have == out.text.size()) {
      if (have > max_bytes) return grew(max_bytes);
      out.text.resize(have + 1 + (max_bytes - have < 4096 ? max_bytes - have : 4096));
    }
    const ssize_t n = ::read(fd.get(), &out.text[have], out.text.size() - have);
    if (n < 0) {
      if (errno == EINTR) continue;
      return system_refused(errno);
    }
    if (n == 0) break;
    have += static_cast<std::size_t>(n);
  }
  if (have > max_bytes) return grew(max_bytes);
  out.text.resize(have);
  return out;
}

}  // namespace pmu::files
