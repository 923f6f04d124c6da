// The physical story the battery and MPPTs tell together: sun -> MPPT power -> battery
// charge; load -> discharge; every value consistent with the others and within the
// document's ranges, as read back through codec::canopen::decode.
#include <gtest/gtest.h>

#include <cmath>

#include "solar_harness.hpp"

namespace pmu::sim::test {
namespace {

constexpr double kEfficiency = 0.96;  // the plant's converter; checked against panel power

SolarWorld world(double load) {
  SolarWorld w;
  w.load_current = load;
  return w;
}

BatterySimConfig pack(double soc, int cells = 12) {
  BatterySimConfig c;
  c.initial_soc = soc;
  c.cells = cells;
  return c;
}

MpptSimConfig mppt(std::uint8_t device) {
  MpptSimConfig c;
  c.device = device;
  return c;
}

// Checks that hold at any moment: the document's ranges and the values' consistency. The
// values of one period are sent at different moments: `drift` is how far a cell may move
// in between (V).
void expect_consistent(const std::map<std::string, double>& v, int cells, double drift = 0.005) {
  EXPECT_GE(v.at("state_of_charge"), 0);
  EXPECT_LE(v.at("state_of_charge"), 100);
  EXPECT_DOUBLE_EQ(v.at("power_level"), v.at("state_of_charge"));
  EXPECT_GE(v.at("current_charge"), 0);
  EXPECT_GE(v.at("current_discharge"), 0);
  EXPECT_NEAR(v.at("current"), v.at("current_charge") - v.at("current_discharge"), 0.03);
  double sum = 0;
  for (int c = 1; c <= cells; ++c) {
    const double cell = v.at("cell_voltage_" + std::to_string(c));
    EXPECT_GE(cell, 2.9) << c;  // Li-ion cell, with I*R
    EXPECT_LE(cell, 4.3) << c;
    EXPECT_LE(cell, v.at("cell_voltage_high") + drift) << c;
    EXPECT_GE(cell, v.at("cell_voltage_low") - drift) << c;
    sum += cell;
  }
  EXPECT_NEAR(v.at("voltage"), sum, drift * cells) << "the pack is its cells in series";
  EXPECT_GE(v.at("cell_temperature_high"), v.at("cell_temperature_low"));
  for (int i = 1; i <= 4; ++i) {
    const double t = v.at("temperature_" + std::to_string(i));
    EXPECT_LE(t, v.at("cell_temperature_high") + 1) << i;
    EXPECT_GE(t, v.at("cell_temperature_low") - 1) << i;
  }
}

void expect_consistent_mppt(const std::map<std::string, double>& v, double battery_voltage) {
  EXPECT_NEAR(v.at("voltage_output_raw") * kMpptVoltsPerCount, battery_voltage, 0.5);
  // Sent 50 ms apart: the pack's voltage may move by a count in between.
  EXPECT_NEAR(v.at("voltage_out_sw_raw"), v.at("voltage_output_raw"), 2);
  EXPECT_EQ(v.at("safety_enabled"), 1);
  double panel_power = 0;
  for (int p = 1; p <= 4; ++p) {
    const std::string n = std::to_string(p);
    const double volts = v.at("voltage_panel_" + n + "_raw") * kMpptVoltsPerCount;
    const double amps = v.at("current_panel_" + n + "_raw") * kMpptAmpsPerCount;
    EXPECT_GE(volts, 0);
    EXPECT_GE(amps, 0);
    panel_power += volts * amps;
    const double duty = v.at("duty_cycle_panel_" + n);
    EXPECT_GE(duty, 0);
    EXPECT_LE(duty, 100);
    EXPECT_EQ(v.at("channel_" + n + "_active"), amps > 0 ? 1 : 0);
    if (amps > 0) {
      EXPECT_NEAR(duty, 100 * (1 - volts / battery_voltage), 2) << "boost converter";
    }
  }
  const double out = v.at("voltage_output_raw") * kMpptVoltsPerCount * v.at("current_output_raw") * kMpptAmpsPerCount;
  EXPECT_NEAR(out, panel_power * kEfficiency, 0.02 * panel_power + 1);
}

TEST(SolarStory, SunChargesTheBattery) {
  SolarHarness h(world(5.0));
  h.plant->set_irradiance(1000.0, h.now);
  h.add(pack(0.5));
  h.add(mppt(0));
  h.add(mppt(1));
  h.run(1s);
  const auto first = latest(h.take());
  h.run(10min, 100ms);
  const auto msgs = h.take();
  const auto last = latest(msgs);

  EXPECT_GT(last.at("current"), 20.0) << "two MPPTs at 1000 W/m2 outrun a 5 A load";
  EXPECT_NEAR(last.at("current_discharge"), 5.0, 0.01);
  EXPECT_GT(last.at("state_of_charge"), first.at("state_of_charge") + 10);
  EXPECT_GT(last.at("voltage"), first.at("voltage"));
  EXPECT_EQ(last.at("time_to_go"), 65535) << "not discharging";
  EXPECT_TRUE(static_cast<std::uint32_t>(last.at("bms_state")) & bms_bit::Charging);
  expect_consistent(last, 12);

  std::map<std::uint8_t, std::vector<CanOpenMessage>> per_device;
  for (const auto& m : msgs)
    if (m.source == codec::canopen::Source::Mppt) per_device[m.device].push_back(m);
  ASSERT_EQ(per_device.size(), 2u);
  double mppt_amps = 0;
  for (const auto& [device, dm] : per_device) {
    SCOPED_TRACE(int{device});
    const auto v = latest(dm);
    EXPECT_EQ(v.at("mppt_state"), mppt_state::Tracking);
    EXPECT_EQ(v.at("pwm_enabled"), 1);
    EXPECT_GT(v.at("current_output_raw"), 0);
    EXPECT_GT(v.at("temperature"), 25) << "converting warms it";
    expect_consistent_mppt(v, last.at("voltage"));
    mppt_amps += v.at("current_output_raw") * kMpptAmpsPerCount;
  }
  EXPECT_NEAR(last.at("current_charge"), mppt_amps, 0.5) << "what the MPPTs put out is what charges the pack";
}

TEST(SolarStory, LoadWithoutSunDischargesTheBattery) {
  SolarHarness h(world(10.0));
  h.plant->set_irradiance(0.0, h.now);
  BatterySimConfig c = pack(0.9);
  c.capacity_ah = 20;
  h.add(c);
  h.add(mppt(3));
  h.run(1s);
  const auto first = latest(h.take());
  h.run(30min, 100ms);
  const auto msgs = h.take();
  const auto last = latest(msgs);
  EXPECT_NEAR(last.at("current"), -10.0, 0.01);
  EXPECT_EQ(last.at("current_charge"), 0);
  EXPECT_NEAR(last.at("current_discharge"), 10.0, 0.01);
  // 10 A for half an hour from 20 Ah is 25 % of the charge.
  EXPECT_NEAR(last.at("state_of_charge"), first.at("state_of_charge") - 25, 1.0);
  EXPECT_LT(last.at("voltage"), first.at("voltage"));
  // Time to go: the charge left at this current, in minutes.
  EXPECT_NEAR(last.at("time_to_go"), last.at("state_of_charge") / 100 * 20 / 10 * 60, 2);
  EXPECT_TRUE(static_cast<std::uint32_t>(last.at("bms_state")) & bms_bit::Discharging);
  expect_consistent(last, 12);

  std::vector<CanOpenMessage> mppt_msgs;
  for (const auto& m : msgs)
    if (m.source == codec::canopen::Source::Mppt) mppt_msgs.push_back(m);
  const auto v = latest(mppt_msgs);
  EXPECT_EQ(v.at("mppt_state"), mppt_state::Idle);
  EXPECT_EQ(v.at("pwm_enabled"), 0);
  EXPECT_EQ(v.at("current_output_raw"), 0);
  expect_consistent_mppt(v, last.at("voltage"));
}

TEST(SolarStory, AFullBatteryMakesTheMpptsLimit) {
  SolarHarness h(world(5.0));
  h.plant->set_irradiance(1000.0, h.now);
  h.add(pack(1.0));
  h.add(mppt(0));
  h.run(5min, 100ms);
  const auto msgs = h.take();
  const auto v = latest(msgs);
  EXPECT_EQ(v.at("state_of_charge"), 100);
  EXPECT_NEAR(v.at("current"), 0, 0.02) << "charge held to the load";
  EXPECT_TRUE(static_cast<std::uint32_t>(v.at("bms_state")) & bms_bit::Full);
  EXPECT_EQ(v.at("mppt_state"), mppt_state::Limiting);
  EXPECT_NEAR(v.at("current_output_raw") * kMpptAmpsPerCount, 5.0, 0.05);
  expect_consistent(v, 12);
}

TEST(SolarStory, AnEmptyBatteryDisconnectsTheLoad) {
  SolarHarness h(world(8.0));
  h.plant->set_irradiance(0.0, h.now);
  BatterySimConfig c = pack(0.01);
  c.capacity_ah = 1;  // 0.01 Ah at 8 A: empty within 5 s
  h.add(c);
  h.run(1min, 100ms);
  const auto v = latest(h.take());
  EXPECT_EQ(v.at("state_of_charge"), 0);
  EXPECT_EQ(v.at("current_discharge"), 0);
  EXPECT_TRUE(static_cast<std::uint32_t>(v.at("bms_state")) & bms_bit::Empty);
  expect_consistent(v, 12);
  // The sun comes back: charging resumes.
  h.add(mppt(0));
  h.plant->set_irradiance(800.0, h.now);
  h.run(30s, 100ms);
  EXPECT_GT(*h.plant->state_of_charge(2), 0.0);
}

TEST(SolarStory, ParallelBatteriesShareChargeAndLoad) {
  SolarHarness h(world(12.0));
  h.plant->set_irradiance(1000.0, h.now);
  BatterySimConfig a = pack(0.5), b = pack(0.5);
  b.node = 3;  // ids 0x203.. : decode() knows node 2 only, so read node 3 from the plant
  h.add(a);
  h.add(b);
  h.add(mppt(0));
  h.run(2s);
  const BatteryReading ra = h.plant->battery(2), rb = h.plant->battery(3);
  EXPECT_NEAR(ra.current_discharge, 6.0, 1e-9);
  EXPECT_NEAR(rb.current_discharge, 6.0, 1e-9);
  EXPECT_NEAR(ra.current_charge, rb.current_charge, 1e-9);
  EXPECT_NEAR(ra.current_charge * 2, h.plant->mppt(0).output_current, 1e-6) << "the one MPPT feeds both";
  std::vector<CanOpenMessage> node2;
  for (const auto& s : h.sent) {
    const auto m = codec::canopen::decode(s.frame);
    if (m) node2.push_back(*m);
  }
  h.sent.clear();
  EXPECT_NEAR(latest(node2).at("current_discharge"), 6.0, 0.01);
}

TEST(SolarStory, FixedCellVoltagesAreSentAsSetWhateverTheCurrent) {
  SolarHarness h;
  BatterySimConfig c;
  c.cells = 3;
  c.cell_voltages = {3.9, 4.25, 3.1};  // an unbalanced pack the charge curve cannot give
  h.add(c);
  h.add(MpptSimConfig{});
  h.plant->set_irradiance(1000.0, h.now);  // charging current flows through the cells
  h.run(2s);
  const auto v = latest(h.take());
  EXPECT_NEAR(v.at("cell_voltage_1"), 3.9, 0.0005);
  EXPECT_NEAR(v.at("cell_voltage_2"), 4.25, 0.0005);
  EXPECT_NEAR(v.at("cell_voltage_3"), 3.1, 0.0005);
  EXPECT_EQ(v.count("cell_voltage_4"), 0u);
  EXPECT_NEAR(v.at("cell_voltage_high"), 4.25, 0.0005);
  EXPECT_NEAR(v.at("cell_voltage_low"), 3.1, 0.0005);
  EXPECT_NEAR(v.at("voltage"), 3.9 + 4.25 + 3.1, 0.002) << "the pack is the sum of its cells";
  EXPECT_GT(v.at("current"), 0) << "the charge still flows; only the cell readings are fixed";
}

TEST(SolarStory, ByDefaultTheSunVariesSlowly) {
  SolarWorld w;
  w.irradiance_mean = 500;
  w.irradiance_swing = 400;
  w.irradiance_cycle = 600s;
  SolarHarness h(w);
  h.add(pack(0.5));
  h.add(mppt(0));
  h.run(150s, 100ms);  // a quarter cycle: the peak
  EXPECT_NEAR(h.plant->irradiance(), 900, 1);
  const double soc_at_peak = *h.plant->state_of_charge(2);
  h.take();
  h.run(300s, 100ms);  // the trough
  EXPECT_NEAR(h.plant->irradiance(), 100, 1);
  const auto v = latest(h.take());
  EXPECT_GT(*h.plant->state_of_charge(2), soc_at_peak) << "charged through the bright half";
  // At 100 W/m2 one MPPT's ~90 W no longer covers the 5 A load.
  EXPECT_LT(v.at("current"), 0);
  expect_consistent(v, 12);
  // A test can fix the sun, and give it back to the sine.
  h.plant->set_irradiance(0.0, h.now);
  EXPECT_EQ(h.plant->irradiance(), 0);
  h.plant->set_irradiance(std::nullopt, h.now);
  EXPECT_NEAR(h.plant->irradiance(), 100, 1);
}

TEST(SolarStory, ValuesStayInRangeThroughDaysOfSunAndLoad) {
  // Long cycles with a changing load, checking every frame (not only the last values).
  SolarWorld w;
  w.irradiance_cycle = 1200s;
  SolarHarness h(w);
  BatterySimConfig c = pack(0.3, 15);
  c.capacity_ah = 5;  // small, so it runs full and empty within the test
  h.add(c);
  h.add(mppt(0));
  h.add(mppt(5));
  const double loads[] = {0, 3, 20, 40, 5};
  for (double load : loads) {
    SCOPED_TRACE(load);
    h.plant->set_load(load, h.now);
    h.run(20min, 200ms);
    const auto msgs = h.take();
    for (const auto& m : msgs) {
      for (std::uint8_t i = 0; i < m.field_count; ++i) {
        const auto& f = m.fields[i];
        SCOPED_TRACE(std::string(f.name));
        EXPECT_TRUE(std::isfinite(f.value));
        if (f.unit == "%") {
          EXPECT_GE(f.value, 0);
          EXPECT_LE(f.value, 100);
        }
        if (f.name == "cell_voltage") {
          EXPECT_GE(f.value, 2.5);
          EXPECT_LE(f.value, 4.4);
        }
        if (f.name == "voltage") {
          EXPECT_LE(f.value, 15 * 4.4);
        }
        if (f.unit == "degC") {
          EXPECT_GE(f.value, 0);
          EXPECT_LE(f.value, 80);
        }
        if (f.name == "mppt_state") {
          EXPECT_LE(f.value, 2);
        }
      }
    }
    // Up to 8C on a small pack: its cells move tens of mV within a period.
    expect_consistent(latest(msgs), 15, 0.05);
  }
}

}  // namespace
}  // namespace pmu::sim::test
