#include "pmu/dds_settings/network_settings.hpp"

#include <arpa/inet.h>
#include <ifaddrs.h>
#include <netdb.h>
#include <netinet/in.h>
#include <sys/socket.h>

#include <algorithm>
#include <cctype>
#include <memory>
#include <set>

namespace pmu::dds {
namespace {

constexpr std::size_t kMaxInterfaceName = 15;  // IFNAMSIZ - 1
constexpr std::size_t kMaxHostName = 253;      // RFC 1035, without the final dot
constexpr std::size_t kMaxLabel = 63;

// The part of `s` from `start` up to the dot at `dot` (or to the end).
std::string_view up_to(std::string_view s, std::size_t start, std::size_t dot) {
  return s.substr(start, dot == std::string_view::npos ? std::string_view::npos : dot - start);
}

bool all_digits(std::string_view s) {
  return !s.empty() && std::all_of(s.begin(), s.end(), [](char c) { return c >= '0' && c <= '9'; });
}

bool digits_and_dots(std::string_view s) {
  return !s.empty() && std::all_of(s.begin(), s.end(), [](char c) { return (c >= '0' && c <= '9') || c == '.'; });
}

// RFC 1123 host name: labels of letters, digits and '-', not starting or ending with '-'.
bool is_host_name(std::string_view s) {
  if (s.empty() || s.size() > kMaxHostName) return false;
  std::size_t start = 0;
  for (;;) {
    const std::size_t dot = s.find('.', start);
    const std::string_view label = up_to(s, start, dot);
    if (label.empty() || label.size() > kMaxLabel || label.front() == '-' || label.back() == '-') return false;
    for (char c : label)
      if (!std::isalnum(static_cast<unsigned char>(c)) && c != '-') return false;
    if (dot == std::string_view::npos) return true;
    start = dot + 1;
  }
}

std::array<unsigned, 4> octets(std::string_view ip) {
  std::array<unsigned, 4> o{};
  std::size_t i = 0;
  for (char c : ip) {
    if (c == '.')
      ++i;
    else
      o[i] = o[i] * 10 + static_cast<unsigned>(c - '0');
  }
  return o;
}

// An address that no single host answers at: the "any" address, multicast, broadcast.
std::string not_a_host(std::string_view ip) {
  const auto o = octets(ip);
  if (o[0] == 0) return "'" + std::string(ip) + "' is not a host's address";
  if (o[0] >= 224 && o[0] <= 239) return "'" + std::string(ip) + "' is a multicast address, not a host's";
  if (o == std::array<unsigned, 4>{255, 255, 255, 255}) return "'" + std::string(ip) + "' is the broadcast address";
  return {};
}

std::string parse_host(std::string_view host) {
  if (host.empty()) return "no address before the ':'";
  if (digits_and_dots(host)) {
    if (!is_ipv4(host)) return "'" + std::string(host) + "' is not an IPv4 address (four numbers 0..255: 192.168.10.2)";
    return not_a_host(host);
  }
  if (!is_host_name(host))
    return "'" + std::string(host) + "' is not an IPv4 address or a host name (letters, digits, '-' and '.')";
  return {};
}

std::string join(const std::vector<std::string>& v) {
  std::string s;
  for (const auto& x : v) s += (s.empty() ? "" : ", ") + x;
  return s;
}

std::string endpoint_text(const Ipv4Endpoint& e) {
  return e.port ? e.address + ":" + std::to_string(e.port) : e.address;
}

}  // namespace

const char* to_string(DiscoveryMode mode) noexcept {
  switch (mode) {
    case DiscoveryMode::Unicast: return "unicast";
    case DiscoveryMode::Server: return "server";
    case DiscoveryMode::Multicast: break;
  }
  return "multicast";
}

bool is_ipv4(std::string_view text) noexcept {
  int parts = 0;
  std::size_t start = 0;
  for (;;) {
    const std::size_t dot = text.find('.', start);
    const std::string_view part = up_to(text, start, dot);
    if (!all_digits(part) || part.size() > 3 || (part.size() > 1 && part.front() == '0')) return false;
    if (std::stoi(std::string(part)) > 255) return false;
    ++parts;
    if (dot == std::string_view::npos) break;
    start = dot + 1;
  }
  return parts == 4;
}

std::string parse_address(std::string_view text, Address& out) {
  if (text.empty()) return "empty address";
  if (text.front() == '[' || std::count(text.begin(), text.end(), ':') > 1)
    return "IPv6 is not supported (Fast DDS's UDPv4 transport carries DDS here): give an IPv4 address or a host name";
  std::string_view host = text;
  std::uint16_t port = 0;
  if (const auto colon = text.find(':'); colon != std::string_view::npos) {
    host = text.substr(0, colon);
    const std::string_view p = text.substr(colon + 1);
    if (p.empty()) return "no port after the ':'";
    if (!all_digits(p)) return "port '" + std::string(p) + "' is not a number";
    // Six digits or more are out of range whatever they say; stoul would not overflow below that.
    if (p.size() > 5 || std::stoul(std::string(p)) > 65535 || std::stoul(std::string(p)) == 0)
      return "port " + std::string(p) + " out of range 1..65535";
    port = static_cast<std::uint16_t>(std::stoul(std::string(p)));
  }
  if (auto why = parse_host(host); !why.empty()) return why;
  out.host = std::string(host);
  out.port = port;
  return {};
}

std::string parse_interface(std::string_view text, Address& out) {
  if (text.empty()) return "empty interface";
  if (digits_and_dots(text)) {
    if (!is_ipv4(text)) return "'" + std::string(text) + "' is not an IPv4 address (four numbers 0..255)";
    if (auto why = not_a_host(text); !why.empty()) return why;
  } else if (text.size() > kMaxInterfaceName || text == "." || text == ".." ||
             std::any_of(text.begin(), text.end(),
                         [](char c) { return c == '/' || c == ':' || std::isspace(static_cast<unsigned char>(c)); })) {
    return "'" + std::string(text) +
           "' is not an interface name (1..15 characters, no '/', ':' or space) "
           "or an IPv4 address";
  }
  out.host = std::string(text);
  out.port = 0;
  return {};
}

NetworkLookup system_lookup() {
  NetworkLookup l;
  l.local_addresses = [] {
    std::vector<LocalAddress> out;
    ifaddrs* list = nullptr;
    if (::getifaddrs(&list) != 0) return out;
    const std::unique_ptr<ifaddrs, decltype(&::freeifaddrs)> guard(list, &::freeifaddrs);
    for (const ifaddrs* a = list; a; a = a->ifa_next) {
      if (!a->ifa_addr || a->ifa_addr->sa_family != AF_INET || !a->ifa_name) continue;
      char text[INET_ADDRSTRLEN] = {};
      const auto* in = reinterpret_cast<const sockaddr_in*>(a->ifa_addr);
      if (::inet_ntop(AF_INET, &in->sin_addr, text, sizeof text)) out.push_back({a->ifa_name, text});
    }
    return out;
  };
  l.host_addresses = [](const std::string& host) {
    std::vector<std::string> out;
    addrinfo hints{};
    hints.ai_family = AF_INET;
    hints.ai_socktype = SOCK_DGRAM;
    addrinfo* res = nullptr;
    if (::getaddrinfo(host.c_str(), nullptr, &hints, &res) != 0) return out;
    const std::unique_ptr<addrinfo, decltype(&::freeaddrinfo)> guard(res, &::freeaddrinfo);
    for (const addrinfo* a = res; a; a = a->ai_next) {
      char text[INET_ADDRSTRLEN] = {};
      const auto* in = reinterpret_cast<const sockaddr_in*>(a->ai_addr);
      if (::inet_ntop(AF_INET, &in->sin_addr, text, sizeof text) &&
          std::find(out.begin(), out.end(), text) == out.end())
        out.emplace_back(text);
    }
    return out;
  };
  return l;
}

ResolvedNetwork resolve_network(const NetworkConfig& config, const NetworkLookup& lookup) {
  ResolvedNetwork r;
  r.mode = config.mode;
  // A literal address is used as written; only names go to the resolver.
  const auto addresses_of = [&](const Address& a, const char* what) {
    if (is_ipv4(a.host)) return std::vector<std::string>{a.host};
    auto found = lookup.host_addresses(a.host);
    if (found.empty())
      throw NetworkError(a.where + ": " + what + " '" + a.text + "': host name '" + a.host +
                         "' does not resolve to an IPv4 address");
    return found;
  };
  std::string summary = std::string(to_string(config.mode)) + " discovery";
  std::vector<std::string> shown;
  if (config.mode == DiscoveryMode::Unicast) {
    for (const auto& p : config.peers)
      for (const auto& ip : addresses_of(p, "peer")) {
        const Ipv4Endpoint e{ip, p.port};
        // "localhost" and "127.0.0.1" are the same peer: once is enough.
        if (std::find(r.peers.begin(), r.peers.end(), e) == r.peers.end()) r.peers.push_back(e);
      }
    for (const auto& e : r.peers) shown.push_back(endpoint_text(e));
    summary += " to " + join(shown);
  } else if (config.mode == DiscoveryMode::Server) {
    for (const auto& s : config.servers) {
      ResolvedServer rs;
      if (s.host.empty()) {  // an id left unused
        r.servers.push_back(std::move(rs));
        continue;
      }
      const std::uint16_t port = s.port ? s.port : kDefaultServerPort;
      for (const auto& ip : addresses_of(s, "server")) rs.locators.push_back({ip, port});
      std::vector<std::string> l;
      for (const auto& e : rs.locators) l.push_back(endpoint_text(e));
      shown.push_back("id " + std::to_string(r.servers.size()) + " at " + join(l));
      r.servers.push_back(std::move(rs));
    }
    summary += " through Discovery Server " + join(shown);
  }
  std::vector<std::string> interfaces;
  const std::vector<LocalAddress> local =
      config.interfaces.empty() ? std::vector<LocalAddress>{} : lookup.local_addresses();
  const auto add = [&](const std::string& ip) {
    if (std::find(r.interface_addresses.begin(), r.interface_addresses.end(), ip) == r.interface_addresses.end())
      r.interface_addresses.push_back(ip);
  };
  for (const auto& i : config.interfaces) {
    std::vector<std::string> found;
    std::string name;
    for (const auto& l : local) {
      if (is_ipv4(i.host) ? l.address == i.host : l.interface == i.host) found.push_back(l.address);
      if (is_ipv4(i.host) && l.address == i.host) name = l.interface;
    }
    if (found.empty()) {
      // Fast DDS would drop it without a word and, with nothing left, bind to 192.0.2.0.
      std::set<std::string> have;
      for (const auto& l : local) have.insert(l.interface + " " + l.address);
      throw NetworkError(i.where + ": interface '" + i.text + "': " +
                         (is_ipv4(i.host) ? "no interface of this machine has this address"
                                          : "no such interface, or it has no IPv4 address") +
                         " (this machine: " + (have.empty() ? std::string("none") : join({have.begin(), have.end()})) +
                         ")");
    }
    // "lo" and "127.0.0.1" are one interface: listed (and shown) once.
    if (std::all_of(found.begin(), found.end(), [&](const std::string& ip) {
          return std::find(r.interface_addresses.begin(), r.interface_addresses.end(), ip) !=
                 r.interface_addresses.end();
        }))
      continue;
    for (const auto& ip : found) add(ip);
    interfaces.push_back(join(found) + " (" + (is_ipv4(i.host) ? name : i.host) + ")");
  }
  if (!interfaces.empty()) {
    // Loopback always: Fast DDS 2.9 sends to a participant on this host through 127.0.0.1
    // whenever its own allowlist admits loopback (UDPTransportInterface::transform_remote_locator),
    // and drops a same-host address its allowlist lacks; without 127.0.0.1 here, pmuctl beside
    // pmu-service could not reach it. Loopback never leaves the host, and Fast DDS announces
    // no loopback address to others while another address is allowed.
    const bool had_loopback = std::find(r.interface_addresses.begin(), r.interface_addresses.end(), "127.0.0.1") !=
                              r.interface_addresses.end();
    if (!had_loopback) r.interface_addresses.push_back("127.0.0.1");
    summary += "; DDS over UDP only on " + join(interfaces) + (had_loopback ? "" : " and loopback (127.0.0.1)");
  }
  r.link = link_plan(config.link);
  // The profile's one agent worker spares aircraft the discovery of more ground
  // participants; through a Discovery Server a new participant costs them a few endpoints,
  // and eight calls at once want the agent's workers (interface.md 7.3).
  if (config.mode == DiscoveryMode::Server) r.link.agent_workers = 0;
  // The summary is what pmuctl compares with its agent's (a call on another link is not the
  // agent's to serve) and what the start-up log shows.
  if (r.link.profile != LinkProfile::None) summary += std::string("; link profile ") + to_string(r.link.profile);
  if (r.link.round_trip.set())
    summary += "; link round trip " + std::to_string(r.link.round_trip.value.count()) + " ms";
  r.summary = summary;
  return r;
}

}  // namespace pmu::dds
