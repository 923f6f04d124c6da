// Two instances of a hot-standby pair through the faults of their hosts, on a fake clock
// (role_pair.hpp): who owns the bus afterwards, how long the takeover took, and that at no tick
// were there two bus owners or an owner made while the other was heard on CAN.
#include <gtest/gtest.h>

#include <string>

#include "role_pair.hpp"

namespace pmu::redundancy::pair_test {
namespace {

std::string violations_of(const Pair& p) {
  std::string all;
  for (const auto& v : p.violations()) all += v + "\n";
  return all;
}

TEST(RolePair, BothStartingAtOnceMakeExactlyOneOwnerTheHigherPriority) {
  struct Case {
    std::uint8_t priority_a, priority_b;
    bool dds_up;
    int owner;
    Role other;
  };
  const Case cases[] = {
      {2, 1, true, 0, Role::Standby},
      {1, 2, true, 1, Role::Standby},
      // The network cut from the start: neither learns the other's priority but from its claim on CAN.
      {2, 1, false, 0, Role::Fenced},
      {1, 2, false, 1, Role::Fenced},
      {200, 7, false, 0, Role::Fenced},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(std::to_string(c.priority_a) + " vs " + std::to_string(c.priority_b) +
                 (c.dds_up ? ", network up" : ", network cut"));
    Pair p(c.priority_a, c.priority_b);
    p.dds_up = c.dds_up;
    settle(p);
    EXPECT_EQ(p.role(c.owner), Role::Active);
    EXPECT_EQ(p.role(1 - c.owner), c.other);
    p.run_for(std::chrono::seconds(5));
    EXPECT_EQ(p.role(c.owner), Role::Active);
    EXPECT_EQ(p.role(1 - c.owner), c.other);
    EXPECT_EQ(p.machine(c.owner).term(), 1u);
    EXPECT_TRUE(p.violations().empty()) << violations_of(p);
  }
}

enum class Fault { Kill, Freeze, BusOff, BusDown, Stop };

const char* fault_name(Fault f) {
  switch (f) {
    case Fault::Kill: return "SIGKILL";
    case Fault::Freeze: return "SIGSTOP";
    case Fault::BusOff: return "bus-off";
    case Fault::BusDown: return "interface down";
    case Fault::Stop: return "SIGTERM";
  }
  return "?";
}

// The owner's fault, the standby's takeover within its bound, and the old owner back as STANDBY
// (restarted, resumed, its bus back), taking nothing back though its priority is higher.
TEST(RolePair, TheStandbyTakesOverEachFaultOfTheOwnerWithinItsBound) {
  const Settings s;  // the defaults: heartbeat 100 ms, lease 300 ms, can_silence 150 ms
  struct Case {
    Fault fault;
    Duration bound;
  };
  const Case cases[] = {
      // Neither heartbeat comes: the lease, then the claim window (and within the 0.5 s budget).
      {Fault::Kill, s.lease + s.can_silence},
      {Fault::Freeze, s.lease + s.can_silence},
      // The owner says NO_BUS at once: only the CAN silence and the claim window are waited.
      {Fault::BusOff, s.can_silence + claim_window(s) + 2 * kTick},
      {Fault::BusDown, s.can_silence + claim_window(s) + 2 * kTick},
      // Released: the claim window only.
      {Fault::Stop, claim_window(s) + 2 * kTick},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(fault_name(c.fault));
    Pair p(2, 1);
    settle(p);
    ASSERT_EQ(p.role(0), Role::Active);
    ASSERT_EQ(p.role(1), Role::Standby);
    switch (c.fault) {
      case Fault::Kill: p.kill(0); break;
      case Fault::Freeze: p.freeze(0); break;
      case Fault::BusOff: p.set_bus(0, BusState::BusOff); break;
      case Fault::BusDown: p.set_bus(0, BusState::Down); break;
      case Fault::Stop:
        p.machine(0).leave(p.now());
        EXPECT_FALSE(p.machine(0).may_transmit());
        break;
    }
    const auto takeover = p.run_until([&] { return p.role(1) == Role::Active; }, std::chrono::seconds(3));
    ASSERT_TRUE(takeover.has_value());
    EXPECT_LE(*takeover, c.bound);
    EXPECT_LT(*takeover, Duration{500});
    EXPECT_EQ(p.machine(1).term(), 2u);

    p.run_for(std::chrono::seconds(1));
    switch (c.fault) {
      case Fault::Kill: p.start(0); break;
      case Fault::Freeze: p.resume(0); break;
      case Fault::BusOff:
      case Fault::BusDown: p.set_bus(0, BusState::Ok); break;
      case Fault::Stop:
        p.kill(0);
        p.start(0);
        break;
    }
    p.run_for(std::chrono::seconds(5));
    EXPECT_EQ(p.role(0), Role::Standby);
    EXPECT_EQ(p.role(1), Role::Active);
    EXPECT_EQ(p.machine(1).term(), 2u);
    EXPECT_EQ(p.machine(0).alarm(), PeerAlarm::None);
    EXPECT_TRUE(p.violations().empty()) << violations_of(p);
  }
}

TEST(RolePair, AFrozenOwnerThatResumesNeverTransmitsBesideTheNewOwner) {
  for (const bool timer_first : {false, true}) {
    SCOPED_TRACE(timer_first ? "polled before it reads its sockets" : "its sockets read first");
    Pair p(2, 1);
    settle(p);
    p.freeze(0);
    p.run_for(std::chrono::seconds(2));
    ASSERT_EQ(p.role(1), Role::Active);
    p.resume(0, timer_first);
    EXPECT_FALSE(p.machine(0).may_transmit());
    for (int i = 0; i < 400; ++i) {
      p.tick();
      ASSERT_FALSE(p.machine(0).may_transmit()) << "tick " << i;
    }
    EXPECT_EQ(p.role(0), Role::Standby);
    EXPECT_EQ(p.role(1), Role::Active);
    EXPECT_TRUE(p.violations().empty()) << violations_of(p);
  }
}

TEST(RolePair, AFreezeShorterThanTheGapChangesNothing) {
  Pair p(2, 1);
  settle(p);
  p.freeze(0);
  p.run_for(Duration{100});
  p.resume(0);
  p.run_for(std::chrono::seconds(2));
  EXPECT_EQ(p.role(0), Role::Active);
  EXPECT_EQ(p.role(1), Role::Standby);
  EXPECT_EQ(p.machine(0).term(), 1u);
  EXPECT_TRUE(p.violations().empty()) << violations_of(p);
}

TEST(RolePair, ANetworkCutMakesNoSecondOwnerAndAnAlarmOnBoth) {
  Pair p(2, 1);
  settle(p);
  p.dds_up = false;
  p.run_for(std::chrono::seconds(5));
  EXPECT_EQ(p.role(0), Role::Active);
  EXPECT_EQ(p.role(1), Role::Fenced);
  EXPECT_FALSE(p.host(1).was_ever_owner_or_claimant);
  EXPECT_EQ(p.machine(0).alarm(), PeerAlarm::PeerUnreachable);
  EXPECT_EQ(p.machine(1).alarm(), PeerAlarm::Partition);
  p.dds_up = true;
  p.run_for(std::chrono::seconds(1));
  EXPECT_EQ(p.role(0), Role::Active);
  EXPECT_EQ(p.role(1), Role::Standby);
  EXPECT_EQ(p.machine(0).alarm(), PeerAlarm::None);
  EXPECT_EQ(p.machine(1).alarm(), PeerAlarm::None);
  EXPECT_TRUE(p.violations().empty()) << violations_of(p);
}

// Cut off on DDS, the standby learns of the owner's end from the bus alone.
TEST(RolePair, TheOwnerEndingDuringANetworkCutIsTakenOverOnceTheBusIsQuiet) {
  const Settings s;
  struct Case {
    Fault fault;
    Duration bound;
  };
  const Case cases[] = {
      {Fault::Kill, s.can_silence + claim_window(s) + 2 * kTick},
      {Fault::BusOff, s.can_silence + claim_window(s) + 2 * kTick},
      {Fault::Stop, claim_window(s) + 2 * kTick},  // its release frame
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(fault_name(c.fault));
    Pair p(2, 1);
    settle(p);
    p.dds_up = false;
    p.run_for(std::chrono::seconds(2));
    ASSERT_EQ(p.role(1), Role::Fenced);
    switch (c.fault) {
      case Fault::Kill: p.kill(0); break;
      case Fault::BusOff: p.set_bus(0, BusState::BusOff); break;
      case Fault::Stop: p.machine(0).leave(p.now()); break;
      case Fault::Freeze:
      case Fault::BusDown: break;
    }
    const auto takeover = p.run_until([&] { return p.role(1) == Role::Active; }, std::chrono::seconds(3));
    ASSERT_TRUE(takeover.has_value());
    EXPECT_LE(*takeover, c.bound);
    EXPECT_TRUE(p.violations().empty()) << violations_of(p);
  }
}

TEST(RolePair, AMoveHandsTheBusToTheStandbyWhichKeepsIt) {
  Pair p(2, 1);
  settle(p);
  const MoveResult move = p.machine(0).hand_over(p.now());
  ASSERT_TRUE(move.accepted) << move.reason;
  EXPECT_FALSE(p.machine(0).may_transmit());
  const auto takeover = p.run_until([&] { return p.role(1) == Role::Active; }, std::chrono::seconds(1));
  ASSERT_TRUE(takeover.has_value());
  EXPECT_LE(*takeover, claim_window(Settings{}) + 2 * kTick);
  // The higher priority takes nothing back.
  p.run_for(std::chrono::seconds(5));
  EXPECT_EQ(p.role(0), Role::Standby);
  EXPECT_EQ(p.role(1), Role::Active);
  EXPECT_TRUE(p.violations().empty()) << violations_of(p);
}

TEST(RolePair, AMoveThatWouldLeaveNobodyToTakeTheBusIsRefused) {
  struct Case {
    const char* what;
    std::function<void(Pair&)> fault;
    int asked;
    const char* reason;
  };
  const Case cases[] = {
      {"asked of the standby", [](Pair&) {}, 1, "this instance is standby, not active"},
      {"network cut", [](Pair& p) { p.dds_up = false; }, 0, "the peer's role heartbeat is older than the lease"},
      {"the standby off the bus", [](Pair& p) { p.set_bus(1, BusState::BusOff); }, 0,
       "the peer is no_bus, not standby"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.what);
    Pair p(2, 1);
    settle(p);
    c.fault(p);
    p.run_for(std::chrono::seconds(1));
    const MoveResult move = p.machine(c.asked).hand_over(p.now());
    EXPECT_FALSE(move.accepted);
    EXPECT_NE(move.reason.find(c.reason), std::string::npos) << move.reason;
    EXPECT_EQ(p.role(0), Role::Active);
  }
}

}  // namespace
}  // namespace pmu::redundancy::pair_test
