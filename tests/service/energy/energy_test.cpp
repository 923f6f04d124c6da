// The derived energy (pmu::energy, interface.md 1.8) on synthetic receive times: power per
// rail and its NaN, the generator's balance, the integral over irregular intervals and its
// gaps, the sign of charge and discharge, and the endurance against the critical voltage.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "pmu/energy/endurance.hpp"
#include "pmu/energy/energy_integral.hpp"
#include "pmu/energy/pmu_energy.hpp"
#include "energy_times.hpp"

namespace pmu::energy {
namespace {

using namespace std::chrono_literals;
using namespace test_times;

codec::Voltages volts(double avionics, double v28, double payload, double servo, double a, double b) {
  codec::Voltages v;
  v.avionics = avionics;
  v.output_28v = v28;
  v.payload = payload;
  v.servo = servo;
  v.battery_a = a;
  v.battery_b = b;
  v.generator = 48;
  return v;
}
codec::Currents amps(double avionics, double v28, double payload, double servo, double a, double b) {
  return {avionics, v28, payload, servo, a, b};
}

void expect_same(double expected, double actual, const char* what) {
  if (std::isnan(expected))
    EXPECT_TRUE(std::isnan(actual)) << what << ": " << actual;
  else
    EXPECT_NEAR(actual, expected, 1e-9) << what;
}

TEST(EnergyPower, EachRailIsVoltsTimesAmpsAndNaNPropagates) {
  struct Row {
    const char* what;
    codec::Voltages v;
    codec::Currents c;
    double avionics, output_28v, payload, servo, battery_a, battery_b, generator;  // W, by hand
  };
  const Row rows[] = {
      // Generator off: the outputs take 12 + 33 + 24 + 3 = 72 W, the batteries give 66 W
      // (negative: out of them); the 6 W left is what the balance cannot place.
      {"batteries feed the outputs", volts(12, 22, 12, 6, 22, 22), amps(1, 1.5, 2, 0.5, -1.5, -1.5), 12, 33, 24, 3, -33,
       -33, 6},
      {"generator charges both", volts(12, 28, 12, 6, 24, 23), amps(1, 1, 2, 0.5, 2, 1), 12, 28, 24, 3, 48, 23, 138},
      {"28 V current negative: fed from outside", volts(12, 28, 0, 6, 24, 24), amps(1, -2, 0, 0.5, 0, 0), 12, -56, 0, 3,
       0, 0, -41},
      {"an unknown voltage makes its rail and the balance unknown", volts(kNaN, 28, 12, 6, 24, 24),
       amps(1, 1, 2, 0.5, 0, 0), kNaN, 28, 24, 3, 0, 0, kNaN},
      {"an unknown battery current", volts(12, 28, 12, 6, 24, 24), amps(1, 1, 2, 0.5, kNaN, 0), 12, 28, 24, 3, kNaN, 0,
       kNaN},
  };
  for (const auto& r : rows) {
    SCOPED_TRACE(r.what);
    PmuEnergy e({19.8, 19.8}, 3s);
    e.on_voltages(at(0), r.v);
    e.on_currents(at(0.1), r.c);
    const auto f = e.figures(at(0.1));
    expect_same(r.avionics, f.avionics_power, "avionics");
    expect_same(r.output_28v, f.output_28v_power, "28 V");
    expect_same(r.payload, f.payload_power, "payload");
    expect_same(r.servo, f.servo_power, "servo");
    expect_same(r.battery_a, f.battery_a.power, "battery A");
    expect_same(r.battery_b, f.battery_b.power, "battery B");
    expect_same(r.generator, f.generator_power, "generator");
  }
}

TEST(EnergyPower, AValueOlderThanTheGapIsNoLongerUsed) {
  PmuEnergy e({19.8, 19.8}, 3s);
  e.on_voltages(at(0), volts(12, 28, 12, 6, 24, 24));
  e.on_currents(at(0), amps(1, 1, 2, 0.5, 0, 0));
  EXPECT_DOUBLE_EQ(e.figures(at(3)).avionics_power, 12);
  e.on_currents(at(3.5), amps(1, 1, 2, 0.5, 0, 0));
  EXPECT_TRUE(std::isnan(e.figures(at(3.5)).avionics_power)) << "voltages 3.5 s old, gap 3 s";
  EXPECT_TRUE(std::isnan(e.figures(at(3.5)).generator_power));
}

TEST(EnergyIntegralTest, TrapezoidsOverIrregularIntervalsAndNothingAcrossAGap) {
  struct Step {
    double t, watts;
  };
  struct Row {
    const char* what;
    std::vector<Step> steps;
    double joules, seconds;  // by hand
  };
  const Row rows[] = {
      {"one sample integrates nothing", {{0, 10}}, 0, 0},
      // 0.5 x 10 + 1.5 x (10 + 20) / 2 + 0.3 x 20
      {"irregular intervals", {{0, 10}, {0.5, 10}, {2.0, 20}, {2.3, 20}}, 33.5, 2.3},
      // 2 x 10, then 6 s > 5 s left out, then 1 x (10 + 30) / 2
      {"a gap longer than the bound", {{0, 10}, {2, 10}, {8, 10}, {9, 30}}, 40, 3},
      {"exactly the bound is integrated", {{0, 10}, {5, 10}}, 50, 5},
      // NaN at 1: neither 0..1 nor 1..2 is known; 2..3 is
      {"an unknown power", {{0, 10}, {1, kNaN}, {2, 10}, {3, 10}}, 10, 1},
      {"a second sample at the same time adds nothing", {{0, 10}, {1, 10}, {1, 1000}, {2, 10}}, 20, 2},
      // 0..1, then the clock steps back to 0.5: 0.5..1.5 again, not -0.5 s nor a stop
      {"a clock stepped back starts again", {{0, 10}, {1, 10}, {0.5, 10}, {1.5, 10}}, 20, 2},
      {"negative power integrates negative", {{0, -36}, {4, -36}, {5, -36}}, -180, 5},
  };
  for (const auto& r : rows) {
    SCOPED_TRACE(r.what);
    EnergyIntegral e(5s);
    for (const auto& s : r.steps) e.add(at(s.t), s.watts);
    EXPECT_NEAR(e.joules(), r.joules, 1e-9);
    EXPECT_NEAR(e.watt_hours(), r.joules / 3600, 1e-12);
    EXPECT_NEAR(e.integrated_s(), r.seconds, 1e-9);
  }
}

TEST(EnergyUsed, DischargeCountsUpAndChargeCountsDown) {
  struct Row {
    const char* what;
    double battery_amps;  // table 3's sign: positive into the battery
    double used_wh;       // over 36 s at 20 V, by hand
  };
  const Row rows[] = {
      {"discharging 5 A: 100 W out for 36 s", -5, 1.0},
      {"charging 2 A: 40 W in for 36 s", 2, -0.4},
      {"idle", 0, 0},
  };
  for (const auto& r : rows) {
    SCOPED_TRACE(r.what);
    PmuEnergy e({19.8, 19.8}, 3s);
    // Currents every 0.5 s, voltages every 2 s and out of step with them: the latest is used.
    for (int i = 0; i <= 72; ++i) {
      if (i % 4 == 0) e.on_voltages(at(i * 0.5 - 0.1), volts(12, 28, 12, 6, 20, 20));
      e.on_currents(at(i * 0.5), amps(0, 0, 0, 0, r.battery_amps, 0));
    }
    const auto f = e.figures(at(36));
    EXPECT_NEAR(f.battery_a.used_wh, r.used_wh, 1e-9);
    EXPECT_NEAR(f.battery_a.integrated_s, 36, 1e-9);
    EXPECT_NEAR(f.battery_b.used_wh, 0, 1e-12);
  }
}

// Battery A at 5 A out, its voltage falling 1 mV/s from 22.0 V: one currents sample a second
// with the voltage of that moment.
PmuEnergy falling(double critical, double battery_amps, double seconds) {
  PmuEnergy e({critical, 19.8}, 3s);
  for (int i = 0; i <= static_cast<int>(seconds); ++i) {
    e.on_voltages(at(i), volts(12, 28, 12, 6, 22.0 - 0.001 * i, 22));
    e.on_currents(at(i), amps(0, 0, 0, 0, battery_amps, 0));
  }
  return e;
}

TEST(Endurance, ReachesTheCriticalVoltageAtTheTrend) {
  struct Row {
    const char* what;
    double critical, amps, seconds;
    double endurance;  // by hand: (22.0 - 0.001 x seconds - critical) / 0.001
  };
  const Row rows[] = {
      {"critical 19.8 V after 120 s", 19.8, -5, 120, 2080},
      {"the configured 20.5 V", 20.5, -5, 120, 1380},
      {"window full (300 s)", 19.8, -5, 400, 1800},
      {"already below critical", 22.5, -5, 120, 0},
      {"charging", 19.8, 2, 120, kNaN},
      {"no current: idle", 19.8, 0, 120, kNaN},
      {"less than a minute of trend", 19.8, -5, 50, kNaN},
      {"no critical voltage", kNaN, -5, 120, kNaN},
  };
  for (const auto& r : rows) {
    SCOPED_TRACE(r.what);
    const auto f = falling(r.critical, r.amps, r.seconds).figures(at(r.seconds));
    if (std::isnan(r.endurance))
      EXPECT_TRUE(std::isnan(f.battery_a.endurance_s)) << f.battery_a.endurance_s;
    else
      EXPECT_NEAR(f.battery_a.endurance_s, r.endurance, 1e-6);
    expect_same(r.critical, f.battery_a.critical_voltage, "critical voltage reported");
    EXPECT_TRUE(std::isnan(f.battery_b.endurance_s)) << "battery B idle at a flat 22 V";
  }
}

TEST(Endurance, AFallTooSmallToTellCannotBeExtrapolated) {
  struct Row {
    const char* what;
    double volts_per_s;
    bool estimated;
  };
  const Row rows[] = {
      {"flat", 0, false},
      {"rising", 0.001, false},
      {"0.036 V over 120 s: less than kMinFall", -0.0003, false},
      {"0.06 V over 120 s", -0.0005, true},
  };
  for (const auto& r : rows) {
    SCOPED_TRACE(r.what);
    VoltageTrendEndurance e(3s);
    for (int i = 0; i <= 120; ++i) e.add(at(i), 22.2 + r.volts_per_s * i, -3);
    const double s = e.seconds_to(19.8);
    EXPECT_EQ(!std::isnan(s), r.estimated) << s;
    // (22.2 - 0.06 - 19.8) / 0.0005
    if (r.estimated) {
      EXPECT_NEAR(s, 4680, 1e-6);
    }
  }
}

TEST(Endurance, ALoadStepOrAGapStartsTheTrendAgain) {
  VoltageTrendEndurance step(3s), gap(3s);
  for (int i = 0; i <= 120; ++i) {
    step.add(at(i), 22.0 - 0.001 * i, -5);
    gap.add(at(i), 22.0 - 0.001 * i, -5);
  }
  ASSERT_NEAR(step.seconds_to(19.8), 2080, 1e-6);
  // The step's IR drop of 0.5 V would read as a steep fall; the window restarts instead.
  for (int i = 121; i <= 150; ++i) step.add(at(i), 21.5 - 0.001 * i, -10);
  EXPECT_TRUE(std::isnan(step.seconds_to(19.8))) << "30 s since the step: less than a minute of trend";
  for (int i = 151; i <= 190; ++i) step.add(at(i), 21.5 - 0.001 * i, -10);
  // (21.5 - 0.190 - 19.8) / 0.001
  EXPECT_NEAR(step.seconds_to(19.8), 1510, 1e-6);
  for (int i = 125; i <= 150; ++i) gap.add(at(i), 22.0 - 0.001 * i, -5);
  EXPECT_TRUE(std::isnan(gap.seconds_to(19.8))) << "4 s without a sample, gap 3 s";
}

TEST(EnergyReport, AtMostOncePerSecondOfReceiveTime) {
  PmuEnergy e({19.8, 19.8}, 3s);
  std::vector<long> reported;                // ms
  for (long ms = 0; ms < 3500; ms += 100) {  // 10 Hz for 3.5 s, currents first
    e.on_currents(t0 + std::chrono::milliseconds(ms), amps(1, 1, 2, 0.5, -1, -1));
    if (e.report(t0 + std::chrono::milliseconds(ms))) reported.push_back(ms);
    e.on_voltages(t0 + std::chrono::milliseconds(ms + 10), volts(12, 28, 12, 6, 22, 22));
    if (e.report(t0 + std::chrono::milliseconds(ms + 10))) reported.push_back(ms + 10);
  }
  // The first as soon as both are known, then each time a second has passed.
  EXPECT_EQ(reported, (std::vector<long>{10, 1010, 2010, 3010}));
}

}  // namespace
}  // namespace pmu::energy
