#include "pmuctl/agent/agent_trust.hpp"

#include <sys/socket.h>
#include <sys/stat.h>

#include <cerrno>
#include <cstdio>
#include <cstring>

namespace pmu::tools {
namespace {

std::string mode_text(mode_t mode) {
  char text[8];
  std::snprintf(text, sizeof text, "%04o", static_cast<unsigned>(mode & 07777));
  return text;
}

// Why `what` (described by `st`) is not the caller's or root's alone, or "".
std::string not_owned(const std::string& what, const struct stat& st, uid_t uid) {
  if (st.st_uid != uid && st.st_uid != 0)
    return what + " belongs to uid " + std::to_string(st.st_uid) + ", not to this user (uid " + std::to_string(uid) +
           ") or root";
  if (st.st_mode & (S_IWGRP | S_IWOTH))
    return what + " is writable by other users (mode " + mode_text(st.st_mode) + ")";
  return {};
}

}  // namespace

std::string untrusted_socket_path(const std::string& path, uid_t uid) {
  struct stat socket_st {};
  if (::lstat(path.c_str(), &socket_st) != 0) return {};  // nothing there: nothing listens
  const auto slash = path.rfind('/');
  const std::string folder = slash == std::string::npos ? "." : slash == 0 ? "/" : path.substr(0, slash);
  struct stat folder_st {};
  if (::stat(folder.c_str(), &folder_st) != 0)
    return "its folder " + folder + " cannot be examined (" + std::strerror(errno) + ")";
  // A folder others may write to lets them put a socket of theirs at the path, or replace ours.
  if (auto why = not_owned("its folder " + folder, folder_st, uid); !why.empty()) return why;
  if (!S_ISSOCK(socket_st.st_mode)) return "it is not a socket";
  return not_owned("the socket", socket_st, uid);
}

std::string untrusted_peer(int fd, uid_t uid) {
  ucred peer{};
  socklen_t len = sizeof peer;
  if (::getsockopt(fd, SOL_SOCKET, SO_PEERCRED, &peer, &len) != 0)
    return std::string("the process that listens cannot be identified (") + std::strerror(errno) + ")";
  if (peer.uid != uid && peer.uid != 0)
    return "the process that listens (pid " + std::to_string(peer.pid) + ") runs as uid " + std::to_string(peer.uid) +
           ", not as this user (uid " + std::to_string(uid) + ") or root";
  return {};
}

}  // namespace pmu::tools
