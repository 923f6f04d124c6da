// Whether a pmuctl call trusts what listens on an agent socket (tools/pmuctl/agent/
// agent_trust.hpp): only a socket and folder that no other user could have put there or
// replace, and a listener that runs as the caller or root; anything else would let another
// user answer the call (a false READY, docs/safety.md H6) or swallow an engine stop (H4).
// Files of another user need root to make: those cases skip for other users.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstring>
#include <fstream>
#include <string>
#include <thread>

#include "pmuctl/agent/agent_trust.hpp"
#include "pmuctl/agent/unix_socket.hpp"

#include "support/temp_dir.hpp"

namespace {

constexpr uid_t kOther = 65534;  // nobody

// A socket bound (not listened on) at `path`, by this process.
bool bind_socket(const std::string& path) {
  pmu::tools::UniqueFd fd(::socket(AF_UNIX, SOCK_SEQPACKET, 0));
  sockaddr_un addr{};
  addr.sun_family = AF_UNIX;
  std::strncpy(addr.sun_path, path.c_str(), sizeof addr.sun_path - 1);
  return ::bind(fd.get(), reinterpret_cast<const sockaddr*>(&addr), sizeof addr) == 0;
}

struct PathCase {
  const char* what;
  bool needs_root;  // makes files of another user
  mode_t folder_mode;
  uid_t folder_owner;   // 0: this process's user
  const char* at_path;  // "socket", "file" or "nothing"
  mode_t socket_mode;
  uid_t socket_owner;
  const char* why;  // "" trusted; else what the message says (the folder's path follows "folder ")
};

TEST(AgentTrust, OnlyAFolderAndSocketOfTheCallerOrRootAreTrusted) {
  const uid_t me = ::geteuid();
  const PathCase cases[] = {
      {"the caller's own folder and socket", false, 0700, 0, "socket", 0600, 0, ""},
      {"a root folder others may read", false, 0755, 0, "socket", 0600, 0, ""},
      {"nothing at the path", false, 0700, 0, "nothing", 0, 0, ""},
      {"a shared folder (/tmp's mode)", false, 01777, 0, "socket", 0600, 0, "is writable by other users (mode 1777)"},
      {"a folder its group may write to", false, 0770, 0, "socket", 0600, 0, "is writable by other users (mode 0770)"},
      {"a socket others may connect to", false, 0700, 0, "socket", 0666, 0,
       "the socket is writable by other users (mode 0666)"},
      {"a file that is not a socket", false, 0700, 0, "file", 0600, 0, "it is not a socket"},
      {"a folder of another user", true, 0700, kOther, "socket", 0600, 0, "belongs to uid 65534"},
      {"a socket of another user", true, 0700, 0, "socket", 0600, kOther, "the socket belongs to uid 65534"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.what);
    if (c.needs_root && me != 0) continue;  // said below
    pmu::test::TempDir dir{"pmu-agent-trust"};
    const std::string folder = dir.path() + "/pmu-dds", path = folder + "/agent.sock";
    ASSERT_EQ(::mkdir(folder.c_str(), 0700), 0);
    if (std::string(c.at_path) == "socket") {
      ASSERT_TRUE(bind_socket(path));
    }
    if (std::string(c.at_path) == "file") std::ofstream(path) << "x";
    if (std::string(c.at_path) != "nothing") {
      ASSERT_EQ(::chmod(path.c_str(), c.socket_mode), 0);
      if (c.socket_owner) {
        ASSERT_EQ(::chown(path.c_str(), c.socket_owner, static_cast<gid_t>(-1)), 0);
      }
    }
    ASSERT_EQ(::chmod(folder.c_str(), c.folder_mode), 0);
    if (c.folder_owner) {
      ASSERT_EQ(::chown(folder.c_str(), c.folder_owner, static_cast<gid_t>(-1)), 0);
    }
    const std::string why = pmu::tools::untrusted_socket_path(path, me);
    if (std::string(c.why).empty()) {
      EXPECT_EQ(why, "");
    } else {
      EXPECT_NE(why.find(c.why), std::string::npos) << why;
      if (std::string(c.why).rfind("is writable", 0) == 0 || std::string(c.why).rfind("belongs", 0) == 0) {
        EXPECT_EQ(why.rfind("its folder " + folder + " ", 0), 0u) << why;
      }
    }
  }
  if (me != 0) GTEST_SKIP() << "the cases with another user's files need root";
}

// A process listening on `path` as user `uid` (after binding it as this one), until killed.
pid_t listen_as(const std::string& path, uid_t uid) {
  const pid_t pid = ::fork();
  if (pid != 0) return pid;
  pmu::tools::UniqueFd fd(::socket(AF_UNIX, SOCK_SEQPACKET, 0));
  sockaddr_un addr{};
  addr.sun_family = AF_UNIX;
  std::strncpy(addr.sun_path, path.c_str(), sizeof addr.sun_path - 1);
  if (::bind(fd.get(), reinterpret_cast<const sockaddr*>(&addr), sizeof addr) != 0) ::_exit(1);
  // The peer's credentials are those of the process when it called listen().
  if (uid != ::geteuid() && (::setgid(uid) != 0 || ::setuid(uid) != 0)) ::_exit(1);
  if (::listen(fd.get(), 4) != 0) ::_exit(1);
  for (;;) ::pause();
}

// Connects to `path` once something listens there (a child just started).
pmu::tools::UniqueFd connect_when_listened(const std::string& path) {
  for (int i = 0; i < 400; ++i) {
    if (auto fd = pmu::tools::connect_unix(path)) return fd;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return pmu::tools::UniqueFd();
}

// Stops a listener child when the test ends, however it ends.
struct Listener {
  pid_t pid;
  ~Listener() {
    ::kill(pid, SIGKILL);
    ::waitpid(pid, nullptr, 0);
  }
};

TEST(AgentTrust, AListenerOfTheCallerOrRootIsTrustedOfAnotherUserNot) {
  pmu::test::TempDir dir{"pmu-agent-trust"};
  const std::string mine = dir.path() + "/mine.sock";
  const Listener own{listen_as(mine, ::geteuid())};
  auto fd = connect_when_listened(mine);
  ASSERT_TRUE(fd);
  EXPECT_EQ(pmu::tools::untrusted_peer(fd.get(), ::geteuid()), "");
  if (::geteuid() != 0) GTEST_SKIP() << "a listener of another user needs root to start";
  // A caller of another user (uid 1000) trusts a listener that runs as root.
  EXPECT_EQ(pmu::tools::untrusted_peer(fd.get(), 1000), "");

  const std::string theirs = dir.path() + "/theirs.sock";
  const Listener other{listen_as(theirs, kOther)};
  fd = connect_when_listened(theirs);
  ASSERT_TRUE(fd);
  EXPECT_EQ(pmu::tools::untrusted_peer(fd.get(), 0), "the process that listens (pid " + std::to_string(other.pid) +
                                                         ") runs as uid 65534, not as this user (uid 0) or root");
}

}  // namespace
