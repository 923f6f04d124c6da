#include "pmuctl/serve/origin_policy.hpp"

#include <arpa/inet.h>

#include <algorithm>
#include <cctype>

namespace pmu::tools {
namespace {

constexpr std::string_view kDefaultOrigins[] = {"https://app.foxglove.dev", "https://studio.foxglove.dev", "file://"};
constexpr std::string_view kLocalHosts[] = {"localhost", "127.0.0.1", "[::1]"};

std::string lower(std::string_view s) {
  std::string out(s);
  std::transform(out.begin(), out.end(), out.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return out;
}

bool digits(std::string_view s) {
  return !s.empty() && std::all_of(s.begin(), s.end(), [](char c) { return c >= '0' && c <= '9'; });
}

// A host name of letters, digits, '-' and '.' (no empty label), an IPv4 address, or [IPv6].
bool valid_host(const std::string& host) {
  if (host.size() > 2 && host.front() == '[' && host.back() == ']') {
    in6_addr a6{};
    return ::inet_pton(AF_INET6, host.substr(1, host.size() - 2).c_str(), &a6) == 1;
  }
  if (host.empty() || host.size() > 253 || host.front() == '.' || host.back() == '.') return false;
  if (host.find("..") != std::string::npos) return false;
  return std::all_of(host.begin(), host.end(),
                     [](char c) { return (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '-' || c == '.'; });
}

// A local page: http or https on localhost, 127.0.0.1 or [::1], any port.
bool local_page(std::string_view origin) {
  for (const std::string_view scheme : {"http://", "https://"}) {
    if (origin.substr(0, scheme.size()) != scheme) continue;
    const std::string_view rest = origin.substr(scheme.size());
    for (const std::string_view host : kLocalHosts) {
      if (rest.substr(0, host.size()) != host) continue;
      const std::string_view port = rest.substr(host.size());
      if (port.empty() || (port[0] == ':' && digits(port.substr(1)))) return true;
    }
  }
  return false;
}

}  // namespace

std::string add_allowed_origin(const std::string& text, OriginPolicy& policy) {
  if (text == "*") {
    policy.any = true;
    return {};
  }
  const std::string bad = "--allow-origin '" + text +
                          "' is not an origin scheme://host[:port] (e.g. "
                          "https://viz.example.com:8443; http or https, no path, not even a final /; or '*' for "
                          "every origin)";
  const std::string o = lower(text);
  std::string scheme;
  for (const char* s : {"http", "https"})
    if (o.rfind(std::string(s) + "://", 0) == 0) scheme = s;
  if (scheme.empty()) return bad;
  std::string rest = o.substr(scheme.size() + 3);
  std::string port;
  // The last ':' after an IPv6 literal's ']' (or in a name) starts the port.
  const std::size_t colon = rest.rfind(':');
  if (colon != std::string::npos && (rest.front() != '[' || colon > rest.rfind(']'))) {
    port = rest.substr(colon + 1);
    rest.resize(colon);
    long p = 0;
    if (!digits(port) || port.size() > 5 || (p = std::stol(port)) < 1 || p > 65535)
      return "--allow-origin '" + text + "': the port must be a number 1..65535";
    port = std::to_string(p);  // no leading zeros: a browser sends none
    if ((scheme == "http" && p == 80) || (scheme == "https" && p == 443)) port.clear();
  }
  if (!valid_host(rest)) return bad;
  const std::string origin = scheme + "://" + rest + (port.empty() ? "" : ":" + port);
  if (std::find(policy.exact.begin(), policy.exact.end(), origin) == policy.exact.end()) policy.exact.push_back(origin);
  return {};
}

bool origin_allowed(const OriginPolicy& policy, std::string_view origin) {
  if (origin.empty() || policy.any) return true;
  const std::string o = lower(origin);
  if (local_page(o)) return true;
  for (const std::string_view d : kDefaultOrigins)
    if (o == d) return true;
  return std::find(policy.exact.begin(), policy.exact.end(), o) != policy.exact.end();
}

}  // namespace pmu::tools
