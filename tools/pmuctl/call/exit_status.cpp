#include "pmuctl/call/exit_status.hpp"

#include <nlohmann/json.hpp>

#include <cstdio>

#include "pmuctl/verbs/state_verbs.hpp"

namespace pmu::tools {

int fail(bool json, ExitStatus status, const std::string& message) {
  std::fprintf(stderr, "pmuctl: %s\n", message.c_str());
  if (json) {
    nlohmann::ordered_json j{{"error", message}, {"exit_status", static_cast<int>(status)}};
    // The message may quote bytes from the network: never let them make the line invalid.
    std::printf("%s\n", j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace).c_str());
    std::fflush(stdout);
  }
  return static_cast<int>(status);
}

int fail(const GlobalOptions& o, ExitStatus status, const std::string& message) {
  return fail(o.json, status, message);
}

}  // namespace pmu::tools
