#pragma once
// Whether a pmuctl call may hand itself to what listens on an agent socket. The call gives
// the agent its arguments, environment and terminal, and prints what the agent says (READY,
// no alarm, COMPLETED): a process of another user on that path could fake any answer
// (docs/safety.md H6) or swallow an engine stop (H4). So a call checks the agent as the agent
// checks its callers: the socket's folder and the socket are owned by the caller or root and
// writable by nobody else (no other user can have put it there or replace it), and the
// process that listens on it runs as the caller or root (SO_PEERCRED).
//
// Threads: any; each function uses only its arguments and the file system.

#include <string>
#include <sys/types.h>

namespace pmu::tools {

// Why the folder and socket at `path` are not to be trusted by user `uid`, or "" when they
// are. A path with nothing at it is "" too: nothing listens there.
std::string untrusted_socket_path(const std::string& path, uid_t uid);

// Why the process on the other end of the connected Unix socket `fd` is not to be trusted
// by user `uid`, or "".
std::string untrusted_peer(int fd, uid_t uid);

}  // namespace pmu::tools
