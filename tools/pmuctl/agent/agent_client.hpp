#pragma once
// A pmuctl call that goes through `pmuctl agent` when one listens on `socket`
// (agent_request.hpp says what crosses). Threads: the caller's; it blocks until the agent
// answers.
//
// nullopt: no agent listens there, or it declined the call (then a line on stderr says why):
// the caller runs the call on its own. Otherwise the call's exit status. An agent that ends
// during the call gives exit status 3 (no answer) after saying so: the call may have been
// carried out, so it is never run a second time here.

#include <optional>
#include <string>
#include <vector>

namespace pmu::tools {

std::optional<int> call_agent(const std::string& socket, const std::vector<std::string>& arguments, bool json);

}  // namespace pmu::tools
