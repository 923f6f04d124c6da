#pragma once
// What a pmuctl call sends `pmuctl agent` over its socket, and what comes back: one
// SOCK_SEQPACKET message each way. The request carries the end of the caller's wait, whether
// it is an engine stop, the call's working directory, the environment variables that change
// what pmuctl does, and its arguments; its standard input, output and error go along as file
// descriptors (SCM_RIGHTS), so the agent writes straight to the caller's terminal or pipe.
// The reply is the call's exit status, why the agent did not run it (the caller then runs it
// on its own), or that its caller's wait ended before a worker was free (not run).
//
// Encoding: NUL-terminated strings: "pmuctl-agent-2", the deadline (ns since the Unix epoch,
// UTC), the lane ("stop" or "call"), the directory, the number of variables, NAME=VALUE for
// each, then the arguments (without argv[0]). Decoding is total: anything else is an error
// naming what was wrong, never a partial request.

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace pmu::tools {

// The variables a call reads (pmuctl(1), ENVIRONMENT). A call sends those it has set; the
// agent runs it with exactly those set and the others unset.
inline constexpr const char* kAgentEnvironment[] = {
    "PMU_VEHICLE",   "PMU_QOS_FILE",         "PMU_SECURITY_DIR",   "PMU_SECURITY_IDENTITY",
    "PMU_DDS_PEERS", "PMU_DISCOVERY_SERVER", "PMU_DDS_INTERFACES", "PMU_LINK",
};

struct AgentRequest {
  // When the caller stops waiting (ns since the Unix epoch, UTC: the clock of expires_at,
  // interface.md 2.3), fixed when the call began. A call still queued then is not run, and
  // every command it sends expires then (docs/safety.md H9).
  std::uint64_t deadline_ns = 0;
  // An engine stop: served on the agent's stop lane, never behind another call (docs/safety.md H4).
  bool engine_stop = false;
  std::string directory;
  std::vector<std::pair<std::string, std::string>> environment;
  std::vector<std::string> arguments;
};

std::string encode_request(const AgentRequest& request);
// The request, or nullopt with `error` saying what is wrong with `bytes`.
std::optional<AgentRequest> decode_request(std::string_view bytes, std::string& error);

// The agent's answer: "exit N" (the call ran; N its exit status), "declined WHY" (not run;
// the caller runs it on its own), "expired WHY" (not run, and its caller's wait is over).
struct AgentReply {
  bool ran = false;
  int status = 0;
  std::string declined;  // why, when !ran and !expired
  bool expired = false;
  std::string why_expired;
};
std::string encode_reply(const AgentReply& reply);
std::optional<AgentReply> decode_reply(std::string_view bytes);

// The socket of the agent for `domain`: $PMU_AGENT_SOCKET when set; else
// $XDG_RUNTIME_DIR/pmu-dds/agent-DOMAIN.sock for a user with a runtime directory, else
// /run/pmu-dds/agent-DOMAIN.sock (a system service's RuntimeDirectory).
std::string agent_socket_path(int domain);

}  // namespace pmu::tools
