#pragma once
// `pmuctl agent`: one process on the ground host that keeps pmuctl's participants for the
// calls made on that host (context_lease.hpp says why). It listens on a Unix socket
// (agent_request.hpp), reads each call's request itself and hands it to a worker: each worker
// is a process of its own with its own participants, forked by the agent (which never makes a
// DDS participant or a thread), and serves one call at a time with the caller's working
// directory, environment and standard streams (which are per process), answering its exit
// status. There are `workers` of them for calls, and one more, the stop lane, for engine
// stops: a stop goes there, or to any free worker, at once, and never waits behind another
// call (docs/safety.md H4). Other calls go to the first worker while it keeps up, so its
// endpoints, matched at the aircraft, serve them; the next takes a call only when every
// worker before it has been on its own for 5 s (kSpillAfter). A call to an aircraft that does
// not answer then holds one worker, not the ground station. A call waiting for a worker whose
// caller left (its connection closed) or whose caller's wait ended (its deadline) is dropped,
// said in the log, and never run (H9). Only the caller's own user may call (the socket is
// 0600 and the peer's uid is checked). It ends on SIGINT or SIGTERM, after each worker's
// current call, removing its socket; a worker that dies is replaced, and the workers die
// with the agent.
//
// Threads: run_agent blocks the calling (main) thread, which must not have started other
// threads (it forks); `run` is called on a worker's main thread, one call at a time per
// worker. Each worker's pool outlives every call it serves.

#include <functional>
#include <string>
#include <vector>

#include "pmuctl/agent/agent_request.hpp"
#include "pmuctl/call/context_lease.hpp"

namespace pmu::tools {

// Runs one call (its arguments, deadline and lane) with `pool` and returns its exit status;
// sets `declined` (and runs nothing) when the call is not the agent's to serve.
using AgentCallRunner = std::function<int(const AgentRequest& request, ContextPool& pool, std::string& declined)>;

// Exit status 0 after a signal; 2 when the socket cannot be made or another agent listens.
// `workers`: 1..16 workers for calls, besides the stop lane.
int run_agent(const GlobalOptions& settings, const std::string& socket, int workers, const AgentCallRunner& run);

}  // namespace pmu::tools
