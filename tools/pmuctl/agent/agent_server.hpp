#pragma once
// `pmuctl agent`: one process on the ground host that keeps pmuctl's participants for the
// calls made on that host (context_lease.hpp says why). It listens on a Unix socket
// (agent_request.hpp), takes one call at a time in the order they come, runs it with the
// caller's working directory, environment and standard streams, and answers its exit
// status. Only the caller's own user may call (the socket is 0600 and the peer's uid is
// checked). It ends on SIGINT or SIGTERM, removing its socket.
//
// Threads: run_agent blocks the calling (main) thread; `run` is called on it, one call at
// a time. The pool outlives every call (run_agent owns it).

#include <functional>
#include <string>
#include <vector>

#include "pmuctl/verbs/context_lease.hpp"

namespace pmu::tools {

// Runs one call's arguments with `pool` and returns its exit status; sets `declined` (and
// runs nothing) when the call is not the agent's to serve.
using AgentCallRunner =
    std::function<int(const std::vector<std::string>& arguments, ContextPool& pool, std::string& declined)>;

// Exit status 0 after a signal; 2 when the socket cannot be made or another agent listens.
int run_agent(const GlobalOptions& settings, const std::string& socket, const AgentCallRunner& run);

}  // namespace pmu::tools
