#include "pmu/dds/dds_participant.hpp"

#include "pmu/dds_settings/statistics_settings.hpp"

#include <fastdds/rtps/attributes/ServerAttributes.h>
#include <fastdds/rtps/transport/UDPv4TransportDescriptor.h>
#include <fastdds/rtps/transport/shared_mem/SharedMemTransportDescriptor.h>
#include <fastrtps/utils/IPLocator.h>

#include <chrono>
#include <filesystem>
#include <memory>

namespace pmu::dds {
namespace {

using eprosima::fastdds::dds::DomainParticipantQos;
using eprosima::fastrtps::rtps::IPLocator;
using eprosima::fastrtps::rtps::Locator_t;

Locator_t udpv4(const std::string& address, std::uint16_t port) {
  Locator_t l;
  l.kind = LOCATOR_KIND_UDPv4;
  IPLocator::setIPv4(l, address);  // a dotted IPv4 address: resolve_network made sure of it
  l.port = port;
  return l;
}

// Metatraffic on unicast only: an explicit list keeps Fast DDS from adding its default
// multicast locator (RTPSParticipantImpl adds defaults only when both lists are empty).
// "Any" with port 0 becomes the domain's well-known unicast discovery port on every allowed
// interface, which is where peers without a port look.
void unicast_metatraffic_only(DomainParticipantQos& qos) {
  auto& b = qos.wire_protocol().builtin;
  b.metatrafficMulticastLocatorList.clear();
  b.metatrafficUnicastLocatorList.clear();
  b.metatrafficUnicastLocatorList.push_back(udpv4("0.0.0.0", 0));
}

// file: URIs as Fast DDS's builtin security plugins take them ("file://" + absolute path).
std::string file_uri(const std::string& path) {
  std::error_code ec;
  const auto abs = std::filesystem::absolute(path, ec);
  return "file://" + (ec ? path : abs.lexically_normal().string());
}

void add_security(DomainParticipantQos& pqos, const SecurityFiles& f) {
  auto& p = pqos.properties().properties();
  p.emplace_back("dds.sec.auth.plugin", "builtin.PKI-DH");
  p.emplace_back("dds.sec.auth.builtin.PKI-DH.identity_ca", file_uri(f.identity_ca));
  p.emplace_back("dds.sec.auth.builtin.PKI-DH.identity_certificate", file_uri(f.identity_certificate));
  p.emplace_back("dds.sec.auth.builtin.PKI-DH.private_key", file_uri(f.private_key));
  p.emplace_back("dds.sec.access.plugin", "builtin.Access-Permissions");
  p.emplace_back("dds.sec.access.builtin.Access-Permissions.permissions_ca", file_uri(f.permissions_ca));
  p.emplace_back("dds.sec.access.builtin.Access-Permissions.governance", file_uri(f.governance));
  p.emplace_back("dds.sec.access.builtin.Access-Permissions.permissions", file_uri(f.permissions));
  p.emplace_back("dds.sec.crypto.plugin", "builtin.AES-GCM-GMAC");
}

eprosima::fastrtps::Duration_t duration(std::chrono::milliseconds ms) {
  return eprosima::fastrtps::Duration_t(static_cast<double>(ms.count()) / 1000.0);
}

eprosima::fastrtps::Duration_t longer(const eprosima::fastrtps::Duration_t& a,
                                      const eprosima::fastrtps::Duration_t& b) {
  return a < b ? b : a;
}

}  // namespace

DomainParticipantQos participant_qos(const std::string& name, Transport transport, const ResolvedNetwork& network,
                                     const SecurityFiles& security, const std::vector<std::string>& statistics) {
  using namespace eprosima::fastdds::rtps;
  DomainParticipantQos qos;
  qos.name(name);
  if (!security.empty()) add_security(qos, security);
  if (!statistics.empty())
    qos.properties().properties().emplace_back("fastdds.statistics", statistics_property(statistics));

  const bool allowlist = !network.interface_addresses.empty();
  if (transport == Transport::ShmOnly && (allowlist || network.mode != DiscoveryMode::Multicast))
    throw NetworkError(std::string("shared memory only (dds_transport shm) cannot carry ") +
                       (allowlist ? "an interface allowlist" : std::string(to_string(network.mode)) + " discovery") +
                       ": both are about UDP");
  if (network.mode == DiscoveryMode::Server && !security.empty())
    throw NetworkError(std::string("Discovery Server mode ") + kServerWithSecurity);
  if (network.servers.size() > kMaxServers)
    throw NetworkError("more than " + std::to_string(kMaxServers) + " Discovery Servers (server ids are 0..255)");
  auto udp = std::make_shared<UDPv4TransportDescriptor>();
  udp->interfaceWhiteList = network.interface_addresses;
  // Fast DDS 2.9 serialises a DDS-Security handshake message, which carries certificates,
  // into one buffer of this size and fails the handshake when it does not fit.
  if (security.empty()) udp->maxMessageSize = kUdpMaxMessageSize;
  auto& t = qos.transport();
  switch (transport) {
    case Transport::Default:
      // Fast DDS's builtin pair, but with the UDPv4 transport that has the allowlist and the
      // datagram size.
      t.use_builtin_transports = false;
      t.user_transports.push_back(std::make_shared<SharedMemTransportDescriptor>());
      t.user_transports.push_back(udp);
      break;
    case Transport::UdpOnly:
      t.use_builtin_transports = false;
      t.user_transports.push_back(udp);
      break;
    case Transport::ShmOnly:
      t.use_builtin_transports = false;
      t.user_transports.push_back(std::make_shared<SharedMemTransportDescriptor>());
      break;
  }

  auto& builtin = qos.wire_protocol().builtin;
  builtin.use_WriterLivelinessProtocol = false;
  // The link's announcement period and lease (link_profile.hpp); Discovery Server clients
  // keep the longer of theirs and the link's (below).
  const auto& link = network.link;
  if (link.announcement_period.set())
    builtin.discovery_config.leaseDuration_announcementperiod = duration(link.announcement_period.value);
  if (link.lease.set()) builtin.discovery_config.leaseDuration = duration(link.lease.value);
  if (link.initial_announcements > 0) {
    builtin.discovery_config.initial_announcements.count = static_cast<std::uint32_t>(link.initial_announcements);
  }
  switch (network.mode) {
    case DiscoveryMode::Multicast: break;
    case DiscoveryMode::Unicast:
      builtin.discovery_config.discoveryProtocol = eprosima::fastrtps::rtps::DiscoveryProtocol_t::SIMPLE;
      builtin.initialPeersList.clear();
      for (const auto& p : network.peers) builtin.initialPeersList.push_back(udpv4(p.address, p.port));
      unicast_metatraffic_only(qos);
      break;
    case DiscoveryMode::Server:
      builtin.discovery_config.discoveryProtocol = eprosima::fastrtps::rtps::DiscoveryProtocol_t::CLIENT;
      // A client's announcements go to its servers alone, which for an aircraft means across
      // the radio link: three per lease instead of every 3 s, so a lossy link must lose three
      // in a row, or be down longer than the lease, before the server gives the client up.
      builtin.discovery_config.leaseDuration = longer(builtin.discovery_config.leaseDuration, kClientLease);
      builtin.discovery_config.leaseDuration_announcementperiod =
          longer(builtin.discovery_config.leaseDuration_announcementperiod, kClientAnnouncementPeriod);
      builtin.discovery_config.m_DiscoveryServers.clear();
      for (std::size_t id = 0; id < network.servers.size(); ++id) {
        if (network.servers[id].locators.empty()) continue;  // an id left unused
        RemoteServerAttributes server;
        // The prefix `fastdds discovery -i ID` gives its server; ROS_DISCOVERY_SERVER's convention.
        get_server_client_default_guidPrefix(static_cast<int>(id), server.guidPrefix);
        for (const auto& l : network.servers[id].locators)
          server.metatrafficUnicastLocatorList.push_back(udpv4(l.address, l.port));
        builtin.discovery_config.m_DiscoveryServers.push_back(server);
      }
      unicast_metatraffic_only(qos);
      break;
  }
  return qos;
}

}  // namespace pmu::dds
