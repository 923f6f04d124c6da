#include "pmuctl/agent/agent_request.hpp"

#include <algorithm>
#include <charconv>
#include <cstdlib>

namespace pmu::tools {
namespace {

constexpr std::string_view kMagic = "pmuctl-agent-2";
constexpr std::size_t kHeader = 5;  // magic, deadline, lane, directory, count
constexpr std::size_t kMostStrings = 4096;

bool is_agent_variable(std::string_view name) {
  return std::any_of(std::begin(kAgentEnvironment), std::end(kAgentEnvironment),
                     [&](const char* v) { return name == v; });
}

}  // namespace

std::string encode_request(const AgentRequest& request) {
  std::string out;
  auto put = [&](std::string_view s) {
    out.append(s);
    out.push_back('\0');
  };
  put(kMagic);
  put(std::to_string(request.deadline_ns));
  put(request.engine_stop ? "stop" : "call");
  put(request.directory);
  put(std::to_string(request.environment.size()));
  for (const auto& [name, value] : request.environment) put(name + "=" + value);
  for (const auto& a : request.arguments) put(a);
  return out;
}

std::optional<AgentRequest> decode_request(std::string_view bytes, std::string& error) {
  std::vector<std::string_view> parts;
  while (!bytes.empty()) {
    const auto end = bytes.find('\0');
    if (end == std::string_view::npos) {
      error = "a request's last string has no terminating NUL";
      return std::nullopt;
    }
    if (parts.size() == kMostStrings) {
      error = "a request of more than " + std::to_string(kMostStrings) + " strings";
      return std::nullopt;
    }
    parts.push_back(bytes.substr(0, end));
    bytes.remove_prefix(end + 1);
  }
  if (parts.size() < kHeader || parts[0] != kMagic) {
    error = "not a pmuctl agent request (it does not begin with \"pmuctl-agent-2\")";
    return std::nullopt;
  }
  AgentRequest r;
  const auto deadline = parts[1];
  const auto [dend, dec] = std::from_chars(deadline.data(), deadline.data() + deadline.size(), r.deadline_ns);
  if (dec != std::errc() || dend != deadline.data() + deadline.size() || r.deadline_ns == 0) {
    error = "the deadline '" + std::string(deadline) + "' is not a time in ns since the epoch";
    return std::nullopt;
  }
  if (parts[2] != "stop" && parts[2] != "call") {
    error = "the lane '" + std::string(parts[2]) + "' is neither stop nor call";
    return std::nullopt;
  }
  r.engine_stop = parts[2] == "stop";
  r.directory = std::string(parts[3]);
  if (r.directory.empty() || r.directory.front() != '/') {
    error = "the working directory is not an absolute path";
    return std::nullopt;
  }
  std::size_t n = 0;
  const auto count = parts[4];
  const auto [ptr, ec] = std::from_chars(count.data(), count.data() + count.size(), n);
  if (ec != std::errc() || ptr != count.data() + count.size() || n > parts.size() - kHeader) {
    error =
        "the count of environment variables '" + std::string(count) + "' is not a number of the strings that follow";
    return std::nullopt;
  }
  for (std::size_t i = 0; i < n; ++i) {
    const auto kv = parts[kHeader + i];
    const auto eq = kv.find('=');
    if (eq == std::string_view::npos || !is_agent_variable(kv.substr(0, eq))) {
      error = "environment entry " + std::to_string(i + 1) + " is not NAME=VALUE of a variable pmuctl reads";
      return std::nullopt;
    }
    r.environment.emplace_back(std::string(kv.substr(0, eq)), std::string(kv.substr(eq + 1)));
  }
  for (std::size_t i = kHeader + n; i < parts.size(); ++i) r.arguments.emplace_back(parts[i]);
  return r;
}

std::string encode_reply(const AgentReply& reply) {
  if (reply.ran) return "exit " + std::to_string(reply.status);
  return reply.expired ? "expired " + reply.why_expired : "declined " + reply.declined;
}

std::optional<AgentReply> decode_reply(std::string_view bytes) {
  AgentReply r;
  if (bytes.substr(0, 5) == "exit ") {
    const auto digits = bytes.substr(5);
    const auto [ptr, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), r.status);
    if (ec != std::errc() || ptr != digits.data() + digits.size() || r.status < 0 || r.status > 255)
      return std::nullopt;
    r.ran = true;
    return r;
  }
  if (bytes.substr(0, 8) == "expired ") {
    r.expired = true;
    r.why_expired = std::string(bytes.substr(8));
    return r;
  }
  if (bytes.substr(0, 9) == "declined ") {
    r.declined = std::string(bytes.substr(9));
    return r;
  }
  return std::nullopt;
}

std::string agent_socket_path(int domain) {
  if (const char* p = std::getenv("PMU_AGENT_SOCKET"); p && *p) return p;
  const std::string name = "/pmu-dds/agent-" + std::to_string(domain) + ".sock";
  if (const char* run = std::getenv("XDG_RUNTIME_DIR"); run && *run == '/') return run + name;
  return "/run" + name;
}

}  // namespace pmu::tools
