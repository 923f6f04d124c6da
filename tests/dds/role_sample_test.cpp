// pmu/role's sample both ways (pmu/dds/role_sample.hpp): every role, bus state and alarm the
// holder writes reads back as written, and a sample whose enumerator is outside the IDL's
// literals (a hostile writer, another build) is refused with its field and number, never cast.
#include "pmu/dds/role_sample.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <string>
#include <vector>

namespace pmu::dds {
namespace {

using redundancy::BusState;
using redundancy::PeerAlarm;
using redundancy::Role;

TEST(RoleSample, EveryValueReadsBackAsWritten) {
  const std::vector<Role> roles{Role::Joining, Role::Standby, Role::Fenced, Role::Claiming,
                                Role::Active,  Role::NoBus,   Role::Leaving};
  const std::vector<BusState> buses{BusState::Ok, BusState::BusOff, BusState::Down};
  const std::vector<PeerAlarm> alarms{PeerAlarm::None, PeerAlarm::PeerUnreachable, PeerAlarm::Partition,
                                      PeerAlarm::PriorityClash};
  for (const auto role : roles)
    for (const auto bus : buses)
      for (const auto alarm : alarms) {
        redundancy::RoleReport r{"mc-a", "mc-b", {role, 4000000000u, 255, role == Role::Standby}, bus, alarm};
        const auto read = read_role_heartbeat(role_heartbeat_sample("uav7", r));
        ASSERT_TRUE(read.ok()) << read.problem;
        EXPECT_EQ(read.vehicle, "uav7");
        EXPECT_EQ(read.report.name, "mc-a");
        EXPECT_EQ(read.report.peer, "mc-b");
        EXPECT_EQ(read.report.beat.role, role);
        EXPECT_EQ(read.report.beat.term, 4000000000u);
        EXPECT_EQ(read.report.beat.priority, 255);
        EXPECT_EQ(read.report.beat.hands_over, role == Role::Standby);
        EXPECT_EQ(read.report.bus, bus);
        EXPECT_EQ(read.report.alarm, alarm);
      }
}

TEST(RoleSample, TheContractsLiteralsInTheirOrder) {
  // The wire carries the literal's number: IDL order, which interface.md 1.10 lists.
  redundancy::RoleReport r;
  r.beat.role = Role::Active;
  r.bus = BusState::Down;
  r.alarm = PeerAlarm::PriorityClash;
  const auto s = role_heartbeat_sample("", r);
  EXPECT_EQ(static_cast<std::uint32_t>(s.role()), 4u);
  EXPECT_EQ(static_cast<std::uint32_t>(s.bus_state()), 2u);
  EXPECT_EQ(static_cast<std::uint32_t>(s.alarm()), 3u);
}

TEST(RoleSample, AnEnumeratorOutsideItsLiteralsIsRefusedByName) {
  struct Case {
    std::uint32_t role, bus, alarm;
    std::string problem;
  };
  for (const auto& c : std::vector<Case>{{7, 0, 0, "role 7 is not an InstanceRole"},
                                         {0xFFFFFFFF, 0, 0, "role 4294967295 is not an InstanceRole"},
                                         {4, 3, 0, "bus_state 3 is not a RoleBusState"},
                                         {4, 0, 4, "alarm 4 is not a PeerAlarm"}}) {
    pmu::v5::RoleHeartbeat s;
    s.vehicle("uav7");
    s.name("mc-a");
    s.role(static_cast<pmu::v5::InstanceRole>(c.role));
    s.bus_state(static_cast<pmu::v5::RoleBusState>(c.bus));
    s.alarm(static_cast<pmu::v5::PeerAlarm>(c.alarm));
    const auto read = read_role_heartbeat(s);
    EXPECT_FALSE(read.ok());
    EXPECT_EQ(read.problem, c.problem);
    EXPECT_EQ(read.report.name, "") << "nothing of a refused sample is handed on";
  }
}

}  // namespace
}  // namespace pmu::dds
