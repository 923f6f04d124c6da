// One role machine fed by hand on a fake clock: the term that makes an owner step down, the
// pause that makes it stop transmitting, what it sends and when, its settings' check.
#include <gtest/gtest.h>

#include <string>

#include "pmu/redundancy/role_machine.hpp"

namespace pmu::redundancy {
namespace {

using namespace std::chrono_literals;

constexpr Duration kStep{5};

Settings settings_with_priority(std::uint8_t priority) {
  Settings s;
  s.priority = priority;
  s.peer = "b";
  return s;
}

// A machine that found no peer and owns the bus, and the time it does.
struct LoneOwner {
  Settings settings = settings_with_priority(2);
  Time now{std::chrono::hours(1)};
  RoleMachine machine{settings, now};

  LoneOwner() {
    for (int i = 0; i < 200 && machine.role() != Role::Active; ++i) {
      now += kStep;
      machine.poll(now);
    }
  }
};

TEST(RoleMachine, AloneItOwnsTheBusAfterALeaseAndAClaimAndSaysThePeerIsUnreachable) {
  LoneOwner o;
  ASSERT_EQ(o.machine.role(), Role::Active);
  EXPECT_TRUE(o.machine.may_transmit());
  EXPECT_TRUE(o.machine.executes_commands());
  EXPECT_TRUE(o.machine.publishes_state());
  EXPECT_EQ(o.machine.term(), 1u);
  EXPECT_EQ(o.machine.alarm(), PeerAlarm::PeerUnreachable);
}

TEST(RoleMachine, AnOwnerThatHearsAStrongerClaimStepsDownOnThatCall) {
  struct Case {
    const char* what;
    bool on_can;
    std::uint32_t term;
    std::uint8_t priority;
    bool steps_down;
  };
  const Case cases[] = {
      {"a higher term on CAN", true, 2, 1, true},
      {"a higher term on DDS", false, 2, 1, true},
      {"the same term, a higher priority, on CAN", true, 1, 3, true},
      {"the same term, a lower priority, on CAN", true, 1, 1, false},
      {"a lower term, a higher priority, on DDS", false, 0, 9, false},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.what);
    LoneOwner o;
    ASSERT_EQ(o.machine.role(), Role::Active);
    o.now += kStep;
    if (c.on_can)
      o.machine.on_peer_can(o.now, CanBeat{CanClaim::Active, c.priority, c.term});
    else
      o.machine.on_peer_heartbeat(o.now, DdsBeat{Role::Active, c.term, c.priority, false});
    EXPECT_EQ(o.machine.may_transmit(), !c.steps_down);
    if (!c.steps_down && c.on_can) {
      // The weaker claimant is answered at once, not a heartbeat period later.
      const Actions a = o.machine.poll(o.now);
      ASSERT_TRUE(a.can.has_value());
      EXPECT_EQ(a.can->claim, CanClaim::Active);
    }
  }
}

TEST(RoleMachine, APauseLongerThanTheGapStopsTheOwnerOnItsFirstCall) {
  LoneOwner o;
  o.now += freeze_gap(o.settings) + 1ms;
  o.machine.on_peer_heartbeat(o.now, DdsBeat{Role::Standby, 0, 1, false});
  EXPECT_FALSE(o.machine.may_transmit());
  EXPECT_NE(o.machine.role(), Role::Active);

  LoneOwner short_pause;
  short_pause.now += freeze_gap(short_pause.settings);
  short_pause.machine.poll(short_pause.now);
  EXPECT_TRUE(short_pause.machine.may_transmit());
}

// Asked from another thread, without a call: the owner owns the bus only while its last call
// is within the gap; past it, its next call would drop the role.
TEST(RoleMachine, AskedWithoutACallItOwnsTheBusOnlyWithinTheGapOfItsLastCall) {
  LoneOwner o;
  EXPECT_TRUE(o.machine.owns_at(o.now));
  EXPECT_TRUE(o.machine.owns_at(o.now + freeze_gap(o.settings)));
  EXPECT_FALSE(o.machine.owns_at(o.now + freeze_gap(o.settings) + 1ms));
  RoleMachine standby{o.settings, o.now};
  EXPECT_FALSE(standby.owns_at(o.now));
}

TEST(RoleMachine, ItNeverClaimsWhileThePeerIsHeardOnCanWhateverDdsSays) {
  Settings s = settings_with_priority(200);
  Time now{std::chrono::hours(1)};
  RoleMachine m(s, now);
  for (int i = 0; i < 1000; ++i) {
    now += kStep;
    // The peer's DDS heartbeat never comes; its CAN heartbeat every 50 ms.
    if (i % 10 == 0) m.on_peer_can(now, CanBeat{CanClaim::Active, 1, 1});
    m.poll(now);
    ASSERT_NE(m.role(), Role::Claiming) << "step " << i;
    ASSERT_NE(m.role(), Role::Active) << "step " << i;
  }
  EXPECT_EQ(m.role(), Role::Fenced);
  EXPECT_EQ(m.alarm(), PeerAlarm::Partition);
}

TEST(RoleMachine, WhatItSendsAndWhen) {
  LoneOwner o;
  // Owner: a DDS beat every heartbeat period, a CAN beat every can_silence / 3.
  int dds = 0;
  int can = 0;
  for (int i = 0; i < 200; ++i) {
    o.now += kStep;
    const Actions a = o.machine.poll(o.now);
    if (a.dds) {
      ++dds;
      EXPECT_EQ(a.dds->role, Role::Active);
      EXPECT_EQ(a.dds->term, 1u);
      EXPECT_EQ(a.dds->priority, 2);
    }
    if (a.can) {
      ++can;
      EXPECT_EQ(a.can->claim, CanClaim::Active);
    }
  }
  EXPECT_EQ(dds, 10);  // 1 s
  EXPECT_EQ(can, 20);
  // Leaving: one release frame, then nothing on CAN; the DDS beat says leaving.
  o.machine.leave(o.now);
  EXPECT_FALSE(o.machine.may_transmit());
  o.now += kStep;
  const Actions first = o.machine.poll(o.now);
  ASSERT_TRUE(first.can.has_value());
  EXPECT_EQ(first.can->claim, CanClaim::Released);
  ASSERT_TRUE(first.dds.has_value());
  EXPECT_EQ(first.dds->role, Role::Leaving);
  for (int i = 0; i < 100; ++i) {
    o.now += kStep;
    EXPECT_FALSE(o.machine.poll(o.now).can.has_value());
  }
}

TEST(RoleMachine, AStandbyNeverSendsOnCan) {
  Settings s = settings_with_priority(1);
  Time now{std::chrono::hours(1)};
  RoleMachine m(s, now);
  for (int i = 0; i < 1000; ++i) {
    now += kStep;
    if (i % 20 == 0) m.on_peer_heartbeat(now, DdsBeat{Role::Active, 1, 2, false});
    if (i % 10 == 0) m.on_peer_can(now, CanBeat{CanClaim::Active, 2, 1});
    ASSERT_FALSE(m.poll(now).can.has_value()) << "step " << i;
  }
  EXPECT_EQ(m.role(), Role::Standby);
  EXPECT_EQ(m.alarm(), PeerAlarm::None);
}

TEST(RoleMachine, EqualPrioritiesAreAnAlarm) {
  Settings s = settings_with_priority(5);
  Time now{std::chrono::hours(1)};
  RoleMachine m(s, now);
  now += kStep;
  m.on_peer_heartbeat(now, DdsBeat{Role::Joining, 0, 5, false});
  EXPECT_EQ(m.alarm(), PeerAlarm::PriorityClash);
}

TEST(RoleMachine, LosingItsBusTheOwnerStopsAndComesBackJoining) {
  LoneOwner o;
  o.now += kStep;
  o.machine.on_bus_state(o.now, BusState::BusOff);
  EXPECT_EQ(o.machine.role(), Role::NoBus);
  EXPECT_FALSE(o.machine.may_transmit());
  const Actions a = o.machine.poll(o.now);
  ASSERT_TRUE(a.dds.has_value());
  EXPECT_EQ(a.dds->role, Role::NoBus);
  EXPECT_FALSE(a.can.has_value());
  o.now += kStep;
  o.machine.on_bus_state(o.now, BusState::Ok);
  EXPECT_EQ(o.machine.role(), Role::Joining);
}

TEST(RedundancySettings, EveryProblemIsNamed) {
  struct Case {
    const char* what;
    void (*change)(Settings&);
    const char* problem;  // "" = runs
  };
  const Case cases[] = {
      {"the defaults", [](Settings&) {}, ""},
      {"priority 0", [](Settings& s) { s.priority = 0; }, "priority 0 is out of range 1..255"},
      {"no peer", [](Settings& s) { s.peer.clear(); }, "peer must name the other instance"},
      {"heartbeat too short", [](Settings& s) { s.heartbeat_period = 5ms; },
       "heartbeat_period 5 ms is out of range 10 ms..1000 ms"},
      {"lease under two heartbeats", [](Settings& s) { s.lease = 150ms; },
       "lease 150 ms is under 2 x heartbeat_period (200 ms)"},
      {"lease too long", [](Settings& s) { s.lease = 10001ms; }, "lease 10001 ms is over 10000 ms"},
      {"can_silence too short", [](Settings& s) { s.can_silence = 20ms; },
       "can_silence 20 ms is out of range 30 ms..10000 ms"},
  };
  for (const auto& c : cases) {
    Settings s;
    s.peer = "b";
    c.change(s);
    EXPECT_EQ(settings_problem(s), c.problem) << c.what;
  }
  const Settings d;
  EXPECT_EQ(can_heartbeat_period(d), 50ms);
  EXPECT_EQ(claim_window(d), 100ms);
  EXPECT_EQ(freeze_gap(d), 200ms);
  EXPECT_LE(poll_period(d), 25ms);
}

}  // namespace
}  // namespace pmu::redundancy
