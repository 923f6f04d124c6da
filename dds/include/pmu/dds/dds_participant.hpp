#pragma once
// participant_qos: the DomainParticipantQos of every participant the project creates
// (pmu-service, pmuctl, the tests), from the transport choice, the discovery settings and
// the DDS-Security files. A pure function (no look-up, no file read, no Fast DDS call), so
// unit tests inspect exactly what a participant will be created with; DdsContext uses it.
//
// What each mode sets (Fast DDS 2.9, wire_protocol().builtin):
//   multicast: nothing (Fast DDS's defaults: SPDP to 239.255.0.1:7400+250*domain and to the
//              local well-known unicast ports).
//   unicast:   discovery protocol SIMPLE; initialPeersList = the peers (port 0: Fast DDS
//              tries the domain's well-known unicast discovery ports of participant ids
//              0..3 on that host, 7410+250*domain+2*id); metatraffic multicast list empty
//              and metatraffic unicast = one UDPv4 "any" locator with port 0, so Fast DDS
//              neither opens the multicast discovery port nor sends to the group, and
//              listens on the well-known unicast port of each (allowed) interface.
//   server:    discovery protocol CLIENT; m_DiscoveryServers = the servers, server i with
//              the GUID prefix of `fastdds discovery -i i` (44.53.<i>.5f.45.50.52.4f.53.49.4d.41)
//              and its locators; metatraffic as in unicast (no multicast); its lease
//              kClientLease, announced every kClientAnnouncementPeriod (the servers'
//              own periods are deploy/discovery-server.xml's).
// Transports: always explicit ones (use_builtin_transports = false), since Fast DDS's builtin
// UDPv4 can be given neither an allowlist nor a datagram size. Transport Default is shared
// memory beside UDPv4, as Fast DDS's builtin pair; UdpOnly is UDPv4 alone. The UDPv4
// transport's maxMessageSize is kUdpMaxMessageSize, except with DDS-Security: Fast DDS 2.9
// serialises a handshake message (certificates) into a buffer of that size, and a handshake
// that does not fit fails ("Cannot serialize ParticipantGenericMessage").
// Interfaces (allowlist): the UDPv4 transport's interfaceWhiteList = the addresses
// (127.0.0.1 always among them, see resolve_network); without one it uses every interface.
// Security: the DDS-Security plugin properties when `security` is not empty, with multicast
// and unicast discovery and with an allowlist.
// Link (network.link, link_profile.hpp): its announcement period, lease and initial
// announcements replace Fast DDS's in every mode (a server client keeps the longer of its
// own and the link's).
// Statistics: property `fastdds.statistics` = the topics joined by ';' when `statistics` is
// not empty (statistics_settings.hpp); nothing otherwise.
//
// Throws NetworkError for a combination that cannot work (ShmOnly with unicast or server
// discovery, or with an allowlist; server discovery with DDS-Security, kServerWithSecurity
// says why); the config and pmuctl refuse these first, naming the line or the option.

#include <fastdds/dds/domain/qos/DomainParticipantQos.hpp>
#include <cstdint>
#include <string>
#include <vector>

#include "pmu/dds_settings/network_settings.hpp"
#include "pmu/dds_settings/transport_choice.hpp"
#include "pmu/security/security_files.hpp"

namespace pmu::dds {

// A Discovery Server client's lease and how often it announces itself to its servers: three
// announcements per lease (Fast DDS's default: every 3 s, lease 20 s). The lease outlasts a
// radio dropout of 30 s and more: a client and a server that expired each other during one
// do not always exchange their endpoints again (deploy/discovery-server.xml says more).
inline const eprosima::fastrtps::Duration_t kClientLease{60, 0};
inline const eprosima::fastrtps::Duration_t kClientAnnouncementPeriod{20, 0};

// The largest datagram a participant sends (Fast DDS sends up to 65,500 bytes by default).
// A datagram larger than the path's MTU leaves as IP fragments, and losing any one fragment
// loses the whole datagram: on a radio link with 10 % loss a 10 kB datagram (7 fragments)
// is lost half the time, and the reliable writer resends all of it, again as fragments, into
// the same link. Under this size every datagram is one packet on a 1,500-byte MTU with room
// for a tunnel's headers, and a sample larger than it goes as RTPS fragments (DATA_FRAG),
// each acknowledged and resent on its own. Fast DDS applies the smallest size of a
// participant's transports to all of them, so same-host shared memory fragments too.
inline constexpr std::uint32_t kUdpMaxMessageSize = 1400;

eprosima::fastdds::dds::DomainParticipantQos participant_qos(const std::string& name, Transport transport,
                                                             const ResolvedNetwork& network,
                                                             const SecurityFiles& security,
                                                             const std::vector<std::string>& statistics = {});

}  // namespace pmu::dds
