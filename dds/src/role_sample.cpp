#include "pmu/dds/role_sample.hpp"

#include <cstdint>
#include <optional>

namespace pmu::dds {
namespace {

using redundancy::BusState;
using redundancy::PeerAlarm;
using redundancy::Role;

// Each literal both ways, by name, so a reordered enum on either side is a compile-time
// mismatch here rather than a silently shifted role on the wire.
std::optional<Role> role_of(pmu::v5::InstanceRole r) noexcept {
  switch (r) {
    case pmu::v5::ROLE_JOINING: return Role::Joining;
    case pmu::v5::ROLE_STANDBY: return Role::Standby;
    case pmu::v5::ROLE_FENCED: return Role::Fenced;
    case pmu::v5::ROLE_CLAIMING: return Role::Claiming;
    case pmu::v5::ROLE_ACTIVE: return Role::Active;
    case pmu::v5::ROLE_NO_BUS: return Role::NoBus;
    case pmu::v5::ROLE_LEAVING: return Role::Leaving;
  }
  return std::nullopt;
}

pmu::v5::InstanceRole role_literal(Role r) noexcept {
  switch (r) {
    case Role::Joining: return pmu::v5::ROLE_JOINING;
    case Role::Standby: return pmu::v5::ROLE_STANDBY;
    case Role::Fenced: return pmu::v5::ROLE_FENCED;
    case Role::Claiming: return pmu::v5::ROLE_CLAIMING;
    case Role::Active: return pmu::v5::ROLE_ACTIVE;
    case Role::NoBus: return pmu::v5::ROLE_NO_BUS;
    case Role::Leaving: return pmu::v5::ROLE_LEAVING;
  }
  return pmu::v5::ROLE_JOINING;
}

std::optional<BusState> bus_of(pmu::v5::RoleBusState b) noexcept {
  switch (b) {
    case pmu::v5::ROLE_BUS_OK: return BusState::Ok;
    case pmu::v5::ROLE_BUS_OFF: return BusState::BusOff;
    case pmu::v5::ROLE_BUS_DOWN: return BusState::Down;
  }
  return std::nullopt;
}

pmu::v5::RoleBusState bus_literal(BusState b) noexcept {
  switch (b) {
    case BusState::Ok: return pmu::v5::ROLE_BUS_OK;
    case BusState::BusOff: return pmu::v5::ROLE_BUS_OFF;
    case BusState::Down: return pmu::v5::ROLE_BUS_DOWN;
  }
  return pmu::v5::ROLE_BUS_DOWN;
}

std::optional<PeerAlarm> alarm_of(pmu::v5::PeerAlarm a) noexcept {
  switch (a) {
    case pmu::v5::PEER_ALARM_NONE: return PeerAlarm::None;
    case pmu::v5::PEER_ALARM_UNREACHABLE: return PeerAlarm::PeerUnreachable;
    case pmu::v5::PEER_ALARM_PARTITION: return PeerAlarm::Partition;
    case pmu::v5::PEER_ALARM_PRIORITY_CLASH: return PeerAlarm::PriorityClash;
  }
  return std::nullopt;
}

pmu::v5::PeerAlarm alarm_literal(PeerAlarm a) noexcept {
  switch (a) {
    case PeerAlarm::None: return pmu::v5::PEER_ALARM_NONE;
    case PeerAlarm::PeerUnreachable: return pmu::v5::PEER_ALARM_UNREACHABLE;
    case PeerAlarm::Partition: return pmu::v5::PEER_ALARM_PARTITION;
    case PeerAlarm::PriorityClash: return pmu::v5::PEER_ALARM_PRIORITY_CLASH;
  }
  return pmu::v5::PEER_ALARM_NONE;
}

// The enumerator's number as Fast CDR read it off the wire: any 32-bit value.
template <class Enum>
std::string number_of(Enum e) {
  return std::to_string(static_cast<std::uint32_t>(e));
}

}  // namespace

pmu::v5::RoleHeartbeat role_heartbeat_sample(const std::string& vehicle, const redundancy::RoleReport& report) {
  pmu::v5::RoleHeartbeat s;
  s.vehicle(vehicle);
  s.name(report.name);
  s.peer(report.peer);
  s.role(role_literal(report.beat.role));
  s.term(report.beat.term);
  s.priority(report.beat.priority);
  s.hands_over(report.beat.hands_over);
  s.bus_state(bus_literal(report.bus));
  s.alarm(alarm_literal(report.alarm));
  return s;
}

ReadRole read_role_heartbeat(const pmu::v5::RoleHeartbeat& sample) {
  ReadRole out;
  const auto role = role_of(sample.role());
  const auto bus = bus_of(sample.bus_state());
  const auto alarm = alarm_of(sample.alarm());
  if (!role)
    out.problem = "role " + number_of(sample.role()) + " is not an InstanceRole";
  else if (!bus)
    out.problem = "bus_state " + number_of(sample.bus_state()) + " is not a RoleBusState";
  else if (!alarm)
    out.problem = "alarm " + number_of(sample.alarm()) + " is not a PeerAlarm";
  out.vehicle = sample.vehicle().to_string();
  if (!out.ok()) return out;
  out.report.name = sample.name().to_string();
  out.report.peer = sample.peer().to_string();
  out.report.beat = redundancy::DdsBeat{*role, sample.term(), sample.priority(), sample.hands_over()};
  out.report.bus = *bus;
  out.report.alarm = *alarm;
  return out;
}

}  // namespace pmu::dds
