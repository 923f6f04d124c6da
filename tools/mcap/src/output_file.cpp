#include "pmu/mcap/output_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <climits>
#include <cstring>
#include <utility>
#include <vector>

namespace pmu::mcap {
namespace {

std::string with_errno(const std::string& what, int e) { return what + ": " + std::strerror(e); }

// Where a chain of symlinks ends (`path` itself when it is no link), or "" and `error`. The
// end need not exist: a dangling link names the file to create, as a shell's `>` does.
std::string follow_links(std::string path, std::string& error) {
  for (int hops = 0; hops < 40; ++hops) {  // the kernel's own limit before ELOOP
    struct stat st {};
    if (::lstat(path.c_str(), &st) != 0) {
      if (errno == ENOENT) return path;
      error = with_errno("cannot create " + path, errno);
      return {};
    }
    if (!S_ISLNK(st.st_mode)) return path;
    std::vector<char> buf(PATH_MAX);
    const ssize_t n = ::readlink(path.c_str(), buf.data(), buf.size());
    if (n <= 0 || static_cast<std::size_t>(n) >= buf.size()) {
      error = with_errno("cannot follow the symlink " + path, n < 0 ? errno : ENAMETOOLONG);
      return {};
    }
    std::string to(buf.data(), static_cast<std::size_t>(n));
    if (to.front() != '/') {  // relative to the folder that holds the link
      const auto slash = path.rfind('/');
      if (slash != std::string::npos) to = path.substr(0, slash + 1) + to;
    }
    path = std::move(to);
  }
  error = with_errno("cannot follow the symlink " + path, ELOOP);
  return {};
}

}  // namespace

OutputFile::~OutputFile() {
  sink_.close();
  if (temporary_ && !keep_) ::unlink(writing_.c_str());
}

OutputFile::OutputFile(OutputFile&& o) noexcept
    : sink_(std::move(o.sink_)),
      kind_(std::exchange(o.kind_, Kind::None)),
      name_(std::move(o.name_)),
      target_(std::move(o.target_)),
      writing_(std::move(o.writing_)),
      temporary_(std::exchange(o.temporary_, false)),
      keep_(o.keep_) {}

OutputFile& OutputFile::operator=(OutputFile&& o) noexcept {
  if (this != &o) {
    sink_.close();
    if (temporary_ && !keep_) ::unlink(writing_.c_str());
    sink_ = std::move(o.sink_);
    kind_ = std::exchange(o.kind_, Kind::None);
    name_ = std::move(o.name_);
    target_ = std::move(o.target_);
    writing_ = std::move(o.writing_);
    temporary_ = std::exchange(o.temporary_, false);
    keep_ = o.keep_;
  }
  return *this;
}

std::string OutputFile::shown() const { return target_ == name_ ? name_ : name_ + " (-> " + target_ + ")"; }

std::string OutputFile::open(const std::string& path) {
  if (kind_ != Kind::None) return "an output is open already";
  name_ = target_ = path == "-" ? "standard output" : path;
  if (path == "-") {
    if (::isatty(STDOUT_FILENO) == 1) return "standard output is a terminal: redirect it to a file or a pipe";
    const int fd = ::fcntl(STDOUT_FILENO, F_DUPFD_CLOEXEC, 0);
    if (fd < 0) return with_errno("standard output", errno);
    sink_.adopt_stream(fd);
    kind_ = Kind::Stream;
    writing_ = name_;
    return {};
  }
  if (path.empty()) return "an empty path names no file";
  std::string error;
  target_ = follow_links(path, error);
  if (!error.empty()) return error;
  struct stat st {};
  if (::stat(target_.c_str(), &st) != 0) {
    if (errno != ENOENT) return with_errno("cannot create " + shown(), errno);
    return open_replacement(nullptr);
  }
  switch (st.st_mode & S_IFMT) {
    case S_IFREG: return open_replacement(&st);
    case S_IFIFO: return open_stream(true);
    case S_IFCHR: return open_stream(false);
    case S_IFDIR: return shown() + " is a directory: name a file in it";
    case S_IFBLK:
      return shown() + " is a block device: writing it would overwrite the file system it holds; name a file on it";
    case S_IFSOCK:
      return shown() +
             " is a socket, which open(2) cannot write: write to standard output (-) and pipe that "
             "into the socket (socat - UNIX-CONNECT:PATH)";
    default: return shown() + " is not a file, FIFO or character device";
  }
}

std::string OutputFile::open_replacement(const struct stat* replaced) {
  // The replacement gets the permissions (and, where allowed, the owner) of the file it
  // replaces; one the user could not write is not replaced behind its owner's back.
  if (replaced && ::access(target_.c_str(), W_OK) != 0) return with_errno("cannot write " + shown(), errno);
  std::string name = target_ + ".partial-XXXXXX";
  std::vector<char> buf(name.begin(), name.end());
  buf.push_back('\0');
  const int fd = ::mkostemp(buf.data(), O_CLOEXEC);  // O_EXCL: nothing that exists is reused
  if (fd < 0) return with_errno("cannot create " + shown(), errno);
  mode_t mode;
  if (replaced) {
    mode = replaced->st_mode & 0777;
    (void)::fchown(fd, replaced->st_uid, replaced->st_gid);  // EPERM unless root: then the user's own
  } else {
    const mode_t mask = ::umask(0);  // mkostemp makes 0600; a new file gets what open(2) would give
    ::umask(mask);
    mode = 0666 & ~mask;
  }
  (void)::fchmod(fd, mode);  // after fchown, which may clear set-id bits; failing leaves 0600: stricter
  sink_.adopt_own(fd);
  kind_ = Kind::Replace;
  writing_ = buf.data();
  temporary_ = true;
  keep_ = false;
  return {};
}

std::string OutputFile::open_stream(bool fifo) {
  // O_NONBLOCK: a FIFO without a reader is refused at once (ENXIO) rather than waited for,
  // which SIGINT could not interrupt (record blocks it). No O_CREAT, no O_TRUNC.
  const int fd = ::open(target_.c_str(), O_WRONLY | O_NOCTTY | O_CLOEXEC | O_NONBLOCK);
  if (fd < 0) {
    if (fifo && errno == ENXIO) return shown() + " is a FIFO that nobody reads: start its reader first";
    return with_errno("cannot open " + shown(), errno);
  }
  struct stat st {};
  const bool same_kind = ::fstat(fd, &st) == 0 && (fifo ? S_ISFIFO(st.st_mode) : S_ISCHR(st.st_mode));
  const bool tty = ::isatty(fd) == 1;
  if (!same_kind || tty) {
    ::close(fd);
    return tty ? shown() + " is a terminal: name a file, a FIFO or a pipe"
               : shown() + " was replaced while being opened";
  }
  if (const int flags = ::fcntl(fd, F_GETFL); flags >= 0) ::fcntl(fd, F_SETFL, flags & ~O_NONBLOCK);
  sink_.adopt_stream(fd);
  kind_ = Kind::Stream;
  writing_ = target_;
  return {};
}

int OutputFile::close() { return sink_.close(); }

std::string OutputFile::commit() {
  if (kind_ != Kind::Replace || !temporary_) return {};
  if (sink_.is_open()) {
    if (const int e = close(); e != 0) {
      keep_ = true;
      return with_errno("closing " + writing_, e) + "; the file stays as " + writing_;
    }
  }
  // What took the target's name meanwhile is not renamed over unless it is a regular file.
  struct stat st {};
  if (::lstat(target_.c_str(), &st) == 0 && !S_ISREG(st.st_mode)) {
    keep_ = true;
    return shown() + " is no longer a regular file; the file stays as " + writing_;
  }
  if (::rename(writing_.c_str(), target_.c_str()) != 0) {
    keep_ = true;
    return with_errno("cannot rename " + writing_ + " to " + shown(), errno) + "; the file stays as " + writing_;
  }
  temporary_ = false;
  writing_ = target_;
  return {};
}

void OutputFile::discard() {
  sink_.close();
  if (temporary_) ::unlink(writing_.c_str());
  temporary_ = false;
}

}  // namespace pmu::mcap
