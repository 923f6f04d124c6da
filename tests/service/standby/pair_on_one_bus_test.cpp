// Two instances of a hot-standby pair on one simulated CAN bus with a PMU, each a BusWorker
// behind its FencedBus, its RoleHolder and its RoleGate, as pmu-service runs them, on one fake
// clock; their pmu/role heartbeats go through a link the test can cut. Every step checks the
// pair's promise on the wire: PMU frames from one instance only, and only from the one whose
// role is ACTIVE (docs/design.md, "Hot standby").

#include <gtest/gtest.h>

#include <deque>
#include <memory>
#include <string>

#include "support/harness.hpp"
#include "pmu/redundancy/can_beat.hpp"
#include "pmu/standby/fenced_bus.hpp"
#include "pmu/standby/ownership.hpp"
#include "pmu/standby/role_gate.hpp"
#include "pmu/standby/role_holder.hpp"

namespace pmu::service::test {
namespace {

using redundancy::Role;
using standby::FencedBus;
using standby::RoleGate;
using standby::RoleHolder;

// pmu/role between the two hosts: what one publishes reaches the other at the next step,
// unless the network is cut.
struct RoleLink {
  bool cut = false;
  std::deque<redundancy::RoleReport> to_a, to_b;
};

class Instance {
 public:
  Instance(const std::string& name, std::uint8_t priority, const std::string& peer, transport::SimulatedNetwork& net,
           transport::ManualClock& clock, std::deque<redundancy::RoleReport>& outbox, RoleLink& link)
      : clock_(clock) {
    redundancy::Settings s;
    s.name = name;
    s.peer = peer;
    s.priority = priority;
    RoleHolder::Outputs out;
    out.publish = [&outbox, &link](const redundancy::RoleReport& r) {
      if (!link.cut) outbox.push_back(r);
    };
    out.peer_joined = [this] { worker->post([this] { worker->repeat_readings(); }); };
    out.changed = [this](const standby::RoleChange& c) { ownership->on_change(c); };
    holder = std::make_unique<RoleHolder>(s, clock.steady_now(), std::move(out));
    gate = std::make_unique<RoleGate>(sink, [this] { ++clears; });
    ownership = std::make_unique<standby::Ownership>(*gate, [this] { ++takeovers; });
    ownership->judge_with(*holder, clock);
    transport::SimBusOptions options;
    options.filters = transport::default_filters(false);
    options.filters.push_back({redundancy::kCanBeatIdBase, 0x1FFFFF00u, true});
    auto recording = std::make_unique<RecordingBus>(net.attach("sim0", options));
    wire = recording.get();
    auto fenced = std::make_unique<FencedBus>(std::move(recording), *holder, clock);
    fence = fenced.get();
    worker = std::make_unique<BusWorker>(sim_bus({device(1, TelemetryMode::Streaming, 100ms)}), std::move(fenced),
                                         clock, Timeouts{}, *gate);
    worker->every(std::chrono::duration_cast<std::chrono::milliseconds>(redundancy::poll_period(s)),
                  [this](std::chrono::steady_clock::time_point t) { holder->tick(t); });
  }

  // PMU frames this instance put on the wire (its CAN heartbeats not counted).
  std::size_t pmu_frames() const {
    std::size_t n = 0;
    for (const auto& f : wire->sent)
      if (!redundancy::is_can_beat_id(f.id, f.extended)) ++n;
    return n;
  }
  std::size_t telemetry_published() const { return sink.telemetry.size(); }

  RecordingSink sink;
  std::unique_ptr<RoleHolder> holder;
  std::unique_ptr<RoleGate> gate;
  std::unique_ptr<standby::Ownership> ownership;
  RecordingBus* wire = nullptr;
  FencedBus* fence = nullptr;
  std::unique_ptr<BusWorker> worker;
  int clears = 0;
  int takeovers = 0;    // Ownership's took_over: the commands' settling
  bool running = true;  // false: killed or frozen, the test no longer runs it

 private:
  transport::ManualClock& clock_;
};

class StandbyPair : public ::testing::Test {
 protected:
  StandbyPair() : network_(clock_) {
    runner_ = std::make_unique<sim::BusRunner>(network_.attach("pmu-sim"), clock_);
    runner_->add(pmu(1, codec::kCurrentFirmware, 10));
    a_ = std::make_unique<Instance>("mc-a", 2, "mc-b", network_, clock_, link_.to_b, link_);
    b_ = std::make_unique<Instance>("mc-b", 1, "mc-a", network_, clock_, link_.to_a, link_);
  }

