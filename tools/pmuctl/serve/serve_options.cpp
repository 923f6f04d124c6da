#include "pmuctl/serve/serve_options.hpp"

#include <arpa/inet.h>

#include <cstdlib>
#include <utility>

namespace pmu::tools {
namespace {

// A whole decimal number within [lo, hi]; false for anything else (sign, spaces, suffixes).
bool whole_number(const std::string& text, long lo, long hi, long& out) {
  if (text.empty() || text.size() > 10) return false;
  for (const char c : text)
    if (c < '0' || c > '9') return false;
  out = std::strtol(text.c_str(), nullptr, 10);
  return out >= lo && out <= hi;
}

bool is_ipv6(const std::string& text) {
  in6_addr a6{};
  return ::inet_pton(AF_INET6, text.c_str(), &a6) == 1;
}

}  // namespace

std::string parse_serve_options(const std::string& listen, const std::string& port, const std::string& client_queue_kb,
                                ServeOptions& out) {
  in_addr a4{};
  if (::inet_pton(AF_INET, listen.c_str(), &a4) != 1 && !is_ipv6(listen))
    return "--listen '" + listen +
           "' is not an IP address (e.g. 127.0.0.1 for this host only, 0.0.0.0 for every "
           "interface, ::1; not a host name)";
  long p = 0;
  if (!whole_number(port, 1, 65535, p)) return "--port '" + port + "' is not a port number 1..65535";
  long kb = 0;
  if (!whole_number(client_queue_kb, kMinClientQueueKb, kMaxClientQueueKb, kb))
    return "--client-queue '" + client_queue_kb + "' is not a size in kB " + std::to_string(kMinClientQueueKb) + ".." +
           std::to_string(kMaxClientQueueKb);
  out.address = listen;
  out.port = static_cast<std::uint16_t>(p);
  out.client_queue = static_cast<std::size_t>(kb) * 1024;
  return {};
}

std::string parse_serve_access(const std::vector<std::string>& allow_origins, const std::string& tls_cert,
                               const std::string& tls_key, ServeOptions& out) {
  OriginPolicy origins;
  for (const auto& a : allow_origins)
    if (auto why = add_allowed_origin(a, origins); !why.empty()) return why;
  if (tls_cert.empty() != tls_key.empty())
    return std::string("--tls-cert and --tls-key go together (the certificate chain and its private key, PEM): ") +
           (tls_cert.empty() ? "--tls-cert" : "--tls-key") + " is missing";
  out.origins = std::move(origins);
  out.tls_cert = tls_cert;
  out.tls_key = tls_key;
  return {};
}

bool listens_on_loopback(const ServeOptions& o) {
  in_addr a4{};
  if (::inet_pton(AF_INET, o.address.c_str(), &a4) == 1) return (ntohl(a4.s_addr) >> 24) == 127;
  in6_addr a6{};
  return ::inet_pton(AF_INET6, o.address.c_str(), &a6) == 1 && IN6_IS_ADDR_LOOPBACK(&a6);
}

std::string endpoint_label(const ServeOptions& o) {
  const std::string host = is_ipv6(o.address) ? "[" + o.address + "]" : o.address;
  return host + ":" + std::to_string(o.port);
}

}  // namespace pmu::tools
