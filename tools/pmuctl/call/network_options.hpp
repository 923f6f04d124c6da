#pragma once
// pmuctl's discovery and interface options (interface.md section 7.2): --peer,
// --discovery-server, --interface, or the environment variables PMU_DDS_PEERS,
// PMU_DISCOVERY_SERVER and PMU_DDS_INTERFACES (comma separated) when the options are absent;
// and the link's profile, --link or PMU_LINK (radio, none; interface.md section 7.3).
// Entries are read by the same functions as pmu-service's config (network_settings.hpp), so the
// same text means the same thing in both.
//
//   --peer 10.0.0.7 --peer gcs.local:7412   -> unicast discovery to both (multicast off)
//   --discovery-server 10.0.0.1,10.0.0.2     -> client of servers 0 and 1, port 11811
//   PMU_DDS_INTERFACES=eth1,192.168.10.1     -> DDS over UDP only on those
//   PMU_LINK=radio --link none               -> no link profile (the option wins)
//
// Error handling: false after printing to stderr what is wrong, naming the option or the
// variable ("pmuctl: --peer '10.0.0.7:0': port 0 out of range 1..65535"); pmuctl then exits 2.

#include <string>
#include <vector>

#include "pmu/dds_settings/network_settings.hpp"

namespace pmu::tools {

struct NetworkOptions {
  std::vector<std::string> peers;       // --peer, once per address
  std::string discovery_servers;        // --discovery-server ADDR[,ADDR...]
  std::vector<std::string> interfaces;  // --interface, once per interface
  std::string link;                     // --link PROFILE (link_profile.hpp); empty: $PMU_LINK
};

// The options, else the environment, into `out` with names looked up through `lookup`.
// `secure`: DDS-Security is on, which a Discovery Server cannot serve (dds::kServerWithSecurity).
bool resolve_network_options(const NetworkOptions& options, const dds::NetworkLookup& lookup, bool secure,
                             dds::ResolvedNetwork& out);

}  // namespace pmu::tools
