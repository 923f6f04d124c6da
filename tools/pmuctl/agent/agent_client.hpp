#pragma once
// A pmuctl call that goes through `pmuctl agent` when one listens on `socket`
// (agent_request.hpp says what crosses). Threads: the caller's; it blocks until the agent
// answers.
//
// The agent is checked first (agent_trust.hpp): a socket or folder another user could have
// put there, or a listener of another user, gets nothing of the call; a line on stderr says
// why and the call runs on its own (docs/safety.md H6: never an answer another user made up;
// H4: an engine stop is still sent).
//
// nullopt: no agent listens there, it is not trusted, or it declined the call (then a line on
// stderr says why): the caller runs the call on its own. Otherwise the call's exit status. An
// agent that ends during the call gives exit status 3 (no answer) after saying so: the call
// may have been carried out, so it is never run a second time here. A call whose wait ended
// while it was queued in the agent exits 3 too: it was not run, and is not run now, its
// caller's wait being over (H9).

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace pmu::tools {

struct AgentCallInfo {
  std::uint64_t deadline_ns = 0;  // the end of the caller's wait, ns since the Unix epoch
  bool engine_stop = false;       // an engine stop: the agent's stop lane
};

std::optional<int> call_agent(const std::string& socket, const std::vector<std::string>& arguments, bool json,
                              const AgentCallInfo& call);

}  // namespace pmu::tools
