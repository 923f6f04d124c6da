#pragma once
// The roles of an instance of a hot-standby pair and what each lets it do (docs/design.md,
// "Hot standby"), and the heartbeat each instance sends on DDS (pmu/role).

#include <cstdint>
#include <string>
#include <string_view>

namespace pmu::redundancy {

enum class Role : std::uint8_t {
  Joining,   // started, resumed or back on the bus: learning who owns it; transmits nothing
  Standby,   // the peer owns the bus or may; listens, keeps its state warm
  Fenced,    // the peer is on CAN but not on DDS: a partition; listens, raises the alarm
  Claiming,  // sends its claim on CAN, waits the claim window; no PMU frame yet
  Active,    // owns the bus: transmits, executes commands, writes the state topics
  NoBus,     // its own bus is off or down: can neither own the bus nor judge the peer's silence
  Leaving,   // stopped (SIGTERM): released the bus, ends
};

std::string_view role_name(Role role) noexcept;

enum class BusState : std::uint8_t { Ok, BusOff, Down };

// What the pair is short of, as this instance sees it. `partition`: the peer is heard on CAN
// but not on DDS; `peer_unreachable`: the peer is on neither (dead, or the network is cut and
// the peer is passive, which a bus owner cannot tell apart); `priority_clash`: both have the
// same priority, so neither claims over the other on priority.
enum class PeerAlarm : std::uint8_t { None, PeerUnreachable, Partition, PriorityClash };

std::string_view alarm_name(PeerAlarm alarm) noexcept;

// One sample of pmu/role as the role machine reads and writes it.
struct DdsBeat {
  Role role = Role::Joining;
  std::uint32_t term = 0;
  std::uint8_t priority = 0;
  bool hands_over = false;  // a STANDBY that has just handed the bus over asks its peer to take it
};

// One instance's pmu/role sample as the holder writes it and a reader takes it, without DDS
// types: the endpoint adds the vehicle and turns it into the contract's type and back.
struct RoleReport {
  std::string name;  // this instance (the config's redundancy.name)
  std::string peer;  // the instance it pairs with
  DdsBeat beat;
  BusState bus = BusState::Ok;
  PeerAlarm alarm = PeerAlarm::None;
};

// A request to move the role (pmuctl): the instance asked to hand the bus over, who asked and
// the request's id, for the audit line and the reply.
struct MoveRequest {
  std::string request_id;
  std::string instance;
  std::string requester;
};

}  // namespace pmu::redundancy
