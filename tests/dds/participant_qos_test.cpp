// participant_qos (dds_participant.hpp): the Fast DDS settings each discovery mode, interface
// allowlist and transport choice produce, read back from the QoS a participant would be
// created with. Creating no participant, it needs no network.
#include <gtest/gtest.h>

#include <optional>

#include <fastdds/rtps/attributes/ServerAttributes.h>
#include <fastdds/rtps/transport/UDPv4TransportDescriptor.h>
#include <fastdds/rtps/transport/shared_mem/SharedMemTransportDescriptor.h>
#include <fastrtps/utils/IPLocator.h>

#include <map>
#include <sstream>

#include "pmu/dds/dds_participant.hpp"

namespace pmu::dds {
namespace {

using eprosima::fastdds::dds::DomainParticipantQos;
using eprosima::fastdds::rtps::SharedMemTransportDescriptor;
using eprosima::fastdds::rtps::UDPv4TransportDescriptor;
using eprosima::fastrtps::Duration_t;
using eprosima::fastrtps::rtps::DiscoveryProtocol_t;
using eprosima::fastrtps::rtps::IPLocator;
using eprosima::fastrtps::rtps::Locator_t;

std::string text(const Locator_t& l) { return IPLocator::toIPv4string(l) + ":" + std::to_string(l.port); }

std::vector<std::string> texts(const eprosima::fastrtps::rtps::LocatorList_t& list) {
  std::vector<std::string> v;
  for (const auto& l : list) {
    EXPECT_EQ(l.kind, LOCATOR_KIND_UDPv4);
    v.push_back(text(l));
  }
  return v;
}

const UDPv4TransportDescriptor* udp_of(const DomainParticipantQos& q) {
  for (const auto& t : q.transport().user_transports)
    if (auto* u = dynamic_cast<const UDPv4TransportDescriptor*>(t.get())) return u;
  return nullptr;
}

bool has_shm(const DomainParticipantQos& q) {
  for (const auto& t : q.transport().user_transports)
    if (dynamic_cast<const SharedMemTransportDescriptor*>(t.get())) return true;
  return false;
}

ResolvedNetwork unicast(std::vector<Ipv4Endpoint> peers) {
  ResolvedNetwork n;
  n.mode = DiscoveryMode::Unicast;
  n.peers = std::move(peers);
  return n;
}

ResolvedNetwork server(std::vector<ResolvedServer> servers) {
  ResolvedNetwork n;
  n.mode = DiscoveryMode::Server;
  n.servers = std::move(servers);
  return n;
}

TEST(ParticipantQos, MulticastIsFastDdsDefaultDiscoveryUntouched) {
  const DomainParticipantQos q = participant_qos("pmu-service", Transport::Default, {}, {});
  const DomainParticipantQos fast_dds_default;
  EXPECT_EQ(q.name().to_string(), "pmu-service");
  EXPECT_TRUE(q.wire_protocol().builtin.discovery_config == fast_dds_default.wire_protocol().builtin.discovery_config);
  EXPECT_TRUE(q.wire_protocol().builtin.initialPeersList == fast_dds_default.wire_protocol().builtin.initialPeersList);
  EXPECT_EQ(q.wire_protocol().builtin.discovery_config.discoveryProtocol, DiscoveryProtocol_t::SIMPLE);
  EXPECT_TRUE(q.wire_protocol().builtin.metatrafficMulticastLocatorList.empty()) << "Fast DDS fills in its defaults";
  EXPECT_TRUE(q.properties() == fast_dds_default.properties()) << "no security";
}

TEST(ParticipantQos, UnicastSendsOnlyToPeersAndListensOnlyOnUnicast) {
  const DomainParticipantQos q =
      participant_qos("pmuctl", Transport::UdpOnly, unicast({{"127.0.0.1", 0}, {"10.0.0.7", 7412}}), {});
  const auto& b = q.wire_protocol().builtin;
  EXPECT_EQ(b.discovery_config.discoveryProtocol, DiscoveryProtocol_t::SIMPLE);
  // Port 0: Fast DDS expands it to the domain's well-known unicast ports (participant ids 0..3).
  EXPECT_EQ(texts(b.initialPeersList), (std::vector<std::string>{"127.0.0.1:0", "10.0.0.7:7412"}));
  // An explicit metatraffic list without multicast: Fast DDS adds no 239.255.0.1 of its own.
  EXPECT_TRUE(b.metatrafficMulticastLocatorList.empty());
  EXPECT_EQ(texts(b.metatrafficUnicastLocatorList), (std::vector<std::string>{"0.0.0.0:0"}));
  EXPECT_TRUE(b.discovery_config.m_DiscoveryServers.empty());
  EXPECT_FALSE(q.transport().use_builtin_transports);
  ASSERT_EQ(q.transport().user_transports.size(), 1u);
  ASSERT_NE(udp_of(q), nullptr);
  EXPECT_TRUE(udp_of(q)->interfaceWhiteList.empty());
}

// Every endpoint has AUTOMATIC liveliness with an infinite lease, which needs no liveliness
// messages; Fast DDS's writer liveliness protocol would still match a builtin writer and
// reader with every participant discovered, whose handshake crossed a radio link once per
// ground participant and aircraft.
TEST(ParticipantQos, NoParticipantRunsTheWriterLivelinessProtocol) {
  ResolvedNetwork allowlist;
  allowlist.interface_addresses = {"127.0.0.1"};
  for (const auto& network :
       {ResolvedNetwork{}, unicast({{"127.0.0.1", 0}}), server({{{{"10.0.0.1", 11811}}}}), allowlist})
    EXPECT_FALSE(
        participant_qos("x", Transport::Default, network, {}).wire_protocol().builtin.use_WriterLivelinessProtocol);
  EXPECT_TRUE(DomainParticipantQos().wire_protocol().builtin.use_WriterLivelinessProtocol) << "Fast DDS's default";
}

// Fast DDS's builtin UDPv4 sends datagrams of up to 65,500 bytes, which cross a radio link
// as IP fragments: every participant has its own UDPv4 transport with the smaller size, in
// every transport choice and discovery mode.
TEST(ParticipantQos, EveryUdpTransportSendsDatagramsThatFitOnePacket) {
  ResolvedNetwork allowlist;
  allowlist.interface_addresses = {"192.168.10.1", "127.0.0.1"};
  for (const auto& network :
       {ResolvedNetwork{}, unicast({{"127.0.0.1", 0}}), server({{{{"10.0.0.1", 11811}}}}), allowlist})
    for (const auto transport : {Transport::Default, Transport::UdpOnly}) {
      const DomainParticipantQos q = participant_qos("x", transport, network, {});
      EXPECT_FALSE(q.transport().use_builtin_transports);
      ASSERT_NE(udp_of(q), nullptr);
      EXPECT_EQ(udp_of(q)->maxMessageSize, 1400u);
      EXPECT_LE(udp_of(q)->maxMessageSize, 1500u - 20u - 8u) << "one packet on a 1,500-byte MTU";
      EXPECT_EQ(has_shm(q), transport == Transport::Default) << "same-host traffic keeps shared memory";
    }
  // A DDS-Security handshake (certificates) must fit one of Fast DDS's messages.
  SecurityFiles files;
  files.identity_ca = files.identity_certificate = files.private_key = "x.pem";
  files.permissions_ca = files.governance = files.permissions = "x.p7s";
  EXPECT_EQ(udp_of(participant_qos("x", Transport::UdpOnly, {}, files))->maxMessageSize,
            UDPv4TransportDescriptor().maxMessageSize);
}

TEST(ParticipantQos, ServerModeIsAClientOfEachServerByPositionWithFastddsDiscoveryPrefixes) {
  const DomainParticipantQos q =
      participant_qos("pmu-service", Transport::Default,
                      server({{{{"10.0.0.1", 11811}}}, {{{"192.168.10.20", 14520}, {"192.168.11.20", 14520}}}}), {});
  const auto& b = q.wire_protocol().builtin;
  EXPECT_EQ(b.discovery_config.discoveryProtocol, DiscoveryProtocol_t::CLIENT);
  const auto& servers = b.discovery_config.m_DiscoveryServers;
  ASSERT_EQ(servers.size(), 2u);
  auto it = servers.begin();
  std::ostringstream p0, p1;
  p0 << it->guidPrefix;
  EXPECT_EQ(p0.str(), "44.53.00.5f.45.50.52.4f.53.49.4d.41") << "fastdds discovery -i 0";
  EXPECT_EQ(texts(it->metatrafficUnicastLocatorList), (std::vector<std::string>{"10.0.0.1:11811"}));
  EXPECT_TRUE(it->metatrafficMulticastLocatorList.empty());
  ++it;
  p1 << it->guidPrefix;
  EXPECT_EQ(p1.str(), "44.53.01.5f.45.50.52.4f.53.49.4d.41") << "fastdds discovery -i 1";
  EXPECT_EQ(texts(it->metatrafficUnicastLocatorList),
            (std::vector<std::string>{"192.168.10.20:14520", "192.168.11.20:14520"}));
  EXPECT_TRUE(b.metatrafficMulticastLocatorList.empty());
  EXPECT_EQ(texts(b.metatrafficUnicastLocatorList), (std::vector<std::string>{"0.0.0.0:0"}));
  EXPECT_TRUE(b.initialPeersList.empty());
}

// An entry left empty keeps its id unused: a client of server 1 alone has that server only.
TEST(ParticipantQos, AServerIdLeftUnusedIsNoServer) {
  const DomainParticipantQos q =
      participant_qos("pmu-service", Transport::Default, server({{}, {{{"10.0.0.2", 11811}}}}), {});
  const auto& servers = q.wire_protocol().builtin.discovery_config.m_DiscoveryServers;
  ASSERT_EQ(servers.size(), 1u);
  std::ostringstream p;
  p << servers.begin()->guidPrefix;
  EXPECT_EQ(p.str(), "44.53.01.5f.45.50.52.4f.53.49.4d.41") << "fastdds discovery -i 1";
  EXPECT_EQ(texts(servers.begin()->metatrafficUnicastLocatorList), (std::vector<std::string>{"10.0.0.2:11811"}));
}

// A client's announcements cross the radio link to the server: three per lease, not
// Fast DDS's every 3 s, and a lease longer than a 30 s dropout; the other modes keep Fast DDS's periods (a multicast participant that
// announced less often would be found later after a lost first announcement).
TEST(ParticipantQos, AServerClientAnnouncesThreeTimesPerLeaseAndTheOtherModesKeepFastDdsPeriods) {
  const auto client = participant_qos("x", Transport::Default, server({{{{"10.0.0.1", 11811}}}}), {});
  const auto& c = client.wire_protocol().builtin.discovery_config;
  EXPECT_EQ(c.leaseDuration, (Duration_t{60, 0}));
  EXPECT_EQ(c.leaseDuration_announcementperiod, (Duration_t{20, 0}));
  const DomainParticipantQos fastdds;
  for (const auto& q : {participant_qos("x", Transport::Default, ResolvedNetwork{}, {}),
                        participant_qos("x", Transport::Default, unicast({{"127.0.0.1", 0}}), {})}) {
    const auto& d = q.wire_protocol().builtin.discovery_config;
    EXPECT_EQ(d.leaseDuration, fastdds.wire_protocol().builtin.discovery_config.leaseDuration);
    EXPECT_EQ(d.leaseDuration_announcementperiod,
              fastdds.wire_protocol().builtin.discovery_config.leaseDuration_announcementperiod);
  }
  EXPECT_EQ(fastdds.wire_protocol().builtin.discovery_config.leaseDuration_announcementperiod, (Duration_t{3, 0}));
}

// The radio link profile (link_profile.hpp): announcements every 20 s with a lease of 60 s,
// and one initial announcement, in every discovery mode; a Discovery Server
// client keeps the longer of its own periods and the link's.
TEST(ParticipantQos, TheRadioLinkSetsAnnouncementsLeaseAndDiscoveryPace) {
  struct Case {
    const char* name;
    ResolvedNetwork network;
  };
  const Case cases[] = {
      {"multicast", ResolvedNetwork{}},
      {"unicast", unicast({{"127.0.0.1", 0}})},
      {"server", server({{{{"10.0.0.1", 11811}}}})},
  };
  for (auto c : cases) {
    SCOPED_TRACE(c.name);
    LinkSettings settings;
    settings.profile = LinkProfile::Radio;
    c.network.link = link_plan(settings);
    const auto q = participant_qos("x", Transport::UdpOnly, c.network, {});
    const auto& d = q.wire_protocol().builtin.discovery_config;
    EXPECT_EQ(d.leaseDuration, (Duration_t{60, 0}));
    EXPECT_EQ(d.leaseDuration_announcementperiod, (Duration_t{20, 0}));
    EXPECT_EQ(d.initial_announcements.count, 1u);
  }
  // Without a profile: Fast DDS's initial announcements.
  const auto plain = participant_qos("x", Transport::UdpOnly, ResolvedNetwork{}, {});
  EXPECT_EQ(plain.wire_protocol().builtin.discovery_config.initial_announcements.count,
            DomainParticipantQos().wire_protocol().builtin.discovery_config.initial_announcements.count);
}

TEST(ParticipantQos, AllowlistReplacesTheBuiltinTransportsSoNoneBypassesIt) {
  ResolvedNetwork n;
  n.interface_addresses = {"192.168.10.1", "127.0.0.1"};
  // Default: shared memory (same host, no network interface) beside the restricted UDPv4.
  const DomainParticipantQos d = participant_qos("pmu-service", Transport::Default, n, {});
  EXPECT_FALSE(d.transport().use_builtin_transports) << "Fast DDS's builtin UDPv4 would use every interface";
  EXPECT_EQ(d.transport().user_transports.size(), 2u);
  EXPECT_TRUE(has_shm(d));
  ASSERT_NE(udp_of(d), nullptr);
  EXPECT_EQ(udp_of(d)->interfaceWhiteList, (std::vector<std::string>{"192.168.10.1", "127.0.0.1"}));
  // udp: the restricted UDPv4 alone.
  const DomainParticipantQos u = participant_qos("pmu-service", Transport::UdpOnly, n, {});
  EXPECT_EQ(u.transport().user_transports.size(), 1u);
  EXPECT_FALSE(has_shm(u));
  EXPECT_EQ(udp_of(u)->interfaceWhiteList, (std::vector<std::string>{"192.168.10.1", "127.0.0.1"}));
  // The allowlist goes with every discovery mode.
  n.mode = DiscoveryMode::Unicast;
  n.peers = {{"192.168.10.2", 0}};
  EXPECT_EQ(udp_of(participant_qos("x", Transport::UdpOnly, n, {}))->interfaceWhiteList.size(), 2u);
}

TEST(ParticipantQos, SharedMemoryOnlyCannotCarryUnicastServerOrAnAllowlist) {
  EXPECT_THROW((void)participant_qos("x", Transport::ShmOnly, unicast({{"127.0.0.1", 0}}), {}), NetworkError);
  EXPECT_THROW((void)participant_qos("x", Transport::ShmOnly, server({{{{"127.0.0.1", 11811}}}}), {}), NetworkError);
  ResolvedNetwork n;
  n.interface_addresses = {"127.0.0.1"};
  EXPECT_THROW((void)participant_qos("x", Transport::ShmOnly, n, {}), NetworkError);
  const DomainParticipantQos s = participant_qos("x", Transport::ShmOnly, {}, {});
  EXPECT_FALSE(s.transport().use_builtin_transports);
  EXPECT_TRUE(has_shm(s));
  EXPECT_EQ(udp_of(s), nullptr);
}

TEST(ParticipantQos, SecurityPluginsWithMulticastUnicastAndAnAllowlist) {
  SecurityFiles f;
  f.identity_ca = "/pki/identity_ca.pem";
  f.identity_certificate = "/pki/svc/cert.pem";
  f.private_key = "/pki/svc/key.pem";
  f.permissions_ca = "/pki/permissions_ca.pem";
  f.governance = "/pki/governance.p7s";
  f.permissions = "/pki/svc/permissions.p7s";
  ResolvedNetwork allowlisted;
  allowlisted.interface_addresses = {"127.0.0.1"};
  const ResolvedNetwork modes[] = {{}, unicast({{"127.0.0.1", 0}}), allowlisted};
  for (const auto& n : modes) {
    SCOPED_TRACE(to_string(n.mode));
    const DomainParticipantQos q = participant_qos("pmu-service", Transport::UdpOnly, n, f);
    std::map<std::string, std::string> p;  // the dds.sec.* ones (Fast DDS adds its own others)
    for (const auto& prop : q.properties().properties())
      if (prop.name().rfind("dds.sec.", 0) == 0) p[prop.name()] = prop.value();
    EXPECT_EQ(p.size(), 9u);
    EXPECT_EQ(p["dds.sec.auth.plugin"], "builtin.PKI-DH");
    EXPECT_EQ(p["dds.sec.access.plugin"], "builtin.Access-Permissions");
    EXPECT_EQ(p["dds.sec.crypto.plugin"], "builtin.AES-GCM-GMAC");
    EXPECT_EQ(p["dds.sec.auth.builtin.PKI-DH.private_key"], "file:///pki/svc/key.pem");
  }
}

// Config dds_statistics (interface.md 9.3): the property Fast DDS reads when it enables the
// participant, and nothing without it.
TEST(ParticipantQos, StatisticsTopicsBecomeTheFastddsStatisticsProperty) {
  const auto value = [](const DomainParticipantQos& q) -> std::optional<std::string> {
    for (const auto& prop : q.properties().properties())
      if (prop.name() == "fastdds.statistics") return prop.value();
    return std::nullopt;
  };
  EXPECT_EQ(value(participant_qos("pmu-service", Transport::Default, {}, {})), std::nullopt);
  EXPECT_EQ(value(participant_qos("pmu-service", Transport::Default, {}, {},
                                  {"_fastdds_statistics_history2history_latency", "_fastdds_statistics_rtps_sent"})),
            "_fastdds_statistics_history2history_latency;_fastdds_statistics_rtps_sent");
}

// Fast DDS 2.9.1 cannot serve secure participants through a Discovery Server
// (network_settings.hpp, kServerWithSecurity): refused, never built.
TEST(ParticipantQos, DiscoveryServerWithSecurityIsRefused) {
  SecurityFiles f;
  f.identity_ca = "/pki/identity_ca.pem";
  try {
    (void)participant_qos("x", Transport::UdpOnly, server({{{{"127.0.0.1", 11811}}}}), f);
    ADD_FAILURE() << "built";
  } catch (const NetworkError& e) {
    EXPECT_EQ(std::string(e.what()).rfind("Discovery Server mode cannot be combined with DDS-Security", 0), 0u)
        << e.what();
  }
}

}  // namespace
}  // namespace pmu::dds
