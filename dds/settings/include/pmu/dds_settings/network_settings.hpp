#pragma once
// How a participant finds others and which network interfaces DDS may use: the config's
// `discovery:` and `interfaces:` keys and pmuctl's --peer, --discovery-server and
// --interface (interface.md section 7.2). No Fast DDS type here, so the configuration can
// name the choice; dds_participant.hpp turns a ResolvedNetwork into participant QoS.
//
// Purpose: one reading of an address or an interface for the config file and pmuctl alike,
// with the same messages, and a look-up of names that tests can replace.
//
// Assumptions: Fast DDS 2.9's UDPv4 transport. Its interface allowlist
// (UDPv4TransportDescriptor::interfaceWhiteList) compares the local IPv4 addresses with the
// strings it is given, so an interface name there matches nothing (the transport then logs
// "All whitelist interfaces were filtered out" and binds to 192.0.2.0, TEST-NET-1): names
// are turned into their addresses here, once, at start, and 127.0.0.1 is added to every
// allowlist (same-host participants reach each other through it; resolve_network says why).
// A peer or server given as a host name is resolved at start too; a later change of its
// address needs a restart.
//
// Error handling: parsing returns the reason as text (parse_address: empty when the text
// is good); resolve_network, a start-up step, throws NetworkError "WHERE: what" where
// WHERE is the entry's origin ("FILE:LINE", "--peer", "PMU_DDS_PEERS").
//
// Security considerations: the addresses come from the operator (a file only root may
// write, the command line); they are checked strictly (four decimal numbers 0..255, host
// names of letters, digits, '-' and '.') so nothing else reaches the resolver or Fast DDS.
//
// Worked examples (parse_address):
//   "192.168.10.2"  -> host "192.168.10.2", port 0 (unicast: the domain's well-known ports)
//   "10.0.0.7:7412" -> host "10.0.0.7", port 7412
//   "gcs.local"     -> host "gcs.local", port 0 (resolved at start)
//   "10.0.0.7:0"    -> "port 0 out of range 1..65535"

#include <array>
#include <cstdint>
#include <functional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "pmu/dds_settings/link_profile.hpp"

namespace pmu::dds {

enum class DiscoveryMode {
  Multicast,  // Fast DDS's default (SPDP to 239.255.0.1 and the domain's well-known ports)
  Unicast,    // SPDP only to the listed peers; no multicast socket, nothing sent to a group
  Server,     // a CLIENT of Fast DDS Discovery Servers (`fastdds discovery`)
};

const char* to_string(DiscoveryMode mode) noexcept;

// One entry as written: an IPv4 address or a host name, and a UDP port (0: none given).
struct Address {
  std::string text;  // as written, for messages
  std::string host;  // "10.0.0.7", "gcs.local"
  std::uint16_t port = 0;
  std::string where;  // "FILE:LINE", "--peer", "PMU_DDS_PEERS": where it came from
};

struct NetworkConfig {
  DiscoveryMode mode = DiscoveryMode::Multicast;
  std::vector<Address> peers;  // Unicast: at least one
  // Server: the position is the server id; an entry with an empty host leaves its id unused
  // (a server of id 1 alone: ["", "10.0.0.2"]), and at least one names a server.
  std::vector<Address> servers;
  std::vector<Address> interfaces;  // empty: every interface; host = a name or an IPv4 address
  LinkSettings link;                // `link:` / --link: the link's profile and round trip (link_profile.hpp)
};

inline constexpr std::uint16_t kDefaultServerPort = 11811;  // `fastdds discovery`'s default
inline constexpr std::size_t kMaxServers = 256;             // server ids 0..255 (a GUID prefix byte)

// Why DDS-Security and Discovery Server mode are refused together (config and pmuctl): with
// Fast DDS 2.9.1, secure clients ignore a server that does not authenticate, and a server
// with DDS-Security no longer has the GUID prefix `fastdds discovery -i N` gives it (the
// PKI-DH plugin derives the prefix from the certificate), so clients find nothing either
// way; they also abort in SecurityManager::encode_rtps_message (an assertion Debian's build
// keeps) when they stop. Unicast peers work with DDS-Security.
inline constexpr const char* kServerWithSecurity =
    "cannot be combined with DDS-Security in Fast DDS 2.9.1: secure participants find nothing through a "
    "Discovery Server (an unauthenticated server is ignored, and a secure one loses the GUID prefix its id "
    "gives it); use unicast peers";

// "HOST[:PORT]" into `out` (host and port; text and where are left alone). Empty result:
// good; otherwise what is wrong, e.g. "port 70000 out of range 1..65535".
std::string parse_address(std::string_view text, Address& out);
// An interface: an IPv4 address, or a name (1..15 characters, no '/', ':' or white space).
std::string parse_interface(std::string_view text, Address& out);
// True when `text` is four decimal numbers 0..255 separated by dots (no leading zeros).
bool is_ipv4(std::string_view text) noexcept;

// One IPv4 address of this machine and the interface that has it.
struct LocalAddress {
  std::string interface;  // "eth1"
  std::string address;    // "192.168.10.1"
};

// The look-ups resolve_network needs, replaceable in tests.
struct NetworkLookup {
  // Every IPv4 address of this machine's interfaces.
  std::function<std::vector<LocalAddress>()> local_addresses;
  // A host name's IPv4 addresses (dotted); empty: it does not resolve.
  std::function<std::vector<std::string>(const std::string& host)> host_addresses;
};
// getifaddrs(3) and getaddrinfo(3) (AF_INET).
NetworkLookup system_lookup();

struct Ipv4Endpoint {
  std::string address;     // dotted IPv4
  std::uint16_t port = 0;  // 0: not given
  bool operator==(const Ipv4Endpoint& o) const { return address == o.address && port == o.port; }
};

// A server and every address its host name resolved to.
struct ResolvedServer {
  std::vector<Ipv4Endpoint> locators;  // each with the server's port (11811 if none given); empty: an id left unused
};

// NetworkConfig with every name replaced by its addresses: what the participant QoS needs.
struct ResolvedNetwork {
  DiscoveryMode mode = DiscoveryMode::Multicast;
  std::vector<Ipv4Endpoint> peers;      // Unicast
  std::vector<ResolvedServer> servers;  // Server; index = server id
  // Empty: every interface. Otherwise the allowed addresses, 127.0.0.1 always among them
  // (same-host traffic; resolve_network says why).
  std::vector<std::string> interface_addresses;
  // The link's values (link_profile.hpp): announcement period, lease, heartbeat floor.
  LinkPlan link;
  // One line for the start-up log, e.g. "unicast discovery to 127.0.0.1; interfaces 10.0.0.1 (eth1)".
  std::string summary;
};

class NetworkError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Resolves names through `lookup`. Throws NetworkError("WHERE: what") for an interface that
// does not exist or has no IPv4 address, an address no interface of this machine has, and a
// host name that does not resolve.
ResolvedNetwork resolve_network(const NetworkConfig& config, const NetworkLookup& lookup);

}  // namespace pmu::dds
