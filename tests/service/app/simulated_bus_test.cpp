// `interface: sim` with `sim:` settings (docs/interface.md section 4.4): a config parsed as
// pmu-service parses it, its bus built by make_simulated_bus as pmu-service builds it, and
// the service's bus worker reading it under a fake clock. What the service would publish
// shows each setting took effect from power-up.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <memory>
#include <string>
#include <variant>

#include "pmu/app/simulated_bus.hpp"
#include "pmu/config/config.hpp"
#include "pmu/session/bus_worker.hpp"
#include "pmu/session/canopen_state.hpp"
#include "support/recording_sink.hpp"

namespace pmu::service::test {
namespace {

using namespace std::chrono_literals;

class SimulatedService {
 public:
  explicit SimulatedService(const std::string& yaml) : config_(parse_config(yaml, "sim.yaml")) {
    sim_ = make_simulated_bus(config_.buses.at(0), clock_);
    worker_ =
        std::make_unique<BusWorker>(config_.buses.at(0), std::move(sim_.service_end), clock_, config_.timeouts, sink);
  }
  ~SimulatedService() { worker_.reset(); }  // before the network its end is on
  SimulatedService(const SimulatedService&) = delete;
  SimulatedService& operator=(const SimulatedService&) = delete;

  void run_for(std::chrono::milliseconds total) {
    for (auto t = 0ms; t < total; t += 10ms) {
      clock_.advance(10ms);
      for (int i = 0; i < 4; ++i) {
        worker_->run_once(0ms);
        sim_.simulator->run_once(0ms);
      }
    }
  }

  template <class Packet>
  const Packet* last(std::uint16_t address = 1) const {
    for (auto it = sink.telemetry.rbegin(); it != sink.telemetry.rend(); ++it)
      if (it->key.address == address)
        if (const auto* p = std::get_if<Packet>(&it->message.payload)) return p;
    return nullptr;
  }
  bool ever(HealthState state, std::uint16_t address, DeviceKind kind = DeviceKind::Pmu) const {
    for (const auto& [key, h] : sink.healths)
      if (key.address == address && key.kind == kind && h.state == state) return true;
    return false;
  }
  sim::BusRunner& simulator() { return *sim_.simulator; }

  RecordingSink sink;

