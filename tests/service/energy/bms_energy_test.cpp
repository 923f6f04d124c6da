// A BMS-reported battery's derived energy (pmu::energy::BmsEnergy, interface.md 1.8,
// pmu/bms_energy) on synthetic receive times: the power's sign, the integral and its gaps,
// the filtered discharge current, and the endurance to the critical state of charge with and
// without a capacity, charging and with the state of charge unknown.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "pmu/energy/bms_energy.hpp"
#include "pmu/energy/mean_current.hpp"
#include "energy_times.hpp"

namespace pmu::energy {
// A namespace of its own: the unity builds put this file in one translation unit with the
// PMU's energy tests, whose helpers have the same names.
namespace bms_energy_test {
namespace {

using namespace std::chrono_literals;
using namespace test_times;

// One pmu/battery sample: receive time (s from t0), volts, amps (+ into the battery), SoC %.
struct Sample {
  double t, volts, amps, soc;
};

// `count` samples a second apart from `from` s, all alike.
std::vector<Sample> steady(double from, int count, double volts, double amps, double soc) {
  std::vector<Sample> s;
  for (int i = 0; i < count; ++i) s.push_back({from + i, volts, amps, soc});
  return s;
}
std::vector<Sample> operator+(std::vector<Sample> a, const std::vector<Sample>& b) {
  a.insert(a.end(), b.begin(), b.end());
  return a;
}

// The gap bound of a BMS with a 1 s period and 3 stale periods.
constexpr std::chrono::seconds kGap{3};

BmsFigures run(const BmsSettings& settings, const std::vector<Sample>& samples) {
  BmsEnergy e(settings, kGap);
  for (const auto& s : samples) e.on_sample(at(s.t), {s.volts, s.amps, s.soc});
  return e.figures(at(samples.back().t));
}

void expect_same(double expected, double actual, const char* what, double tolerance = 1e-9) {
  if (std::isnan(expected))
    EXPECT_TRUE(std::isnan(actual)) << what << ": " << actual;
  else
    EXPECT_NEAR(actual, expected, tolerance) << what;
}

const BmsSettings k20Ah{20, 7};  // 20 Ah, critical at 7 %: the table's bms_critical_soc

TEST(BmsEnergyPower, VoltsTimesAmpsWithTheBmsCurrentsSign) {
  struct Row {
    const char* what;
    double volts, amps, watts;  // W by hand
  };
  const Row rows[] = {
      {"charging: positive, into the battery", 48, 2.5, 120},
      {"discharging: negative, out of it", 48, -5, -240},
      {"idle", 48.5, 0, 0},
      {"voltage not received", kNaN, -5, kNaN},
      {"current not received", 48, kNaN, kNaN},
  };
  for (const auto& r : rows) {
    SCOPED_TRACE(r.what);
    expect_same(r.watts, run(k20Ah, {{0, r.volts, r.amps, 80}}).power, "power");
  }
}

TEST(BmsEnergyPower, ValuesOlderThanTheGapAreNoLongerUsed) {
  BmsEnergy e(k20Ah, kGap);
  e.on_sample(at(0), {48, -5, 80});
  EXPECT_DOUBLE_EQ(e.figures(at(3)).power, -240);
  EXPECT_TRUE(std::isnan(e.figures(at(3.5)).power)) << "3.5 s old, gap 3 s";
  EXPECT_TRUE(std::isnan(e.figures(at(3.5)).endurance_s));
}

TEST(BmsEnergyUsed, TrapezoidsOutOfTheBatteryAndNothingAcrossAGap) {
  struct Row {
    const char* what;
    std::vector<Sample> samples;
    double joules, seconds;  // out of the battery, by hand
  };
  const Row rows[] = {
      {"one sample integrates nothing", {{0, 48, -5, 80}}, 0, 0},
      // 240 W out for 10 s
      {"a steady discharge", steady(0, 11, 48, -5, 80), 2400, 10},
      {"a charge counts down", steady(0, 5, 50, 2, 80), -400, 4},
      // 0.2 s x 240 W, then 0.8 s x (240 + 480) / 2, then 1 s x 480 W
      {"irregular intervals and a load step",
       {{0, 48, -5, 80}, {0.2, 48, -5, 80}, {1.0, 48, -10, 80}, {2.0, 48, -10, 80}},
       48 + 288 + 480,
       2},
      // 2 s x 240 W, then 5 s > 3 s left out, then 1 s x 240 W
      {"a gap longer than the STALE time", {{0, 48, -5, 80}, {2, 48, -5, 80}, {7, 48, -5, 80}, {8, 48, -5, 80}}, 720, 3},
      // The current unknown at 1: neither 0..1 nor 1..2 is known
      {"an unknown current", {{0, 48, -5, 80}, {1, 48, kNaN, 80}, {2, 48, -5, 80}, {3, 48, -5, 80}}, 240, 1},
  };
  for (const auto& r : rows) {
    SCOPED_TRACE(r.what);
    const auto f = run(k20Ah, r.samples);
    EXPECT_NEAR(f.used_wh, r.joules / 3600, 1e-12);
    EXPECT_NEAR(f.integrated_s, r.seconds, 1e-9);
  }
}

TEST(MeanCurrentTest, TimeWeightedOverTheWindowRestartedByAGap) {
  struct Step {
    double t, amps;
  };
  struct Row {
    const char* what;
    std::vector<Step> steps;
    double mean;  // A, by hand
  };
  std::vector<Step> half_and_half, before_window, across_gap;
  for (int i = 0; i <= 300; ++i) half_and_half.push_back({static_cast<double>(i), i < 150 ? -2.0 : -6.0});
  for (int i = 0; i <= 600; ++i) before_window.push_back({static_cast<double>(i), i < 300 ? -10.0 : -2.0});
  for (int i = 0; i <= 100; ++i) across_gap.push_back({static_cast<double>(i), -10});
  for (int i = 200; i <= 250; ++i) across_gap.push_back({static_cast<double>(i), -2});
  const Row rows[] = {
      {"one sample is its own mean", {{0, -3}}, -3},
      // 1 s at -2, 2 s at (-2 - 6) / 2: -10 A s over 3 s
      {"irregular intervals weigh by time", {{0, -2}, {1, -2}, {3, -6}}, -10.0 / 3},
      // 149 s at -2, the step's second at -4, 150 s at -6: (-298 - 4 - 900) / 300
      {"a load step is kept in the mean", half_and_half, -1202.0 / 300},
      {"what left the window is gone", before_window, -2},
      {"a gap starts the window again", across_gap, -2},
      {"an unknown current starts it again", {{0, -10}, {1, -10}, {2, kNaN}, {3, -4}, {4, -4}}, -4},
      {"a clock stepped back starts it again", {{10, -10}, {11, -10}, {5, -4}, {6, -4}}, -4},
  };
  for (const auto& r : rows) {
    SCOPED_TRACE(r.what);
    MeanCurrent m(kGap);
    for (const auto& s : r.steps) m.add(at(s.t), s.amps);
    EXPECT_NEAR(m.mean(), r.mean, 1e-9);
  }
  EXPECT_TRUE(std::isnan(MeanCurrent(kGap).mean())) << "nothing yet";
}

TEST(BmsEnergyEndurance, StateOfChargeAboveTheCriticalOverTheFilteredDischarge) {
  struct Row {
    const char* what;
    BmsSettings settings;
    std::vector<Sample> samples;
    double endurance_s;  // by hand
  };
  const Row rows[] = {
      // (80 - 7) % of 20 Ah = 14.6 Ah at 5 A: 2.92 h
      {"a steady discharge", k20Ah, steady(0, 61, 48, -5, 80), 14.6 / 5 * 3600},
      {"the configured critical state of charge", {20, 20}, steady(0, 61, 48, -5, 80), 12.0 / 5 * 3600},
      // The mean of 150 s at -2 A and 150 s at -6 A (as in MeanCurrentTest)
      {"the filtered current, not the latest", k20Ah, steady(0, 150, 48, -2, 80) + steady(150, 151, 48, -6, 80),
       14.6 / (1202.0 / 300) * 3600},
      {"the latest state of charge", k20Ah, steady(0, 30, 48, -5, 80) + steady(30, 31, 48, -5, 79), 14.4 / 5 * 3600},
      {"at the critical state of charge: 0", k20Ah, steady(0, 10, 48, -5, 7), 0},
      {"below it: 0", k20Ah, steady(0, 10, 48, -5, 3), 0},
      {"capacity not configured", {kNaN, 7}, steady(0, 61, 48, -5, 80), kNaN},
      {"charging", k20Ah, steady(0, 61, 50, 3, 80), kNaN},
      {"idle: a BMS's own draw", k20Ah, steady(0, 61, 48, -0.05, 80), kNaN},
      {"charging on average, though discharging now", k20Ah, steady(0, 200, 50, 3, 80) + steady(200, 101, 48, -1, 80),
       kNaN},
      {"state of charge not received", k20Ah, steady(0, 61, 48, -5, kNaN), kNaN},
      {"current not received", k20Ah, steady(0, 61, 48, kNaN, 80), kNaN},
  };
  for (const auto& r : rows) {
    SCOPED_TRACE(r.what);
    const auto f = run(r.settings, r.samples);
    expect_same(r.endurance_s, f.endurance_s, "endurance", 1e-6);
    expect_same(r.settings.capacity_ah, f.capacity_ah, "capacity");
    expect_same(r.settings.critical_state_of_charge, f.critical_state_of_charge, "critical state of charge");
  }
}

TEST(BmsEnergyReport, FirstWithVoltageAndCurrentThenOnceASecond) {
  BmsEnergy e(k20Ah, kGap);
  e.on_sample(at(0), {kNaN, kNaN, 80});
  EXPECT_FALSE(e.report(at(0))) << "nothing to report before voltage and current";
  e.on_sample(at(0.2), {48, kNaN, 80});
  EXPECT_FALSE(e.report(at(0.2)));
  e.on_sample(at(0.4), {48, -5, 80});
  ASSERT_TRUE(e.report(at(0.4)));
  for (double t : {0.6, 0.8, 1.2}) {
    e.on_sample(at(t), {48, -5, 80});
    EXPECT_FALSE(e.report(at(t))) << t;
  }
  e.on_sample(at(1.4), {48, -5, 80});
  const auto f = e.report(at(1.4));
  ASSERT_TRUE(f) << "a second after the first";
  EXPECT_NEAR(f->used_wh, 240 * 1.0 / 3600, 1e-12) << "0.4 .. 1.4 s at 240 W out";
  // The values forgotten after OFFLINE: reported on, with what is not known as NaN.
  e.on_sample(at(2.4), {kNaN, kNaN, kNaN});
  const auto g = e.report(at(2.4));
  ASSERT_TRUE(g);
  EXPECT_TRUE(std::isnan(g->power));
  EXPECT_TRUE(std::isnan(g->endurance_s));
  EXPECT_NEAR(g->used_wh, f->used_wh, 1e-12);
}

}  // namespace
}  // namespace bms_energy_test
}  // namespace pmu::energy
