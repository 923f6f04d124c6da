// The simulated PMU behind the service's bus worker, its readiness tracker and the command
// service: what a set does is judged on the values the unit reports now (policy.hpp's
// DeviceUse, filled on the worker's thread), and a PMU whose alarms cannot see what they read
// is not READY (readiness_rules.hpp, input_missing). docs/safety.md H2, H3, H6.
#include <gtest/gtest.h>

#include "support/harness.hpp"
#include "pmu/dispatch/command_service.hpp"
#include "pmu/readiness/readiness_tracker.hpp"

namespace pmu::service::test {
namespace {

// PMU 1 (simulated, factory values: T_U 80 degC, every packet streamed every 1 s) on sim0
// as `config` says, at `internal` degC; the tracker between the bus worker and a recording
// sink, and a command service as a ground station reaches it.
class Vehicle {
 public:
  Vehicle(DeviceConfig config, double internal)
      : buses_{sim_bus({config})},
        tracker(buses_, Timeouts{}.stale_periods, sink, tracker_clock),
        h(buses_[0], {pmu(1)}, Timeouts{}, &tracker),
        commands({&h.worker()}, PolicyConfig{}, Timeouts{}, h.clock(),
                 [this](const CommandReplyData& r) { replies.push_back(r); }) {
    heat(internal);
  }

  void heat(double internal) {
    h.pmus().with_model(1, [this, internal](sim::PmuModel& m) {
      auto p = m.plant();
      p.internal_temperature = internal;
      m.set_plant(p, h.clock().steady_now());
    });
  }
  // The bus and the tracker's clock move together.
  void run_for(std::chrono::milliseconds d) {
    h.run_for(d);
    tracker_clock.advance(d);
  }
  // A set as pmuctl sends it; runs the bus until its reply.
  CommandReplyData set(const char* parameter, double value, bool confirm = false) {
    CommandSample s;
    s.request_id = "set-" + std::to_string(++next_id_);
    s.sender = "test";
    s.bus = "sim0";
    s.address = 1;
    s.kind = static_cast<std::uint32_t>(CommandKind::SetParameter);
    s.parameter = parameter;
    s.value = value;
    s.confirm = confirm ? 1 : 0;
    const auto before = replies.size();
    commands.submit(s);
    for (int i = 0; i < 500 && replies.size() == before; ++i) run_for(std::chrono::milliseconds(10));
    return replies.size() > before ? replies.back() : CommandReplyData{};
  }
  // The messages of PMU 1's input_missing reasons.
  std::vector<std::string> missing() const {
    std::vector<std::string> out;
    for (const auto& r : tracker.current().reasons)
      if (r.code == "input_missing" && r.device == 1) out.push_back(r.message);
    return out;
  }
  // Sets the service sent to the PMU.
  std::size_t sets_sent() const {
    std::size_t n = 0;
    for (const auto& m : h.sent())
      if (!m.request && std::holds_alternative<codec::ParameterValue>(m.payload)) ++n;
    return n;
  }

 private:
  std::vector<BusConfig> buses_;
  int next_id_ = 0;