  // Moves the clock in 10 ms steps; after each, everything running acts, and the wire is
  // checked: no PMU frame from an instance that is not ACTIVE.
  void run_for(std::chrono::milliseconds total) {
    for (auto t = 0ms; t < total; t += 10ms) {
      clock_.advance(10ms);
      for (int i = 0; i < 3; ++i) {
        deliver();
        for (auto* x : {a_.get(), b_.get()}) {
          if (!x->running) continue;
          const auto before = x->pmu_frames();
          x->worker->run_once(0ms);
          if (x->pmu_frames() != before) {
            EXPECT_EQ(x->holder->role(), Role::Active) << "a PMU frame from an instance that does not own the bus";
          }
        }
        runner_->run_once(0ms);
      }
      if (a_->running && b_->running) {
        EXPECT_FALSE(a_->holder->role() == Role::Active && b_->holder->role() == Role::Active) << "two bus owners";
      }
    }
  }
  void deliver() {
    const auto now = clock_.steady_now();
    while (!link_.to_a.empty()) {
      if (a_->running && !link_.cut) a_->holder->on_report(link_.to_a.front(), now);
      link_.to_a.pop_front();
    }
    while (!link_.to_b.empty()) {
      if (b_->running && !link_.cut) b_->holder->on_report(link_.to_b.front(), now);
      link_.to_b.pop_front();
    }
  }
  // How long, in 10 ms steps, until `x` is ACTIVE; fails after `limit`.
  std::chrono::milliseconds until_active(Instance& x, std::chrono::milliseconds limit) {
    auto waited = 0ms;
    while (x.holder->role() != Role::Active && waited < limit) {
      run_for(10ms);
      waited += 10ms;
    }
    EXPECT_EQ(x.holder->role(), Role::Active);
    return waited;
  }

