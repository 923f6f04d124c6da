// pmu/energy as a ground station reads it (docs/interface.md 1.8, 3.2): pmu-service on the
// configured simulator, pmuctl energy --json against the voltages and currents the same
// simulator publishes (pmuctl watch --json), with the generator running and stopped.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <string>
#include <thread>

#include "support/configured_service.hpp"
#include "support/domain.hpp"
#include "support/json_lines.hpp"
#include "support/process.hpp"

// A namespace of its own: the unity builds put this file in one translation unit with the
// other integration tests, whose helpers have the same names.
namespace energy_pmuctl_test {
namespace {

using namespace std::chrono_literals;
using Json = nlohmann::json;

// PMU 1 on a simulated bus, battery A's critical voltage changed from the table's so the
// figures must carry the configured one.
constexpr double kCriticalA = 20.5;
std::string config(const std::string& domain, const std::string& sim) {
  return "domain: " + domain +
         "\nqos_file: " PMU_QOS_FILE
         "\nbuses:\n  - interface: sim\n    devices:\n      - address: 1\n        period: 0.5\n"
         "        alarms:\n          battery_a_critical_voltage: {limit: 20.5}\n" +
         sim;
}

template <class Done>
pmu::test::RunResult until(const std::string& command, Done done, std::chrono::seconds within) {
  const auto deadline = std::chrono::steady_clock::now() + within;
  pmu::test::RunResult r = pmu::test::run_capture(command);
  while (!done(r) && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(500ms);
    r = pmu::test::run_capture(command);
  }
  return r;
}

// The latest "values" of `topic` among pmuctl watch --json lines.
Json values_of(const std::vector<Json>& lines, const std::string& topic) {
  Json v;
  for (const auto& l : lines)
    if (l.value("topic", "") == topic) v = l["values"];
  return v;
}

// Float32 on the wire: what the service multiplied, to float precision.
void expect_close(const Json& actual, double expected, const std::string& what) {
  ASSERT_TRUE(actual.is_number()) << what << ": " << actual.dump();
  EXPECT_NEAR(actual.get<double>(), expected, 1e-4 * std::max(1.0, std::abs(expected))) << what;
}

struct Measured {
  Json volts, amps, energy;
};

// Waits until the energy's integral covers at least `seconds`, then reads the simulator's
// voltages and currents and the energy figures.
Measured measure(const std::string& p, double seconds) {
  const auto energy = until(
      p + "--timeout 5 --json energy",
      [&](const auto& r) {
        const auto lines = pmu::test::json_lines(r.out);
        return r.status == 0 && lines.size() == 1 &&
               lines[0]["values"]["battery_a"]["integrated_s"].template get<double>() >= seconds;
      },
      40s);
  const auto watch = pmu::test::run_capture(p + "--timeout 10 --json watch --count 15");
  const auto lines = pmu::test::json_lines(watch.out);
  const auto e = pmu::test::json_lines(energy.out);
  return {values_of(lines, "voltages"), values_of(lines, "currents"), e.empty() ? Json() : e[0]};
}

// Every figure that is V x I, and the balance, from the simulator's own values.
void expect_powers(const Measured& m) {
  const Json& e = m.energy["values"];
  double outputs = 0;
  for (const std::string rail : {"avionics", "output_28v", "payload", "servo"}) {
    const double w = m.volts[rail].get<double>() * m.amps[rail].get<double>();
    expect_close(e[rail + "_power"], w, rail);
    outputs += w;
  }
  const double a = m.volts["battery_a"].get<double>() * m.amps["battery_a"].get<double>();
  const double b = m.volts["battery_b"].get<double>() * m.amps["battery_b"].get<double>();
  expect_close(e["battery_a"]["power"], a, "battery A");
  expect_close(e["battery_b"]["power"], b, "battery B");
  expect_close(e["generator_power"], outputs + a + b, "generator: the balance");
  // The simulator's battery power is constant: the integral is that power times its time,
  // out of the battery (the opposite sign of the power into it).
  for (const char* battery : {"battery_a", "battery_b"}) {
    const double into = e[battery]["power"].get<double>();
    const double s = e[battery]["integrated_s"].get<double>();
    expect_close(e[battery]["used_wh"], -into * s / 3600, std::string(battery) + " used_wh");
  }
  expect_close(e["battery_a"]["critical_voltage"], kCriticalA, "battery A's configured critical voltage");
}

TEST(EnergyOverDds, GeneratorRunningChargesTheBatteries) {
  const std::string domain = std::to_string(pmu::test::exclusive_dds_domain());
  pmu::test::ConfiguredService service(PMU_SERVICE_PATH, config(domain, "        sim: {engine: running}\n"));
  const std::string p = std::string(PMUCTL_PATH) + " --domain " + domain + " ";
  const auto m = measure(p, 3);
  ASSERT_FALSE(m.energy.is_null()) << service.describe();
  ASSERT_TRUE(m.volts.is_object() && m.amps.is_object()) << service.describe();
  EXPECT_EQ(m.energy["topic"], "energy");
  EXPECT_EQ(m.energy["bus"], "sim");
  EXPECT_EQ(m.energy["address"], 1);
  ASSERT_GT(m.amps["battery_a"].get<double>(), 0) << "the simulator charges while generating";
  expect_powers(m);
  EXPECT_GT(m.energy["values"]["generator_power"].get<double>(), 0);
  EXPECT_LT(m.energy["values"]["battery_a"]["used_wh"].get<double>(), 0) << "charged: less used than none";
  EXPECT_TRUE(m.energy["values"]["battery_a"]["endurance_s"].is_null()) << "charging: no endurance";
  EXPECT_TRUE(m.energy["values"]["battery_b"]["endurance_s"].is_null());
}

TEST(EnergyOverDds, GeneratorStoppedTheBatteriesFeedTheOutputs) {
  const std::string domain = std::to_string(pmu::test::exclusive_dds_domain());
  pmu::test::ConfiguredService service(PMU_SERVICE_PATH, config(domain, "        sim: {engine: stopped}\n"));
  const std::string p = std::string(PMUCTL_PATH) + " --domain " + domain + " ";
  const auto m = measure(p, 3);
  ASSERT_FALSE(m.energy.is_null()) << service.describe();
  ASSERT_TRUE(m.volts.is_object() && m.amps.is_object()) << service.describe();
  ASSERT_LT(m.amps["battery_a"].get<double>(), 0) << "the simulator discharges without the generator";
  expect_powers(m);
  EXPECT_GT(m.energy["values"]["battery_a"]["used_wh"].get<double>(), 0) << "discharged";
  // The simulator's battery voltage does not fall: there is no trend to extrapolate.
  EXPECT_TRUE(m.energy["values"]["battery_a"]["endurance_s"].is_null());
  const auto text = pmu::test::run_capture(p + "--timeout 5 energy");
  EXPECT_EQ(text.status, 0);
  EXPECT_NE(text.out.find("sim/1"), std::string::npos) << text.out;
  EXPECT_NE(text.out.find("to 20.5 V"), std::string::npos) << text.out;
}

}  // namespace
}  // namespace energy_pmuctl_test
