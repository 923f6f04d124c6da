// Batteries and MPPTs on a BusRunner over the in-process bus, with a manual clock: what a
// listener on the bus receives, the harness controls under the runner's lock, and the
// runner waking at the devices' deadlines.
#include <gtest/gtest.h>

#include <chrono>
#include <map>
#include <set>
#include <stdexcept>

#include "pmu/codec/canopen.hpp"
#include "pmu/sim/bus_runner.hpp"
#include "pmu/transport/sim_bus.hpp"

namespace pmu::sim::test {
namespace {

using namespace std::chrono_literals;

struct Listener final : transport::BusHandler {
  std::vector<transport::ReceivedFrame> frames;
  void on_frame(const transport::ReceivedFrame& f) override { frames.push_back(f); }
  void on_event(const transport::BusEvent&) override {}
};

class RunnerHarness {
 public:
  RunnerHarness() : network(clock), runner(network.attach("pmu-sim"), clock), bus(network.attach("listener")) {}

  // Moves the clock in `step`s, one runner turn each, and collects what reached the bus.
  void run(std::chrono::milliseconds total, std::chrono::milliseconds step = 10ms) {
    for (auto t = 0ms; t < total; t += step) {
      clock.advance(step);
      runner.run_once(0ms);
    }
    (void)bus->drain(listener);
  }

  // COB-ID -> frames received, each decoded without error.
  std::map<std::uint16_t, int> take() {
    (void)bus->drain(listener);
    std::map<std::uint16_t, int> per_id;
    for (const auto& f : listener.frames) {
      const auto m = codec::canopen::decode(f.frame);
      EXPECT_TRUE(m.ok()) << m.error().describe();
      if (m) ++per_id[m->cob_id];
    }
    listener.frames.clear();
    return per_id;
  }

  transport::ManualClock clock;
  transport::SimulatedNetwork network;
  BusRunner runner;
  std::unique_ptr<transport::SimBus> bus;
  Listener listener;
};

int battery_frames(std::map<std::uint16_t, int>& per_id) {
  return per_id[0x202] + per_id[0x302] + per_id[0x402] + per_id[0x482];
}

TEST(RunnerSolar, BatteriesAndMpptsReachTheBus) {
  RunnerHarness h;
  h.runner.add_battery(BatterySimConfig{});
  MpptSimConfig m;
  m.device = 3;
  m.period = 500ms;
  h.runner.add_mppt(m);
  h.run(990ms);  // [0, 1 s): the frame at 1 s starts the next period
  auto per_id = h.take();
  EXPECT_EQ(battery_frames(per_id), 25) << "node 2, 12 cells, one period";
  EXPECT_EQ(per_id[0x4FE] + per_id[0x4FF], 2 * 20) << "MPPT 3, two periods";
  EXPECT_EQ(per_id.size(), 6u);
}

TEST(RunnerSolar, HarnessControlsRunUnderTheLock) {
  RunnerHarness h;
  h.runner.add_battery(BatterySimConfig{});
  h.runner.add_mppt(MpptSimConfig{});
  EXPECT_FALSE(h.runner.with_battery(3, [](BatteryModel&) { ADD_FAILURE() << "no battery 3"; }));
  EXPECT_FALSE(h.runner.with_mppt(1, [](MpptModel&) { ADD_FAILURE() << "no MPPT 1"; }));

  // The battery and MPPT share one plant: the sun set through one is seen by the other.
  ASSERT_TRUE(h.runner.with_mppt(0, [&](MpptModel& m) { m.plant().set_irradiance(0.0, h.clock.steady_now()); }));
  double seen = -1;
  ASSERT_TRUE(h.runner.with_battery(2, [&](BatteryModel& b) { seen = b.plant().irradiance(); }));
  EXPECT_EQ(seen, 0.0);

  // Silence the battery: only the MPPT is heard; then it comes back.
  CanOpenFaults silent;
  silent.silent = true;
  ASSERT_TRUE(h.runner.with_battery(2, [&](BatteryModel& b) { b.set_faults(silent); }));
  h.run(1990ms);
  auto per_id = h.take();
  EXPECT_EQ(battery_frames(per_id), 0);
  EXPECT_EQ(per_id[0x4E6] + per_id[0x4E7], 40);
  ASSERT_TRUE(h.runner.with_battery(2, [](BatteryModel& b) { b.set_faults(CanOpenFaults{}); }));
  h.run(1000ms);
  per_id = h.take();
  EXPECT_EQ(battery_frames(per_id), 25);
}

TEST(RunnerSolar, AddingAgainReplacesTheDevice) {
  RunnerHarness h;
  h.runner.add_battery(BatterySimConfig{});
  BatterySimConfig four;
  four.cells = 4;
  four.initial_soc = 0.25;
  h.runner.add_battery(four);  // node 2 again
  h.run(990ms);
  auto per_id = h.take();
  EXPECT_EQ(per_id[0x482], 4);
  double soc = -1;
  ASSERT_TRUE(h.runner.with_battery(2, [&](BatteryModel& b) { soc = b.plant().state_of_charge(2).value_or(-1); }));
  EXPECT_NEAR(soc, 0.25, 0.01) << "the replacement is in the plant, not removed with the old model";

  // A refused replacement leaves the device that was there.
  BatterySimConfig bad = four;
  bad.cells = 16;
  EXPECT_THROW(h.runner.add_battery(bad), std::invalid_argument);
  MpptSimConfig bad_mppt;
  bad_mppt.panels = 5;
  EXPECT_THROW(h.runner.add_mppt(bad_mppt), std::invalid_argument);
  EXPECT_FALSE(h.runner.with_mppt(0, [](MpptModel&) {}));
  h.run(1000ms);
  per_id = h.take();
  EXPECT_EQ(per_id[0x482], 4);
  EXPECT_EQ(per_id[0x302], 6);
}

TEST(RunnerSolar, TheRunnerWakesAtTheDevicesDeadlines) {
  RunnerHarness h;
  BatterySimConfig b;
  b.cells = 7;  // 20 frames a second: one every 50 ms
  h.runner.add_battery(b);
  h.runner.run_once(0ms);  // frame 0, due at once
  (void)h.bus->drain(h.listener);
  ASSERT_EQ(h.listener.frames.size(), 1u);

  // Frame 1 is due in 50 ms of the manual clock: a turn given 20 ms finds nothing to do.
  h.runner.run_once(20ms);
  (void)h.bus->drain(h.listener);
  EXPECT_EQ(h.listener.frames.size(), 1u);

  // Once it is due, a turn allowed to wait 5 s ends at once: the timer was armed for it.
  h.clock.advance(50ms);
  const auto before = std::chrono::steady_clock::now();
  h.runner.run_once(5000ms);
  EXPECT_LT(std::chrono::steady_clock::now() - before, 1s);
  (void)h.bus->drain(h.listener);
  EXPECT_EQ(h.listener.frames.size(), 2u);
}

}  // namespace
}  // namespace pmu::sim::test
