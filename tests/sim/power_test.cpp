// Battery energy integration (table 4: time-integral of current into the battery, mAh) and
// thermal shutdown (table 15: T_U = 0 forces it, 255 disables it, ~10% hysteresis; 5.14:
// charging ceases, the 28 V output takes the highest battery voltage, outputs unaffected).
#include <gtest/gtest.h>

#include "sim_harness.hpp"

namespace pmu::sim::test {
namespace {

namespace ob = codec::output_bit;

// ---- energy ------------------------------------------------------------------------------
struct EnergyCase {
  const char* what;
  std::uint8_t outputs;
  bool engine_running;
  bool generation;
  std::uint32_t upper_limit;  // T_U
  double charge_current;
  Duration duration, step;
  double mah_a, mah_b;
};

// Loads for every case: avionics 1 A at V_A 12.0 V, servo 0 A at 6.0 V, payload and 28 V
// output 0 A; batteries at 20.0 V. Off the generator the two batteries share 12 W: 0.3 A each.
const EnergyCase kEnergy[] = {
    {"charging both, fine ticks", ob::All, true, true, 80, 2.0, 1h, 100ms, 2000, 2000},
    {"charging both, one tick", ob::All, true, true, 80, 2.0, 1h, 1h, 2000, 2000},
    {"charger A only", ob::AvionicsServo | ob::ChargerA, true, true, 80, 1.5, 30min, 1s, 750, 0},
    {"charger B only", ob::ChargerB, true, true, 80, 1.5, 30min, 1s, 0, 750},
    {"generation off: batteries feed the outputs", ob::All, true, false, 80, 2.0, 1h, 1s, -300, -300},
    {"engine stopped", ob::All, false, true, 80, 2.0, 2h, 10s, -600, -600},
    {"nothing on, engine stopped", 0, false, true, 80, 2.0, 1h, 1min, 0, 0},
    {"saturates at +32767", ob::All, true, true, 80, 10.0, 4h, 1h, 40000, 40000},
};

TEST(SimEnergy, IntegratesBatteryCurrent) {
  for (const auto& c : kEnergy) {
    SCOPED_TRACE(c.what);
    Harness h;
    Plant p;
    p.avionics_load = 1.0;
    p.servo_load = 0;
    p.payload_load = 0;
    p.output_28v_load = 0;
    p.battery_a_voltage = p.battery_b_voltage = 20.0;
    p.charge_current = c.charge_current;
    h.pmu.set_plant(p, h.now);
    h.pmu.set_engine_running(c.engine_running, h.now);
    h.deliver(codec::encode_set_outputs(c.outputs, 1));
    h.deliver(codec::encode_generation(c.generation, 1));
    h.deliver(codec::encode_set(Parameter::UpperTemperatureLimit, c.upper_limit, 1));
    h.run(c.duration, c.step);
    EXPECT_NEAR(h.pmu.battery_a_mah(), c.mah_a, 1e-6);
    EXPECT_NEAR(h.pmu.battery_b_mah(), c.mah_b, 1e-6);
    const auto e = h.get<codec::BatteryEnergy>(PacketId::BatteryEnergy);
    ASSERT_TRUE(e);
    EXPECT_EQ(e->battery_a_mah, static_cast<std::int16_t>(std::min(c.mah_a, 32767.0)));
    EXPECT_EQ(e->battery_b_mah, static_cast<std::int16_t>(std::min(c.mah_b, 32767.0)));
  }
}

TEST(SimEnergy, ChargingStartsWhenTheEngineFires) {
  // The engine fires 30 min into cranking (CT 0: no timeout); one tick an hour later still
  // integrates only the half hour of charging.
  Harness h;
  Plant p;
  p.engine_starts_after = 30min;
  p.charge_current = 2.0;
  p.avionics_load = p.servo_load = p.payload_load = p.output_28v_load = 0;
  h.pmu.set_plant(p, h.now);
  h.deliver(codec::encode_set(Parameter::CrankingTime, 0, 1));
  h.deliver(codec::encode_engine_start(1));
  h.now += 1h;
  h.pmu.tick(h.now);
  EXPECT_EQ(h.pmu.engine_state(), EngineState::Running);
  EXPECT_NEAR(h.pmu.battery_a_mah(), 1000, 1e-6);
}

TEST(SimEnergy, PlantChangeAppliesFromItsTime) {
  Harness h;
  Plant p;
  p.charge_current = 1.0;
  h.pmu.set_plant(p, h.now);
  h.pmu.set_engine_running(true, h.now);
  h.now += 1h;
  p.charge_current = 3.0;
  h.pmu.set_plant(p, h.now);  // the first hour at 1 A
  h.now += 1h;
  h.pmu.tick(h.now);
  EXPECT_NEAR(h.pmu.battery_a_mah(), 4000, 1e-6);
}

// ---- thermal shutdown --------------------------------------------------------------------
struct ThermalStep {
  double temperature;
  bool shutdown;
};
struct ThermalCase {
  const char* what;
  std::uint32_t limit;
  std::vector<ThermalStep> steps;
};

const ThermalCase kThermal[] = {
    {"T_U 0 forces shutdown", 0, {{-40, true}, {25, true}, {127, true}}},
    {"T_U 255 disables it", 255, {{25, false}, {127, false}, {300, false}}},
    {"above the limit, not at it", 80, {{80, false}, {80.5, true}}},
    {"~10% hysteresis",
     100,
     {{99, false}, {101, true}, {95, true}, {90, true}, {89.9, false}, {95, false}, {100, false}, {100.5, true}}},
};

TEST(SimThermal, LimitAndHysteresis) {
  for (const auto& c : kThermal) {
    SCOPED_TRACE(c.what);
    Harness h;
    h.deliver(codec::encode_set(Parameter::UpperTemperatureLimit, c.limit, 1));
    Plant p;
    for (const auto& step : c.steps) {
      SCOPED_TRACE(step.temperature);
      p.internal_temperature = step.temperature;
      h.pmu.set_plant(p, h.now);
      h.run(100ms);
      EXPECT_EQ(h.pmu.thermal_shutdown(), step.shutdown);
      EXPECT_EQ(h.get<codec::Status>(PacketId::Status)->thermal_shutdown, step.shutdown);
    }
  }
}

TEST(SimThermal, LimitSetTakesEffectAtOnce) {
  Harness h;
  h.deliver(codec::encode_set(Parameter::UpperTemperatureLimit, 0, 1));
  EXPECT_TRUE(h.get<codec::Status>(PacketId::Status)->thermal_shutdown);
  h.deliver(codec::encode_set(Parameter::UpperTemperatureLimit, 255, 1));
  EXPECT_FALSE(h.get<codec::Status>(PacketId::Status)->thermal_shutdown);
}

TEST(SimThermal, ShutdownStopsChargingOnly) {
  Harness h;
  Plant p;
  p.avionics_load = p.servo_load = p.payload_load = p.output_28v_load = 0;
  p.charge_current = 2.0;
  p.battery_a_voltage = 21.0;
  p.battery_b_voltage = 23.5;
  p.output_28v_voltage = 28.0;
  h.pmu.set_plant(p, h.now);
  h.pmu.set_engine_running(true, h.now);

  auto a = h.get<codec::Currents>(PacketId::Currents);
  EXPECT_DOUBLE_EQ(a->battery_a, 2.0);
  EXPECT_DOUBLE_EQ(h.get<codec::Voltages>(PacketId::Voltages)->output_28v, 28.0);

  h.deliver(codec::encode_set(Parameter::UpperTemperatureLimit, 0, 1));
  a = h.get<codec::Currents>(PacketId::Currents);
  EXPECT_DOUBLE_EQ(a->battery_a, 0.0);
  EXPECT_DOUBLE_EQ(a->battery_b, 0.0);
  const auto v = h.get<codec::Voltages>(PacketId::Voltages);
  EXPECT_DOUBLE_EQ(v->output_28v, 23.6) << "highest battery, 0.2 V steps (23.5 rounds up)";
  EXPECT_DOUBLE_EQ(v->avionics, 12.0) << "outputs unaffected";
  EXPECT_EQ(h.get<codec::Status>(PacketId::Status)->outputs, ob::All) << "chargers stay enabled";
  h.run(1h, 1min);
  EXPECT_NEAR(h.pmu.battery_a_mah(), 0, 1e-9);
}

}  // namespace
}  // namespace pmu::sim::test