 private:
  Config config_;
  transport::ManualClock clock_;
  SimulatedBus sim_;
  std::unique_ptr<BusWorker> worker_;
};

std::string pmu_with(const std::string& sim) {
  return "buses:\n  - interface: sim\n    devices:\n      - address: 1\n" +
         (sim.empty() ? std::string() : "        sim: {" + sim + "}\n");
}

struct PmuCase {
  const char* sim;  // the PMU's sim: mapping's keys, "" for none
  std::function<void(const SimulatedService&)> check;
};

// Each setting against what the service reads from the unit after 3 s of streaming, beside
// the same reading without it.
const PmuCase kPmuCases[] = {
    {"",
     [](const SimulatedService& s) {
       ASSERT_NE(s.last<codec::Status>(), nullptr);
       EXPECT_EQ(s.last<codec::Status>()->generator_rpm, 6000) << "running by default";
       EXPECT_FALSE(s.last<codec::Status>()->thermal_shutdown);
       EXPECT_TRUE(s.last<codec::Status>()->starter_ready);
       EXPECT_FALSE(s.last<codec::Status>()->soa_shutdown);
       EXPECT_FALSE(s.last<codec::Status>()->payload_shed);
       EXPECT_NEAR(s.last<codec::Voltages>()->battery_a, 22.2, 0.05);
     }},
    {"engine: stopped",
     [](const SimulatedService& s) {
       ASSERT_NE(s.last<codec::Status>(), nullptr);
       EXPECT_EQ(s.last<codec::Status>()->generator_rpm, 0);
       EXPECT_EQ(s.last<codec::Voltages>()->generator, 0);
     }},
    {"engine: running",
     [](const SimulatedService& s) {
       ASSERT_NE(s.last<codec::Status>(), nullptr);
       EXPECT_EQ(s.last<codec::Status>()->generator_rpm, 6000);
     }},
    // T_U is 80 degC from the factory (sim/README.md).
    {"internal_temperature: 95",
     [](const SimulatedService& s) {
       ASSERT_NE(s.last<codec::Status>(), nullptr);
       EXPECT_TRUE(s.last<codec::Status>()->thermal_shutdown);
       EXPECT_EQ(s.last<codec::Status>()->generator_rpm, 6000) << "the engine runs; the PMU stops using it";
       EXPECT_EQ(s.last<codec::Temperatures>()->internal, 95);
     }},
    {"internal_temperature: 79",
     [](const SimulatedService& s) {
       ASSERT_NE(s.last<codec::Status>(), nullptr);
       EXPECT_FALSE(s.last<codec::Status>()->thermal_shutdown);
       EXPECT_EQ(s.last<codec::Temperatures>()->internal, 79);
     }},
    {"battery_a_voltage: 19.5, battery_b_voltage: 0",
     [](const SimulatedService& s) {
       ASSERT_NE(s.last<codec::Voltages>(), nullptr);
       EXPECT_NEAR(s.last<codec::Voltages>()->battery_a, 19.5, 0.05);
       EXPECT_EQ(s.last<codec::Voltages>()->battery_b, 0);
     }},
    {"starter_ready: false, soa_shutdown: true, payload_shed: true",
     [](const SimulatedService& s) {
       ASSERT_NE(s.last<codec::Status>(), nullptr);
       EXPECT_FALSE(s.last<codec::Status>()->starter_ready);
       EXPECT_TRUE(s.last<codec::Status>()->soa_shutdown);
       EXPECT_TRUE(s.last<codec::Status>()->payload_shed);
     }},
    {"firmware: \"1.14\", serial: 4242",
     [](const SimulatedService& s) {
       ASSERT_FALSE(s.sink.infos.empty());
       EXPECT_EQ(s.sink.infos.back().second.serial_number, 4242);
       EXPECT_EQ(s.sink.infos.back().second.firmware.version(), (codec::FirmwareVersion{1, 14}));
     }},
};

TEST(SimulatedBus, EachPmuSettingShowsInWhatTheServiceReads) {
  for (const auto& c : kPmuCases) {
    SCOPED_TRACE(c.sim);
    SimulatedService s(pmu_with(c.sim));
    s.run_for(3000ms);
    EXPECT_TRUE(s.ever(HealthState::Online, 1));
    c.check(s);
  }
}

TEST(SimulatedBus, EngineStartsAfterReachesThePlant) {
  const struct {
    const char* sim;
    std::optional<sim::Duration> expected;
  } cases[] = {
      {"", std::chrono::seconds(2)},  // the model's own
      {"engine_starts_after: 7.5", 7500ms},
      {"engine_starts_after: 0", 0ms},
      {"engine_starts_after: never", std::nullopt},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.sim);
    SimulatedService s(pmu_with(c.sim));
    std::optional<sim::Duration> got = 1h;
    ASSERT_TRUE(s.simulator().with_model(1, [&](sim::PmuModel& m) { got = m.plant().engine_starts_after; }));
    EXPECT_EQ(got, c.expected);
  }
}

TEST(SimulatedBus, ASilentPmuIsNeverOnlineAndGoesOffline) {
  // offline_periods (10) x the device's period (1 s) without a frame.
  SimulatedService s(pmu_with("silent: true"));
  s.run_for(10500ms);
  EXPECT_FALSE(s.ever(HealthState::Online, 1));
  ASSERT_NE(s.sink.last_health(1), nullptr);
  EXPECT_EQ(s.sink.last_health(1)->state, HealthState::Offline);
  EXPECT_EQ(s.last<codec::Status>(), nullptr);
  SimulatedService speaking(pmu_with("silent: false"));
  speaking.run_for(10500ms);
  EXPECT_EQ(speaking.sink.last_health(1)->state, HealthState::Online);
}

std::string canopen_with(const std::string& battery_sim, const std::string& mppt_sim) {
  return "buses:\n  - interface: sim\n    batteries:\n      - node: 2\n        period: 0.5\n" +
         (battery_sim.empty() ? std::string() : "        sim: {" + battery_sim + "}\n") +
         "    mppts:\n      - device: 0\n        period: 0.5\n" +
         (mppt_sim.empty() ? std::string() : "        sim: {" + mppt_sim + "}\n");
}

double battery_value(const SimulatedService& s, const char* name) {
  return s.sink.batteries.empty() ? std::nan("") : s.sink.batteries.back().state.values[*battery_slot(name)];
}
double mppt_value(const SimulatedService& s, const char* name) {
  return s.sink.mppts.empty() ? std::nan("") : s.sink.mppts.back().state.values[*mppt_slot(name)];
}

TEST(SimulatedBus, BatteryStateOfChargeAndCellVoltages) {
  SimulatedService s(canopen_with("state_of_charge: 40, cell_voltages: [3.9, 3.85, 3.7]", ""));
  s.run_for(1000ms);
  EXPECT_NEAR(battery_value(s, "state_of_charge"), 40, 1.0);
  EXPECT_NEAR(battery_value(s, "voltage"), 3.9 + 3.85 + 3.7, 0.002);
  EXPECT_NEAR(battery_value(s, "cell_voltage_high"), 3.9, 0.002);
  EXPECT_NEAR(battery_value(s, "cell_voltage_low"), 3.7, 0.002);
  ASSERT_FALSE(s.sink.cells.empty());
  const auto& volts = s.sink.cells.back().state.volts;
  EXPECT_NEAR(volts[1], 3.9, 0.0005);
  EXPECT_NEAR(volts[2], 3.85, 0.0005);
  EXPECT_NEAR(volts[3], 3.7, 0.0005);
  EXPECT_TRUE(std::isnan(volts[4])) << "three cells";

  SimulatedService counted(canopen_with("cells: 4", ""));
  counted.run_for(1000ms);
  ASSERT_FALSE(counted.sink.cells.empty());
  EXPECT_FALSE(std::isnan(counted.sink.cells.back().state.volts[4]));
  EXPECT_TRUE(std::isnan(counted.sink.cells.back().state.volts[5]));
  EXPECT_NEAR(battery_value(counted, "state_of_charge"), 80, 1.0) << "the model's own";
}

TEST(SimulatedBus, MpptPanels) {
  SimulatedService s(canopen_with("", "panels: 1"));
  s.run_for(1000ms);
  EXPECT_GT(mppt_value(s, "voltage_panel_1_raw"), 0);
  EXPECT_EQ(mppt_value(s, "voltage_panel_2_raw"), 0);
}

struct CanOpenFaultCase {
  const char* battery_sim;
  const char* mppt_sim;
  bool battery_online, mppt_online;
  bool battery_decode_errors, mppt_decode_errors;
};

const CanOpenFaultCase kCanOpenFaults[] = {
    {"", "", true, true, false, false},
    {"silent: true", "", false, true, false, false},
    {"", "silent: true", true, false, false, false},
    // Every frame spoiled: nothing decodes, but the device speaks (interface.md 1.4).
    {"garble: wrong_length", "garble: unknown_subindex", true, true, true, true},
    {"garble: unknown_subindex", "garble: none", true, true, true, false},
};

TEST(SimulatedBus, BatteryAndMpptSilenceAndGarble) {
  for (const auto& c : kCanOpenFaults) {
    SCOPED_TRACE(std::string(c.battery_sim) + " / " + c.mppt_sim);
    SimulatedService s(canopen_with(c.battery_sim, c.mppt_sim));
    s.run_for(6000ms);  // offline_periods (10) x 0.5 s, and a little
    const auto* battery = s.sink.last_health(2, DeviceKind::Battery);
    const auto* mppt = s.sink.last_health(0, DeviceKind::Mppt);
    ASSERT_NE(battery, nullptr);
    ASSERT_NE(mppt, nullptr);
    EXPECT_EQ(battery->state, c.battery_online ? HealthState::Online : HealthState::Offline);
    EXPECT_EQ(mppt->state, c.mppt_online ? HealthState::Online : HealthState::Offline);
    EXPECT_EQ(s.ever(HealthState::Online, 2, DeviceKind::Battery), c.battery_online);
    EXPECT_EQ(s.ever(HealthState::Online, 0, DeviceKind::Mppt), c.mppt_online);
    EXPECT_EQ(battery->decode_errors > 0, c.battery_decode_errors);
    EXPECT_EQ(mppt->decode_errors > 0, c.mppt_decode_errors);
  }
}

}  // namespace
}  // namespace pmu::service::test
