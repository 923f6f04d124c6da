#include "pmu/redundancy/role.hpp"

namespace pmu::redundancy {

std::string_view role_name(Role role) noexcept {
  switch (role) {
    case Role::Joining: return "joining";
    case Role::Standby: return "standby";
    case Role::Fenced: return "fenced";
    case Role::Claiming: return "claiming";
    case Role::Active: return "active";
    case Role::NoBus: return "no_bus";
    case Role::Leaving: return "leaving";
  }
  return "unknown";
}

std::string_view alarm_name(PeerAlarm alarm) noexcept {
  switch (alarm) {
    case PeerAlarm::None: return "none";
    case PeerAlarm::PeerUnreachable: return "peer_unreachable";
    case PeerAlarm::Partition: return "partition";
    case PeerAlarm::PriorityClash: return "priority_clash";
  }
  return "unknown";
}

}  // namespace pmu::redundancy
