#include "telemetry/generator_status.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace pmu::mavlink_bridge {
namespace generator_status_test {  // named: the unity build joins this file with others of its target
namespace {

namespace flag = pmu::mavlink::mav_generator_status_flag;
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

PmuView running() {
  PmuView v;
  v.online = true;
  v.voltages.emplace();
  v.voltages->generator(28.4F);
  v.currents.emplace();
  v.currents->battery_a(2.0F);
  v.currents->battery_b(1.0F);
  v.temperatures.emplace();
  v.temperatures->generator(64.6F);
  v.status.emplace();
  v.status->generator_rpm(6200.0F);
  v.status->generation_enabled(true);
  v.energy.emplace();
  v.energy->generator_power(180.5F);
  return v;
}

TEST(GeneratorStatus, RunningGeneratorCharging) {
  const auto m = generator_status(running());
  EXPECT_EQ(m.generator_speed, 6200);
  EXPECT_FLOAT_EQ(m.bus_voltage, 28.4F);
  EXPECT_FLOAT_EQ(m.battery_current, -3.0F) << "into the batteries is negative";
  EXPECT_FLOAT_EQ(m.power_generated, 180.5F);
  EXPECT_EQ(m.generator_temperature, 65);
  EXPECT_EQ(m.status, flag::kGenerating | flag::kCharging);
  EXPECT_TRUE(std::isnan(m.load_current)) << "the PMU reports no generator current";
  EXPECT_EQ(m.rectifier_temperature, INT16_MAX);
  EXPECT_TRUE(std::isnan(m.bat_current_setpoint));
  EXPECT_EQ(m.runtime, UINT32_MAX);
  EXPECT_EQ(m.time_until_maintenance, INT32_MAX);
}

TEST(GeneratorStatus, StatusFlags) {
  struct GeneratorCase {
    const char* name;
    bool enabled;
    float rpm;
    bool thermal;
    bool soa;
    bool shed;
    std::uint64_t flags;
  };
  const GeneratorCase cases[] = {
      {"generation disabled", false, 0.0F, false, false, false, flag::kOff},
      {"enabled, engine stopped", true, 0.0F, false, false, false, flag::kReady},
      {"enabled, no rpm reading", true, kNaN, false, false, false, flag::kReady},
      {"running", true, 5000.0F, false, false, false, flag::kGenerating},
      {"thermal shutdown", false, 0.0F, true, false, false, flag::kOff | flag::kElectronicsOvertempFault},
      {"soa shutdown", true, 5000.0F, false, true, false, flag::kGenerating | flag::kOvercurrentFault},
      {"payload shed", true, 5000.0F, false, false, true, flag::kGenerating | flag::kReducedPower},
  };
  for (const auto& c : cases) {
    PmuView v = running();
    v.currents.reset();  // no CHARGING from the batteries
    v.status->generation_enabled(c.enabled);
    v.status->generator_rpm(c.rpm);
    v.status->thermal_shutdown(c.thermal);
    v.status->soa_shutdown(c.soa);
    v.status->payload_shed(c.shed);
    EXPECT_EQ(generator_status(v).status, c.flags) << c.name;
  }
}

TEST(GeneratorStatus, EveryUnknownIsTheSentinel) {
  PmuView nan_values = running();
  nan_values.voltages->generator(kNaN);
  nan_values.currents->battery_b(kNaN);
  nan_values.temperatures->generator(kNaN);
  nan_values.status->generator_rpm(kNaN);
  nan_values.energy->generator_power(kNaN);
  PmuView stale = running();
  stale.online = false;
  PmuView nothing;
  nothing.online = true;
  const std::pair<const char*, PmuView> cases[] = {
      {"NaN", nan_values}, {"not ONLINE (H7)", stale}, {"no sample yet", nothing}};
  for (const auto& [name, view] : cases) {
    const auto m = generator_status(view);
    EXPECT_EQ(m.generator_speed, UINT16_MAX) << name;
    EXPECT_TRUE(std::isnan(m.bus_voltage)) << name;
    EXPECT_TRUE(std::isnan(m.battery_current)) << name;
    EXPECT_TRUE(std::isnan(m.power_generated)) << name;
    EXPECT_EQ(m.generator_temperature, INT16_MAX) << name;
  }
  EXPECT_EQ(generator_status(stale).status, flag::kCommunicationWarning) << "stale says only that";
  EXPECT_EQ(generator_status(nothing).status, 0U) << "no status sample: no flag claimed";
}

}  // namespace
}  // namespace generator_status_test
}  // namespace pmu::mavlink_bridge
