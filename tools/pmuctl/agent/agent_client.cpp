#include "pmuctl/agent/agent_client.hpp"

#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "pmuctl/agent/agent_request.hpp"
#include "pmuctl/agent/agent_trust.hpp"
#include "pmuctl/agent/unix_socket.hpp"
#include "pmuctl/call/exit_status.hpp"

namespace pmu::tools {
namespace {

std::nullopt_t not_trusted(const std::string& socket, const std::string& why) {
  std::fprintf(stderr, "pmuctl: not using the agent on %s: %s; the call runs on its own\n", socket.c_str(),
               why.c_str());
  return std::nullopt;
}

}  // namespace

std::optional<int> call_agent(const std::string& socket, const std::vector<std::string>& arguments, bool json,
                              const AgentCallInfo& call) {
  // The path before connecting, the listener once connected: nothing of the call (arguments,
  // environment, terminal) reaches a process this user did not start.
  if (const auto why = untrusted_socket_path(socket, ::getuid()); !why.empty()) return not_trusted(socket, why);
  UniqueFd fd = connect_unix(socket);
  if (!fd) return std::nullopt;  // no agent: the common case, said nowhere
  if (const auto why = untrusted_peer(fd.get(), ::getuid()); !why.empty()) return not_trusted(socket, why);

  AgentRequest request;
  request.deadline_ns = call.deadline_ns;
  request.engine_stop = call.engine_stop;
  char cwd[4096];
  if (!::getcwd(cwd, sizeof cwd)) return std::nullopt;  // the agent could not find relative paths
  request.directory = cwd;
  for (const char* name : kAgentEnvironment)
    if (const char* v = std::getenv(name)) request.environment.emplace_back(name, v);
  request.arguments = arguments;
  const std::string bytes = encode_request(request);
  if (!send_with_fds(fd.get(), bytes, {STDIN_FILENO, STDOUT_FILENO, STDERR_FILENO})) {
    std::fprintf(stderr, "pmuctl: cannot send the call to the agent on %s (%s); it runs on its own\n", socket.c_str(),
                 std::strerror(errno));
    return std::nullopt;
  }
  std::string answer;
  if (!receive(fd.get(), answer)) {
    return fail(json, ExitStatus::NoAnswer,
                "the agent on " + socket +
                    " ended during the call: it may have been carried out (see the agent's log), so it is not "
                    "run again");
  }
  const auto reply = decode_reply(answer);
  if (!reply)
    return fail(json, ExitStatus::NoAnswer, "the agent on " + socket + " answered something that is not a result");
  if (reply->ran) return reply->status;
  if (reply->expired)
    return fail(json, ExitStatus::NoAnswer, "the agent on " + socket + " did not run the call: " + reply->why_expired);
  std::fprintf(stderr, "pmuctl: the agent on %s does not serve this call (%s); it runs on its own\n", socket.c_str(),
               reply->declined.c_str());
  return std::nullopt;
}

}  // namespace pmu::tools