 public:
  transport::ManualClock tracker_clock;
  RecordingSink sink;
  ReadinessTracker tracker;
  Harness h;
  std::vector<CommandReplyData> replies;
  CommandService commands;
};

DeviceConfig streamed() { return device(1); }

DeviceConfig polled(std::uint8_t groups) {
  DeviceConfig d = device(1, TelemetryMode::Polling);
  d.groups = groups;
  return d;
}

// At 95 degC over its T_U of 80 the unit is in thermal shutdown; polled for voltages and
// currents only, the service hears neither the flag nor the temperature.
TEST(InputsOfTheRules, APmuPolledWithoutStatusAndTemperaturesIsNotReady) {
  Vehicle v(polled(codec::group_bit::Voltages | codec::group_bit::Currents), 95);
  v.run_for(std::chrono::milliseconds(3000));
  ASSERT_TRUE(v.h.worker().session(1)->ready());
  EXPECT_EQ(v.h.worker().session(1)->health().state, HealthState::Online);
  EXPECT_FALSE(v.tracker.current().ready);
  EXPECT_EQ(v.missing(), (std::vector<std::string>{"PMU 1 status not monitored", "PMU 1 temperatures not monitored"}));

  Vehicle all(polled(codec::group_bit::All), 35);
  all.run_for(std::chrono::milliseconds(3000));
  EXPECT_TRUE(all.missing().empty());
  EXPECT_TRUE(all.tracker.current().ready);
}

// Streaming at 35 degC: dropping temperatures and status from PS needs confirm; once done the
// PMU is not READY at once, and with the temperature gone stale a low T_U still needs confirm.
TEST(InputsOfTheRules, DroppingAPacketTheRulesReadNeedsConfirmAndMakesItNotReady) {
  Vehicle v(streamed(), 35);
  v.run_for(std::chrono::milliseconds(2500));
  ASSERT_TRUE(v.tracker.current().ready);
  const auto before = v.sets_sent();

  auto r = v.set("packets_streamed", codec::group_bit::Voltages);
  EXPECT_EQ(r.result, CommandResult::Denied) << r.reason;
  EXPECT_NE(r.reason.find("rule blind_monitoring"), std::string::npos) << r.reason;
  EXPECT_EQ(v.sets_sent(), before) << "a denied set reached the bus";
  EXPECT_EQ(v.set("packets_streamed", codec::group_bit::All & ~codec::group_bit::Currents).result,
            CommandResult::Completed)
      << "currents are read by no rule";

  r = v.set("packets_streamed", codec::group_bit::Voltages, true);
  ASSERT_EQ(r.result, CommandResult::Completed) << r.reason;
  EXPECT_FALSE(v.tracker.current().ready);
  EXPECT_EQ(v.missing(), (std::vector<std::string>{"PMU 1 status not monitored", "PMU 1 temperatures not monitored"}));

  // The last temperature (35 degC) is still fresh: T_U 1 is at or below it.
  r = v.set("upper_temperature_limit", 1);
  EXPECT_EQ(r.result, CommandResult::Denied) << r.reason;
  EXPECT_NE(r.reason.find("internal temperature 35 degC"), std::string::npos) << r.reason;
  // Three periods later it is unknown: any T_U a temperature could reach needs confirm.
  v.run_for(std::chrono::milliseconds(3500));
  r = v.set("upper_temperature_limit", 100);
  EXPECT_EQ(r.result, CommandResult::Denied) << r.reason;
  EXPECT_NE(r.reason.find("internal temperature is unknown"), std::string::npos) << r.reason;
  EXPECT_EQ(v.set("upper_temperature_limit", 128).result, CommandResult::Completed);
}

// T_U against the unit's internal temperature as it reports it now (v1.9 5.14).
TEST(InputsOfTheRules, AnUpperTemperatureLimitIsJudgedOnTheTemperatureNow) {
  Vehicle v(streamed(), 35);
  v.run_for(std::chrono::milliseconds(2500));
  EXPECT_EQ(v.set("upper_temperature_limit", 85).result, CommandResult::Completed);
  const auto before = v.sets_sent();
  auto r = v.set("upper_temperature_limit", 1);
  EXPECT_EQ(r.result, CommandResult::Denied) << r.reason;
  EXPECT_NE(r.reason.find("rule thermal_shutdown"), std::string::npos) << r.reason;
  EXPECT_EQ(v.set("upper_temperature_limit", 35).result, CommandResult::Denied);
  EXPECT_EQ(v.sets_sent(), before) << "a denied set reached the bus";

  v.heat(95);
  v.run_for(std::chrono::milliseconds(1500));  // a temperatures packet at 95 degC
  EXPECT_EQ(v.set("upper_temperature_limit", 90).result, CommandResult::Denied);
  EXPECT_EQ(v.set("upper_temperature_limit", 96).result, CommandResult::Completed);
  EXPECT_EQ(v.set("upper_temperature_limit", 1, true).result, CommandResult::Completed) << "confirmed";
}

}  // namespace
}  // namespace pmu::service::test