  transport::ManualClock clock_;
  transport::SimulatedNetwork network_;
  std::unique_ptr<sim::BusRunner> runner_;
  RoleLink link_;
  std::unique_ptr<Instance> a_, b_;
};

TEST_F(StandbyPair, OneOwnerAtStartTheOtherListensAndPublishesNothing) {
  run_for(2s);
  EXPECT_EQ(a_->holder->role(), Role::Active);
  EXPECT_EQ(b_->holder->role(), Role::Standby);
  EXPECT_GT(a_->pmu_frames(), 0u) << "the owner reads the PMU";
  EXPECT_EQ(b_->pmu_frames(), 0u);
  EXPECT_GT(b_->fence->fenced(), 0u) << "the standby's sessions tried and were held back";
  EXPECT_GT(a_->telemetry_published(), 0u);
  EXPECT_EQ(b_->telemetry_published(), 0u) << "a second stream per device";
  EXPECT_TRUE(b_->sink.healths.empty());
}

TEST_F(StandbyPair, KilledOwnerTheStandbyTakesOverWithItsWarmState) {
  run_for(2s);
  ASSERT_EQ(a_->holder->role(), Role::Active);
  a_->running = false;  // SIGKILL: nothing of it runs, on CAN or DDS
  const auto took = until_active(*b_, 2s);
  EXPECT_LE(took, 500ms) << "lease 0.3 s and can_silence 0.15 s, claim window 0.1 s";
  EXPECT_TRUE(b_->ownership->executing());
  EXPECT_EQ(b_->takeovers, 1) << "what the former owner left is settled once";
  // Its kept state goes out at once, before any new frame: health ONLINE, config, info.
  ASSERT_FALSE(b_->sink.healths.empty());
  EXPECT_EQ(b_->sink.healths.front().second.state, HealthState::Online);
  EXPECT_FALSE(b_->sink.configs.empty()) << "the configuration heard while standing by";
  const auto before = b_->telemetry_published();
  run_for(1500ms);  // the PMU streams every 1.0 s
  EXPECT_GT(b_->telemetry_published(), before) << "the new owner publishes the PMU's stream";
}

// A standby that starts after the owner read the devices cannot ask them itself: the owner asks
// again when it hears the newcomer, and the newcomer takes over with the configuration known.
TEST_F(StandbyPair, AStandbyThatJoinsLateHearsTheOwnerReadTheDevicesAgain) {
  b_->running = false;
  run_for(3s);
  ASSERT_EQ(a_->holder->role(), Role::Active);
  link_.to_b.clear();
  b_ = std::make_unique<Instance>("mc-b", 1, "mc-a", network_, clock_, link_.to_a, link_);
  run_for(3s);
  ASSERT_EQ(b_->holder->role(), Role::Standby);
  a_->running = false;
  until_active(*b_, 2s);
  EXPECT_FALSE(b_->sink.configs.empty()) << "the configuration at the takeover, from the owner's repeated gets";
  EXPECT_FALSE(b_->sink.infos.empty()) << "serial and firmware too";
}

TEST_F(StandbyPair, NetworkCutNobodyTakesOverWhileTheOwnerIsHeardOnCan) {
  run_for(2s);
  link_.cut = true;
  run_for(1s);
  const auto before = a_->telemetry_published();
  run_for(2s);
  EXPECT_EQ(a_->holder->role(), Role::Active);
  EXPECT_GT(a_->telemetry_published(), before) << "the owner's alarm changed, not its role: it still publishes";
  EXPECT_EQ(a_->clears, 0);
  EXPECT_TRUE(a_->ownership->executing()) << "and it still executes commands";
  EXPECT_FALSE(b_->ownership->executing());
  EXPECT_EQ(b_->holder->role(), Role::Fenced);
  EXPECT_EQ(b_->pmu_frames(), 0u);
  EXPECT_NE(b_->holder->status().find("partition"), std::string::npos) << b_->holder->status();
  EXPECT_NE(a_->holder->status().find("peer_unreachable"), std::string::npos) << a_->holder->status();
  link_.cut = false;
  run_for(1s);
  EXPECT_EQ(b_->holder->role(), Role::Standby);
}

TEST_F(StandbyPair, FrozenOwnerStepsDownOnItsFirstCallAndSendsNothingStale) {
  run_for(2s);
  a_->running = false;  // SIGSTOP
  until_active(*b_, 2s);
  run_for(1s);
  const auto a_frames = a_->pmu_frames();
  const auto clears = a_->clears;
  const auto a_samples = a_->telemetry_published();
  // On SIGCONT its DDS listeners may run before its bus thread: a resend they take now finds
  // the role still ACTIVE in the machine, and must not be answered on it.
  EXPECT_EQ(a_->holder->role(), Role::Active) << "its bus thread has not run since the freeze";
  EXPECT_FALSE(a_->ownership->executing()) << "a listener woken with the frozen owner would act as the owner";
  a_->running = true;  // SIGCONT: its timers are all due at once, its socket full of frames
  run_for(1s);
  EXPECT_EQ(a_->pmu_frames(), a_frames) << "the resumed former owner sent a PMU frame";
  EXPECT_EQ(a_->telemetry_published(), a_samples) << "the resumed former owner published beside the new one";
  EXPECT_NE(a_->holder->role(), Role::Active);
  EXPECT_FALSE(a_->ownership->executing());
  EXPECT_EQ(b_->holder->role(), Role::Active) << "it takes nothing back";
  EXPECT_EQ(a_->clears, clears + 1) << "its state topics' histories are cleared";
}

TEST_F(StandbyPair, CleanHandOverOnSigterm) {
  run_for(2s);
  a_->holder->leave(clock_.steady_now());
  a_->holder->tick(clock_.steady_now());  // what main does on SIGTERM: release sent on the bus thread
  EXPECT_EQ(a_->holder->role(), Role::Leaving);
  run_for(10ms);
  a_->running = false;
  const auto took = until_active(*b_, 1s);
  EXPECT_LT(took, 300ms) << "a hand-over need not wait for the lease";
}

TEST_F(StandbyPair, BusLossOfTheOwnerIsAFailover) {
  run_for(2s);
  // A's own interface fails: its bus events say DOWN; it can no longer send or hear.
  a_->holder->on_bus_state(clock_.steady_now(), transport::BusState::Down);
  EXPECT_EQ(a_->holder->role(), Role::NoBus);
  EXPECT_EQ(a_->clears, 1);
  until_active(*b_, 1s);
}

TEST_F(StandbyPair, TheOldOwnerReturnsAsStandby) {
  run_for(2s);
  a_->running = false;
  until_active(*b_, 2s);
  run_for(500ms);
  // A restarts: a new instance of the same name and priority.
  link_.to_a.clear();
  a_ = std::make_unique<Instance>("mc-a", 2, "mc-b", network_, clock_, link_.to_b, link_);
  run_for(2s);
  EXPECT_EQ(a_->holder->role(), Role::Standby);
  EXPECT_EQ(b_->holder->role(), Role::Active);
  EXPECT_EQ(a_->pmu_frames(), 0u);
}

TEST_F(StandbyPair, AMoveHandsTheBusToTheStandby) {
  run_for(2s);
  EXPECT_FALSE(b_->holder->hand_over(clock_.steady_now()).accepted) << "a standby has nothing to hand over";
  const auto moved = a_->holder->hand_over(clock_.steady_now());
  ASSERT_TRUE(moved.accepted) << moved.reason;
  until_active(*b_, 1s);
  run_for(2s);
  EXPECT_EQ(a_->holder->role(), Role::Standby);
}

}  // namespace
}  // namespace pmu::service::test
