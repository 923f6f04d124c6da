// network_settings.hpp: addresses and interfaces as the config and pmuctl read them, and their
// look-up at start through a fake NetworkLookup (no real interface or name server).
#include <gtest/gtest.h>

#include <algorithm>

#include "pmu/dds_settings/network_settings.hpp"

namespace pmu::dds {
namespace {

// The worked examples of network_settings.hpp.
TEST(NetworkAddress, WorkedExamples) {
  Address a;
  EXPECT_EQ(parse_address("192.168.10.2", a), "");
  EXPECT_EQ(a.host, "192.168.10.2");
  EXPECT_EQ(a.port, 0);
  EXPECT_EQ(parse_address("10.0.0.7:7412", a), "");
  EXPECT_EQ(a.host, "10.0.0.7");
  EXPECT_EQ(a.port, 7412);
  EXPECT_EQ(parse_address("gcs.local", a), "");
  EXPECT_EQ(a.host, "gcs.local");
  EXPECT_EQ(a.port, 0);
  EXPECT_EQ(parse_address("10.0.0.7:0", a), "port 0 out of range 1..65535");
  EXPECT_EQ(parse_address("10.0.0.7:65535", a), "");
  EXPECT_EQ(a.port, 65535);
  EXPECT_EQ(parse_address("10.0.0.7:00080", a), "") << "leading zeros in a port are still the number";
  EXPECT_EQ(a.port, 80);
}

TEST(NetworkAddress, Ipv4IsFourDecimalNumbersUpTo255) {
  for (const char* good : {"0.0.0.0", "127.0.0.1", "255.255.255.255", "10.20.30.40"})
    EXPECT_TRUE(is_ipv4(good)) << good;
  for (const char* bad :
       {"", "1.2.3", "1.2.3.4.5", "256.1.1.1", "01.2.3.4", "1..2.3", "1.2.3.4.", "a.b.c.d", "1.2.3.-4", "1234.1.1.1"})
    EXPECT_FALSE(is_ipv4(bad)) << bad;
}

TEST(NetworkAddress, InterfacesAreNamesOrAddresses) {
  Address a;
  EXPECT_EQ(parse_interface("eth1", a), "");
  EXPECT_EQ(a.host, "eth1");
  EXPECT_EQ(parse_interface("enp0s31f6", a), "");
  EXPECT_EQ(parse_interface("wlan0.100", a), "") << "a VLAN interface name has a dot";
  EXPECT_EQ(parse_interface("192.168.10.1", a), "");
  EXPECT_EQ(a.host, "192.168.10.1");
  EXPECT_NE(parse_interface("..", a), "");
  EXPECT_NE(parse_interface("eth 1", a), "");
  EXPECT_NE(parse_interface("", a), "");
  EXPECT_NE(parse_interface("224.0.0.1", a), "") << "multicast is no interface's address";
}

// A machine with lo, eth1 (two addresses) and wlan0, and one name server entry.
NetworkLookup fake_lookup(int* host_lookups = nullptr) {
  NetworkLookup l;
  l.local_addresses = [] {
    return std::vector<LocalAddress>{
        {"lo", "127.0.0.1"}, {"eth1", "192.168.10.1"}, {"eth1", "192.168.11.1"}, {"wlan0", "10.1.1.5"}};
  };
  l.host_addresses = [host_lookups](const std::string& host) {
    if (host_lookups) ++*host_lookups;
    if (host == "gcs.local") return std::vector<std::string>{"192.168.10.20", "192.168.11.20"};
    if (host == "localhost") return std::vector<std::string>{"127.0.0.1"};
    return std::vector<std::string>{};
  };
  return l;
}

Address address(const std::string& text, const std::string& where = "f.yaml:3") {
  Address a;
  a.text = text;
  a.where = where;
  EXPECT_EQ(parse_address(text, a), "") << text;
  return a;
}

Address interface(const std::string& text, const std::string& where = "f.yaml:9") {
  Address a;
  a.text = text;
  a.where = where;
  EXPECT_EQ(parse_interface(text, a), "") << text;
  return a;
}

TEST(NetworkResolve, MulticastOnEveryInterfaceNeedsNoLookup) {
  NetworkLookup none;  // any call would throw std::bad_function_call
  const ResolvedNetwork r = resolve_network(NetworkConfig{}, none);
  EXPECT_EQ(r.mode, DiscoveryMode::Multicast);
  EXPECT_TRUE(r.interface_addresses.empty());
  EXPECT_EQ(r.summary, "multicast discovery");
}

TEST(NetworkResolve, PeersNamesResolvedAddressesAsWrittenDuplicatesOnce) {
  NetworkConfig c;
  c.mode = DiscoveryMode::Unicast;
  c.peers = {address("10.0.0.7:7412"), address("gcs.local"), address("localhost"), address("127.0.0.1")};
  int lookups = 0;
  const ResolvedNetwork r = resolve_network(c, fake_lookup(&lookups));
  EXPECT_EQ(lookups, 2) << "literal addresses never reach the resolver";
  ASSERT_EQ(r.peers.size(), 4u);
  EXPECT_EQ(r.peers[0], (Ipv4Endpoint{"10.0.0.7", 7412}));
  EXPECT_EQ(r.peers[1], (Ipv4Endpoint{"192.168.10.20", 0}));
  EXPECT_EQ(r.peers[2], (Ipv4Endpoint{"192.168.11.20", 0}));
  EXPECT_EQ(r.peers[3], (Ipv4Endpoint{"127.0.0.1", 0})) << "localhost and 127.0.0.1 once";
  EXPECT_EQ(r.summary, "unicast discovery to 10.0.0.7:7412, 192.168.10.20, 192.168.11.20, 127.0.0.1");
}

TEST(NetworkResolve, ServersKeepTheirPositionAndGetTheDefaultPort) {
  NetworkConfig c;
  c.mode = DiscoveryMode::Server;
  c.servers = {address("10.0.0.1"), address("gcs.local:14520")};
  const ResolvedNetwork r = resolve_network(c, fake_lookup());
  ASSERT_EQ(r.servers.size(), 2u);
  ASSERT_EQ(r.servers[0].locators.size(), 1u);
  EXPECT_EQ(r.servers[0].locators[0], (Ipv4Endpoint{"10.0.0.1", kDefaultServerPort}));
  ASSERT_EQ(r.servers[1].locators.size(), 2u) << "every address of the name is a locator of server 1";
  EXPECT_EQ(r.servers[1].locators[1], (Ipv4Endpoint{"192.168.11.20", 14520}));
  EXPECT_EQ(r.summary,
            "server discovery through Discovery Server id 0 at 10.0.0.1:11811, id 1 at 192.168.10.20:14520, "
            "192.168.11.20:14520");
}

// The radio profile's single agent worker holds for multicast and unicast discovery only:
// through a Discovery Server a ground participant costs the aircraft a few endpoints, and
// the agent keeps its workers (interface.md 7.3).
TEST(NetworkResolve, TheRadioProfileLimitsTheAgentsWorkersOnlyWithoutADiscoveryServer) {
  const struct {
    DiscoveryMode mode;
    int workers;
  } cases[] = {{DiscoveryMode::Multicast, 1}, {DiscoveryMode::Unicast, 1}, {DiscoveryMode::Server, 0}};
  for (const auto& k : cases) {
    SCOPED_TRACE(to_string(k.mode));
    NetworkConfig c;
    c.mode = k.mode;
    if (k.mode == DiscoveryMode::Unicast) c.peers = {address("10.0.0.7")};
    if (k.mode == DiscoveryMode::Server) c.servers = {address("10.0.0.1")};
    c.link.profile = LinkProfile::Radio;
    const ResolvedNetwork r = resolve_network(c, fake_lookup());
    EXPECT_EQ(r.link.agent_workers, k.workers);
    EXPECT_EQ(r.link.round_trip.value.count(), 700) << "the rest of the profile holds";
    const auto lines = r.link.explain();
    const bool says_workers = std::any_of(
        lines.begin(), lines.end(), [](const std::string& l) { return l.find("agent runs") != std::string::npos; });
    EXPECT_EQ(says_workers, k.workers > 0);
  }
}

TEST(NetworkResolve, AnEmptyServerEntryKeepsItsIdAndHasNoLocator) {
  NetworkConfig c;
  c.mode = DiscoveryMode::Server;
  Address unused;
  unused.where = "f.yaml:3";
  c.servers = {unused, address("10.0.0.2")};
  NetworkLookup none;  // nothing to look up
  none.local_addresses = [] { return std::vector<LocalAddress>{}; };
  const ResolvedNetwork r = resolve_network(c, none);
  ASSERT_EQ(r.servers.size(), 2u);
  EXPECT_TRUE(r.servers[0].locators.empty());
  ASSERT_EQ(r.servers[1].locators.size(), 1u);
  EXPECT_EQ(r.servers[1].locators[0], (Ipv4Endpoint{"10.0.0.2", kDefaultServerPort}));
  EXPECT_EQ(r.summary, "server discovery through Discovery Server id 1 at 10.0.0.2:11811");
}

TEST(NetworkResolve, InterfaceNamesBecomeTheirAddresses) {
  NetworkConfig c;
  c.interfaces = {interface("eth1"), interface("10.1.1.5"), interface("lo"), interface("127.0.0.1")};
  const ResolvedNetwork r = resolve_network(c, fake_lookup());
  EXPECT_EQ(r.interface_addresses, (std::vector<std::string>{"192.168.10.1", "192.168.11.1", "10.1.1.5", "127.0.0.1"}));
  EXPECT_EQ(r.summary,
            "multicast discovery; DDS over UDP only on 192.168.10.1, 192.168.11.1 (eth1), 10.1.1.5 (wlan0), "
            "127.0.0.1 (lo)");
}

TEST(NetworkResolve, LoopbackIsAlwaysAllowedSoSameHostParticipantsMeet) {
  NetworkConfig c;
  c.interfaces = {interface("eth1")};
  const ResolvedNetwork r = resolve_network(c, fake_lookup());
  EXPECT_EQ(r.interface_addresses, (std::vector<std::string>{"192.168.10.1", "192.168.11.1", "127.0.0.1"}));
  EXPECT_EQ(r.summary,
            "multicast discovery; DDS over UDP only on 192.168.10.1, 192.168.11.1 (eth1) and loopback "
            "(127.0.0.1)");
}

TEST(NetworkResolve, WhatCannotBeFoundIsAStartupErrorAtItsLine) {
  const auto message = [](const NetworkConfig& c) {
    try {
      (void)resolve_network(c, fake_lookup());
    } catch (const NetworkError& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  NetworkConfig c;
  c.interfaces = {interface("eth7", "/etc/pmu-dds/pmu-service.yaml:12")};
  EXPECT_EQ(message(c),
            "/etc/pmu-dds/pmu-service.yaml:12: interface 'eth7': no such interface, or it has no IPv4 "
            "address (this machine: eth1 192.168.10.1, eth1 192.168.11.1, lo 127.0.0.1, wlan0 10.1.1.5)");
  // Fast DDS 2.9 would silently drop an address no interface has, and bind nowhere useful.
  c.interfaces = {interface("192.168.99.1", "--interface")};
  EXPECT_EQ(message(c),
            "--interface: interface '192.168.99.1': no interface of this machine has this address (this "
            "machine: eth1 192.168.10.1, eth1 192.168.11.1, lo 127.0.0.1, wlan0 10.1.1.5)");
  NetworkConfig u;
  u.mode = DiscoveryMode::Unicast;
  u.peers = {address("nowhere.invalid:7412", "PMU_DDS_PEERS")};
  EXPECT_EQ(message(u),
            "PMU_DDS_PEERS: peer 'nowhere.invalid:7412': host name 'nowhere.invalid' does not resolve to an IPv4 "
            "address");
  NetworkConfig s;
  s.mode = DiscoveryMode::Server;
  s.servers = {address("10.0.0.1"), address("nowhere.invalid", "f.yaml:8")};
  EXPECT_EQ(message(s),
            "f.yaml:8: server 'nowhere.invalid': host name 'nowhere.invalid' does not resolve to an IPv4 "
            "address");
}

}  // namespace
}  // namespace pmu::dds
