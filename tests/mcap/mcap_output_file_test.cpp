// pmu::mcap::OutputFile (tools/mcap/include/pmu/mcap/output_file.hpp), for each kind of path
// docs/interface.md section 9.1 names: what is written where, and that nothing the output did
// not create is removed, renamed over or truncated, whether it commits, discards or is
// dropped. Device nodes are made with mknod(2) in a temporary folder (root only: those rows
// are skipped otherwise, with the reason).

#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <sys/un.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <dirent.h>
#include <functional>
#include <map>
#include <string>

#include "pmu/mcap/output_file.hpp"

namespace {

struct Entry {
  mode_t type = 0;
  ino_t inode = 0;
  std::string content;  // regular files
  bool operator==(const Entry& o) const { return type == o.type && inode == o.inode && content == o.content; }
};
using Snapshot = std::map<std::string, Entry>;

std::string read_file(const std::string& path) {
  std::string s;
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return "<unreadable>";
  char buf[4096];
  ssize_t n;
  while ((n = ::read(fd, buf, sizeof buf)) > 0) s.append(buf, static_cast<std::size_t>(n));
  ::close(fd);
  return s;
}

// Every entry of `dir` (not following links), recursively enough for these layouts.
Snapshot snapshot(const std::string& dir) {
  Snapshot s;
  DIR* d = ::opendir(dir.c_str());
  if (!d) return s;
  while (const dirent* e = ::readdir(d)) {
    const std::string name = e->d_name;
    if (name == "." || name == "..") continue;
    const std::string path = dir + "/" + name;
    struct stat st {};
    if (::lstat(path.c_str(), &st) != 0) continue;
    Entry en{static_cast<mode_t>(st.st_mode & S_IFMT), st.st_ino, S_ISREG(st.st_mode) ? read_file(path) : ""};
    s[name] = en;
    if (S_ISDIR(st.st_mode))
      for (const auto& [sub, se] : snapshot(path)) s[name + "/" + sub] = se;
  }
  ::closedir(d);
  return s;
}

std::string describe(const Snapshot& s) {
  std::string out;
  for (const auto& [name, e] : s)
    out +=
        name + "(type " + std::to_string(e.type) + ", inode " + std::to_string(e.inode) + ", \"" + e.content + "\") ";
  return out;
}

class TempDir {
 public:
  TempDir() {
    char t[] = "/tmp/mcap-output-XXXXXX";
    path = ::mkdtemp(t);
  }
  ~TempDir() { std::system(("rm -rf '" + path + "'").c_str()); }
  std::string path;
};

// A FIFO reader the test holds open, so that the FIFO "has a reader".
struct FifoReader {
  int fd = -1;
  ~FifoReader() {
    if (fd >= 0) ::close(fd);
  }
};

void write_file(const std::string& path, const std::string& text) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
  ASSERT_GE(fd, 0) << path;
  ASSERT_EQ(::write(fd, text.data(), text.size()), static_cast<ssize_t>(text.size()));
  ::close(fd);
}

void make_socket(const std::string& path) {
  const int fd = ::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
  ASSERT_GE(fd, 0);
  sockaddr_un a{};
  a.sun_family = AF_UNIX;
  std::strncpy(a.sun_path, path.c_str(), sizeof a.sun_path - 1);
  ASSERT_EQ(::bind(fd, reinterpret_cast<const sockaddr*>(&a), sizeof a), 0) << std::strerror(errno);
  ::close(fd);
}

enum class Then { Replaced, Streamed, StreamFull, Refused };

struct Case {
  const char* kind;
  bool root;                                                             // needs root (mknod of a device)
  std::function<void(const std::string& dir, FifoReader& reader)> make;  // makes dir/out
  const char* path;                                                      // relative to dir
  Then then;
  const char* written;  // the file that gets the bytes (Replaced), relative to dir
  const char* refusal;  // part of open()'s message (Refused)
};

const std::string kOld = "the operator's own bytes";
const std::string kNew = "\x89MCAP0\r\n and the rest";

