#include "pmuctl/call/network_options.hpp"

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <set>
#include <utility>

namespace pmu::tools {
namespace {

std::string env(const char* name) {
  const char* v = std::getenv(name);
  return v ? std::string(v) : std::string();
}

std::string trimmed(const std::string& s) {
  const auto b = s.find_first_not_of(" \t");
  if (b == std::string::npos) return {};
  return s.substr(b, s.find_last_not_of(" \t") - b + 1);
}

// "a, b,c" -> {"a", "b", "c"}; an empty entry ("a,,b", "a,") stays, to be refused.
std::vector<std::string> split_commas(const std::string& s) {
  std::vector<std::string> out;
  std::size_t start = 0;
  for (;;) {
    const auto comma = s.find(',', start);
    out.push_back(trimmed(s.substr(start, comma == std::string::npos ? std::string::npos : comma - start)));
    if (comma == std::string::npos) return out;
    start = comma + 1;
  }
}

// Reads each entry with the config's functions; `where` names the option or variable.
// `empty_keeps_position`: an empty entry (",10.0.0.2") is a server id left unused; at least
// one must name a server.
std::optional<std::vector<dds::Address>> addresses(const std::vector<std::string>& texts, const std::string& where,
                                                   bool interface, bool empty_keeps_position = false) {
  std::vector<dds::Address> out;
  std::set<std::pair<std::string, std::uint16_t>> seen;
  for (const auto& text : texts) {
    dds::Address a;
    a.text = text;
    a.where = where;
    if (empty_keeps_position && text.empty()) {
      out.push_back(std::move(a));
      continue;
    }
    const std::string why = interface ? dds::parse_interface(text, a) : dds::parse_address(text, a);
    if (!why.empty()) {
      std::fprintf(stderr, "pmuctl: %s '%s': %s\n", where.c_str(), text.c_str(), why.c_str());
      return std::nullopt;
    }
    std::string host = a.host;
    std::transform(host.begin(), host.end(), host.begin(), [](unsigned char c) { return std::tolower(c); });
    if (!seen.insert({host, a.port}).second) {
      std::fprintf(stderr, "pmuctl: %s '%s' given twice\n", where.c_str(), text.c_str());
      return std::nullopt;
    }
    out.push_back(std::move(a));
  }
  if (empty_keeps_position &&
      std::all_of(out.begin(), out.end(), [](const dds::Address& a) { return a.host.empty(); })) {
    std::fprintf(stderr, "pmuctl: %s names no server (an empty entry only leaves its id unused)\n", where.c_str());
    return std::nullopt;
  }
  return out;
}

}  // namespace

bool resolve_network_options(const NetworkOptions& o, const dds::NetworkLookup& lookup, bool secure,
                             dds::ResolvedNetwork& out) {
  dds::NetworkConfig config;
  // Discovery: the options if any is given, else the environment; never a mix, so an
  // exported variable cannot quietly change what the command line asked for.
  std::vector<std::string> peers = o.peers, servers;
  std::string peers_from = "--peer", servers_from = "--discovery-server";
  if (!o.discovery_servers.empty()) servers = split_commas(o.discovery_servers);
  if (!peers.empty() && !servers.empty()) {
    std::fprintf(stderr, "pmuctl: --peer (unicast discovery) and --discovery-server exclude each other\n");
    return false;
  }
  if (peers.empty() && servers.empty()) {
    const std::string env_peers = env("PMU_DDS_PEERS"), env_servers = env("PMU_DISCOVERY_SERVER");
    if (!env_peers.empty() && !env_servers.empty()) {
      std::fprintf(stderr,
                   "pmuctl: PMU_DDS_PEERS (unicast discovery) and PMU_DISCOVERY_SERVER are both set: "
                   "unset one, or give --peer or --discovery-server\n");
      return false;
    }
    if (!env_peers.empty()) {
      peers = split_commas(env_peers);
      peers_from = "PMU_DDS_PEERS";
    }
    if (!env_servers.empty()) {
      servers = split_commas(env_servers);
      servers_from = "PMU_DISCOVERY_SERVER";
    }
  }
  if (!peers.empty()) {
    auto a = addresses(peers, peers_from, false);
    if (!a) return false;
    config.mode = dds::DiscoveryMode::Unicast;
    config.peers = std::move(*a);
  } else if (!servers.empty()) {
    auto a = addresses(servers, servers_from, false, true);
    if (!a) return false;
    if (a->size() > dds::kMaxServers) {
      std::fprintf(stderr, "pmuctl: %s: more than %zu servers (server ids are 0..255)\n", servers_from.c_str(),
                   dds::kMaxServers);
      return false;
    }
    if (secure) {
      std::fprintf(stderr, "pmuctl: %s %s\n", servers_from.c_str(), dds::kServerWithSecurity);
      return false;
    }
    config.mode = dds::DiscoveryMode::Server;
    config.servers = std::move(*a);
  }

  std::vector<std::string> interfaces = o.interfaces;
  std::string interfaces_from = "--interface";
  if (interfaces.empty()) {
    if (const std::string e = env("PMU_DDS_INTERFACES"); !e.empty()) {
      interfaces = split_commas(e);
      interfaces_from = "PMU_DDS_INTERFACES";
    }
  }
  auto i = addresses(interfaces, interfaces_from, true);
  if (!i) return false;
  config.interfaces = std::move(*i);

  // The link: the option, else the variable (the option wins, also --link none).
  std::string link = o.link, link_from = "--link";
  if (link.empty()) {
    link = env("PMU_LINK");
    link_from = "PMU_LINK";
  }
  if (!link.empty()) {
    const auto profile = dds::parse_link_profile(link);
    if (!profile) {
      std::fprintf(stderr, "pmuctl: %s '%s': not a link profile (one of: %s)\n", link_from.c_str(), link.c_str(),
                   dds::kLinkProfileNames);
      return false;
    }
    config.link.profile = *profile;
    config.link.profile_where = link_from;
  }

  try {
    out = dds::resolve_network(config, lookup);
  } catch (const dds::NetworkError& e) {
    std::fprintf(stderr, "pmuctl: %s\n", e.what());
    return false;
  }
  return true;
}

}  // namespace pmu::tools