// docs/interface.md section 9.1, "Where the file goes": one row per kind of path.
const Case kCases[] = {
    {"missing file", false, [](const std::string&, FifoReader&) {}, "out", Then::Replaced, "out", ""},
    {"regular file", false, [](const std::string& d, FifoReader&) { write_file(d + "/out", kOld); }, "out",
     Then::Replaced, "out", ""},
    {"symlink to a regular file", false,
     [](const std::string& d, FifoReader&) {
       ::mkdir((d + "/data").c_str(), 0755);
       write_file(d + "/data/target", kOld);
       ASSERT_EQ(::symlink("data/target", (d + "/out").c_str()), 0);
     },
     "out", Then::Replaced, "data/target", ""},
    {"chain of symlinks", false,
     [](const std::string& d, FifoReader&) {
       write_file(d + "/target", kOld);
       ASSERT_EQ(::symlink((d + "/target").c_str(), (d + "/middle").c_str()), 0);  // absolute
       ASSERT_EQ(::symlink("middle", (d + "/out").c_str()), 0);
     },
     "out", Then::Replaced, "target", ""},
    {"dangling symlink", false,
     [](const std::string& d, FifoReader&) { ASSERT_EQ(::symlink("target", (d + "/out").c_str()), 0); }, "out",
     Then::Replaced, "target", ""},
    {"FIFO with a reader", false,
     [](const std::string& d, FifoReader& r) {
       ASSERT_EQ(::mkfifo((d + "/out").c_str(), 0644), 0);
       r.fd = ::open((d + "/out").c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
       ASSERT_GE(r.fd, 0);
     },
     "out", Then::Streamed, "", ""},
    {"FIFO without a reader", false,
     [](const std::string& d, FifoReader&) { ASSERT_EQ(::mkfifo((d + "/out").c_str(), 0644), 0); }, "out",
     Then::Refused, "", "out is a FIFO that nobody reads"},
    {"character device (null)", true,
     [](const std::string& d, FifoReader&) {
       ASSERT_EQ(::mknod((d + "/out").c_str(), S_IFCHR | 0666, makedev(1, 3)), 0);
     },
     "out", Then::Streamed, "", ""},
    {"character device (full)", true,
     [](const std::string& d, FifoReader&) {
       ASSERT_EQ(::mknod((d + "/out").c_str(), S_IFCHR | 0666, makedev(1, 7)), 0);
     },
     "out", Then::StreamFull, "", ""},
    {"symlink to a character device", true,
     [](const std::string& d, FifoReader&) {
       ASSERT_EQ(::mknod((d + "/null").c_str(), S_IFCHR | 0666, makedev(1, 3)), 0);
       ASSERT_EQ(::symlink("null", (d + "/out").c_str()), 0);
     },
     "out", Then::Streamed, "", ""},
    {"block device", true,
     [](const std::string& d, FifoReader&) {
       ASSERT_EQ(::mknod((d + "/out").c_str(), S_IFBLK | 0660, makedev(7, 0)), 0);
     },
     "out", Then::Refused, "", "out is a block device"},
    {"socket", false, [](const std::string& d, FifoReader&) { make_socket(d + "/out"); }, "out", Then::Refused, "",
     "out is a socket"},
    {"directory", false,
     [](const std::string& d, FifoReader&) {
       ASSERT_EQ(::mkdir((d + "/out").c_str(), 0755), 0);
       write_file(d + "/out/inside", kOld);
     },
     "out", Then::Refused, "", "out is a directory"},
    {"symlink to a directory", false,
     [](const std::string& d, FifoReader&) {
       ASSERT_EQ(::mkdir((d + "/dir").c_str(), 0755), 0);
       ASSERT_EQ(::symlink("dir", (d + "/out").c_str()), 0);
     },
     "out", Then::Refused, "", "is a directory"},
    {"missing folder", false, [](const std::string&, FifoReader&) {}, "no/such/out", Then::Refused, "",
     "cannot create "},
    {"folder is a file", false, [](const std::string& d, FifoReader&) { write_file(d + "/file", kOld); }, "file/out",
     Then::Refused, "", "Not a directory"},
};

enum class Ending { Commit, Discard, Drop };

void run_case(const Case& c, Ending ending) {
  SCOPED_TRACE(std::string(c.kind) + (ending == Ending::Commit    ? ", committed"
                                      : ending == Ending::Discard ? ", discarded"
                                                                  : ", dropped"));
  TempDir dir;
  FifoReader reader;
  c.make(dir.path, reader);
  if (::testing::Test::HasFatalFailure()) return;
  const Snapshot before = snapshot(dir.path);
  const std::string path = dir.path + "/" + c.path;
  {
    pmu::mcap::OutputFile out;
    const std::string why = out.open(path);
    if (c.then == Then::Refused) {
      EXPECT_NE(why.find(c.refusal), std::string::npos) << why;
      EXPECT_NE(why.find(path), std::string::npos) << "names the path: " << why;
      EXPECT_EQ(snapshot(dir.path), before) << describe(snapshot(dir.path));
      return;
    }
    ASSERT_EQ(why, "");
    EXPECT_EQ(out.streaming(), c.then != Then::Replaced);
    const int e = out.sink().write(reinterpret_cast<const std::uint8_t*>(kNew.data()), kNew.size());
    EXPECT_EQ(e, c.then == Then::StreamFull ? ENOSPC : 0) << std::strerror(e);
    EXPECT_EQ(out.sink().truncate(0), c.then == Then::Replaced ? 0 : ESPIPE);
    EXPECT_EQ(out.sink().write(reinterpret_cast<const std::uint8_t*>(kNew.data()), kNew.size()),
              c.then == Then::StreamFull ? ENOSPC : 0);
    if (ending == Ending::Commit) {
      EXPECT_EQ(out.close(), 0);
      EXPECT_EQ(out.commit(), "");
    } else if (ending == Ending::Discard) {
      out.discard();
    }
  }
  Snapshot after = snapshot(dir.path);
  if (c.then == Then::Replaced && ending == Ending::Commit) {
    // The one change: the file the bytes were for holds them (a new inode: renamed onto it).
    const auto it = after.find(c.written);
    ASSERT_NE(it, after.end()) << describe(after);
    EXPECT_EQ(it->second.type, static_cast<mode_t>(S_IFREG));
    EXPECT_EQ(it->second.content, kNew);
    const auto was = before.find(c.written);
    if (was != before.end())
      after[c.written] = was->second;
    else
      after.erase(it);
  }
  if (c.then == Then::Streamed && std::string(c.kind).find("FIFO") != std::string::npos) {
    std::string got(2 * kNew.size() + 1, '\0');
    EXPECT_EQ(::read(reader.fd, got.data(), got.size()), static_cast<ssize_t>(2 * kNew.size()));
  }
  EXPECT_EQ(after, before) << "before: " << describe(before) << "\nafter: " << describe(after);
}

void run_rows(bool device_rows) {
  for (const Case& c : kCases)
    if (c.root == device_rows)
      for (const Ending e : {Ending::Commit, Ending::Discard, Ending::Drop}) run_case(c, e);
}

TEST(McapOutputFile, NothingNotCreatedIsRemovedRenamedOverOrTruncated) { run_rows(false); }

TEST(McapOutputFile, NoDeviceNodeIsRemovedOrRenamedOver) {
  if (::geteuid() != 0) GTEST_SKIP() << "making device nodes (mknod) needs root";
  run_rows(true);
}

// A file its owner cannot write is refused, not replaced by rename(2) (which only needs the
// folder to be writable). Root can write every file, so this needs another user.
TEST(McapOutputFile, AFileThatCannotBeWrittenIsRefused) {
  if (::geteuid() == 0) GTEST_SKIP() << "root may write every file";
  TempDir dir;
  write_file(dir.path + "/out", kOld);
  ASSERT_EQ(::chmod((dir.path + "/out").c_str(), 0444), 0);
  pmu::mcap::OutputFile out;
  const std::string why = out.open(dir.path + "/out");
  EXPECT_NE(why.find("cannot write " + dir.path + "/out: Permission denied"), std::string::npos) << why;
  EXPECT_EQ(read_file(dir.path + "/out"), kOld);
}

// As root, the owner too: an operator's file that root records over stays the operator's.
TEST(McapOutputFile, TheReplacementKeepsThePermissions) {
  TempDir dir;
  write_file(dir.path + "/out", kOld);
  ASSERT_EQ(::chmod((dir.path + "/out").c_str(), 0640), 0);
  const bool root = ::geteuid() == 0;
  if (root) {
    ASSERT_EQ(::chown((dir.path + "/out").c_str(), 65534, 65534), 0);
  }
  pmu::mcap::OutputFile out;
  ASSERT_EQ(out.open(dir.path + "/out"), "");
  EXPECT_EQ(out.close(), 0);
  ASSERT_EQ(out.commit(), "");
  struct stat st {};
  ASSERT_EQ(::stat((dir.path + "/out").c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 0777, 0640u);
  if (root) {
    EXPECT_EQ(st.st_uid, 65534u);
    EXPECT_EQ(st.st_gid, 65534u);
  }
}

// Whatever takes the name while the file is written is not renamed over, and the bytes stay
// in the temporary file, which the message names and only discard() removes.
TEST(McapOutputFile, ACommitThatFailsKeepsTheFile) {
  TempDir dir;
  std::string kept;
  {
    pmu::mcap::OutputFile out;
    ASSERT_EQ(out.open(dir.path + "/out"), "");
    ASSERT_EQ(out.sink().write(reinterpret_cast<const std::uint8_t*>(kNew.data()), kNew.size()), 0);
    kept = out.writing();
    ASSERT_EQ(::mkfifo((dir.path + "/out").c_str(), 0644), 0);
    const std::string why = out.commit();
    EXPECT_NE(why.find("out is no longer a regular file; the file stays as " + kept), std::string::npos) << why;
  }
  struct stat st {};
  ASSERT_EQ(::lstat((dir.path + "/out").c_str(), &st), 0);
  EXPECT_TRUE(S_ISFIFO(st.st_mode));
  EXPECT_EQ(read_file(kept), kNew);
}

// "-": standard output, written where it stands, never truncated (here a pipe).
TEST(McapOutputFile, DashIsStandardOutputAsAStream) {
  int p[2];
  ASSERT_EQ(::pipe(p), 0);
  const int saved = ::dup(STDOUT_FILENO);
  ASSERT_GE(saved, 0);
  std::fflush(stdout);
  ASSERT_EQ(::dup2(p[1], STDOUT_FILENO), STDOUT_FILENO);
  std::string why, name;
  bool streaming = false;
  int written = -1, cut = -1;
  {
    pmu::mcap::OutputFile out;
    why = out.open("-");
    name = out.name();
    streaming = out.streaming();
    if (why.empty()) {
      written = out.sink().write(reinterpret_cast<const std::uint8_t*>(kNew.data()), kNew.size());
      cut = out.sink().truncate(0);
      out.close();
    }
  }
  ::dup2(saved, STDOUT_FILENO);
  ::close(saved);
  ::close(p[1]);
  EXPECT_EQ(why, "");
  EXPECT_EQ(name, "standard output");
  EXPECT_TRUE(streaming);
  EXPECT_EQ(written, 0);
  EXPECT_EQ(cut, ESPIPE);
  std::string got(kNew.size() + 1, '\0');
  EXPECT_EQ(::read(p[0], got.data(), got.size()), static_cast<ssize_t>(kNew.size()));
  got.resize(kNew.size());
  EXPECT_EQ(got, kNew);
  ::close(p[0]);
}

}  // namespace
