// pmu/bms_energy as a ground station reads it (docs/interface.md 1.8, 3.2): pmu-service on the
// configured simulator with a BMS, pmuctl energy --json against the voltage, current and state
// of charge the same simulator's BMS publishes on pmu/battery (pmuctl watch --json),
// discharging into the load and charged by the sun through an MPPT.
#include <gtest/gtest.h>

#include <algorithm>
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
namespace bms_energy_pmuctl_test {
namespace {

using namespace std::chrono_literals;
using Json = nlohmann::json;

// Battery node 2 on a simulated bus, its capacity and critical state of charge configured
// (the table's bms_critical_soc is 7 %), its twelve cells held at 4.0 V so the pack's voltage
// stays put while the current flows. `extra`: more of the bus (an MPPT).
constexpr double kCapacityAh = 20;
constexpr double kCriticalSoc = 10;
std::string config(const std::string& domain, const std::string& extra) {
  return "domain: " + domain +
         "\nqos_file: " PMU_QOS_FILE
         "\nbuses:\n  - interface: sim\n    devices:\n      - address: 1\n"
         "    batteries:\n      - node: 2\n        capacity_ah: 20\n"
         "        alarms:\n          bms_critical_soc: {limit: 10}\n"
         "        sim:\n          state_of_charge: 80\n"
         "          cell_voltages: [4.0, 4.0, 4.0, 4.0, 4.0, 4.0, 4.0, 4.0, 4.0, 4.0, 4.0, 4.0]\n" +
         extra;
}

// The pmuctl energy --json line of battery 2, or null.
Json battery_line(const std::string& out) {
  for (const auto& l : pmu::test::json_lines(out))
    if (l.value("topic", "") == "bms_energy" && l.value("node", -1) == 2) return l;
  return Json();
}

struct Measured {
  Json energy;                       // the bms_energy line
  Json battery;                      // the latest pmu/battery values
  double soc_low = 0, soc_high = 0;  // % over the pmu/battery samples read around it
};

// Waits until the battery's integral covers at least `seconds`, reading pmu/battery before
// and after, so the state of charge the figures used is among those read.
Measured measure(const std::string& p, double seconds) {
  Measured m;
  m.soc_low = 1e9;
  m.soc_high = -1e9;
  auto watch = [&] {
    for (const auto& l :
         pmu::test::json_lines(pmu::test::run_capture(p + "--timeout 10 --json watch --count 12").out)) {
      if (l.value("topic", "") != "battery" || !l["values"]["state_of_charge"].is_number()) continue;
      m.battery = l["values"];
      m.soc_low = std::min(m.soc_low, m.battery["state_of_charge"].get<double>());
      m.soc_high = std::max(m.soc_high, m.battery["state_of_charge"].get<double>());
    }
  };
  watch();
  const auto deadline = std::chrono::steady_clock::now() + 40s;
  do {
    m.energy = battery_line(pmu::test::run_capture(p + "--timeout 5 --json energy").out);
    if (!m.energy.is_null() && m.energy["values"]["integrated_s"].get<double>() >= seconds) break;
    std::this_thread::sleep_for(500ms);
  } while (std::chrono::steady_clock::now() < deadline);
  watch();
  return m;
}

// Float32 on the wire: what the service multiplied, to float precision.
void expect_close(const Json& actual, double expected, double tolerance, const std::string& what) {
  ASSERT_TRUE(actual.is_number()) << what << ": " << actual.dump();
  EXPECT_NEAR(actual.get<double>(), expected, tolerance) << what;
}

// What every battery line carries: the key, the configured limits, and the used energy as the
// integral of a power the simulator holds steady over the seconds integrated.
void expect_common(const Measured& m) {
  EXPECT_EQ(m.energy["bus"], "sim");
  EXPECT_EQ(m.energy["vehicle"], "");
  EXPECT_FALSE(m.energy.contains("address"));
  const Json& e = m.energy["values"];
  expect_close(e["capacity_ah"], kCapacityAh, 0, "the configured capacity");
  expect_close(e["critical_state_of_charge"], kCriticalSoc, 0, "the configured bms_critical_soc limit");
  EXPECT_GE(e["integrated_s"].get<double>(), 3);
}

// A service with the bus's `extra` config (its MPPTs), the battery's figures measured over
// 3 s, and what every line carries checked; `check` gets pmuctl's command prefix, the
// figures, and the latest pmu/battery voltage and current.
template <class Check>
void with_figures(const std::string& extra, Check check) {
  const std::string domain = std::to_string(pmu::test::exclusive_dds_domain());
  pmu::test::ConfiguredService service(PMU_SERVICE_PATH, config(domain, extra));
  const std::string p = std::string(PMUCTL_PATH) + " --domain " + domain + " ";
  const auto m = measure(p, 3);
  ASSERT_FALSE(m.energy.is_null()) << service.describe();
  ASSERT_TRUE(m.battery.is_object()) << service.describe();
  expect_common(m);
  check(p, m, m.battery["voltage"].get<double>(), m.battery["current"].get<double>());
}

TEST(BmsEnergyOverDds, DischargingIntoTheLoad) {
  with_figures("", [](const std::string& p, const Measured& m, double volts, double amps) {
    const Json& e = m.energy["values"];
    ASSERT_LT(amps, 0) << "without sun the load discharges the battery";
    // No sun, a steady load and fixed cells: the simulator's power does not change.
    expect_close(e["power"], volts * amps, 1e-3 * std::abs(volts * amps), "power: V x I, negative out of the battery");
    expect_close(e["used_wh"], -volts * amps * e["integrated_s"].get<double>() / 3600, 1e-6, "used_wh");
    EXPECT_GT(e["used_wh"].get<double>(), 0) << "discharged";
    // (state of charge - critical) of the capacity at the steady current, with the state of
    // charge the BMS sent (whole percent; it may tick once while this runs).
    const auto endurance = [&](double soc) { return (soc - kCriticalSoc) / 100 * kCapacityAh * 3600 / -amps; };
    ASSERT_TRUE(e["endurance_s"].is_number()) << m.energy.dump();
    EXPECT_GE(e["endurance_s"].get<double>(), endurance(m.soc_low) - 1) << m.energy.dump();
    EXPECT_LE(e["endurance_s"].get<double>(), endurance(m.soc_high) + 1) << m.energy.dump();
    // The BMS's own time to go runs to empty, so it is longer, in the same proportion.
    if (m.battery["time_to_go"].is_number()) {
      EXPECT_GT(m.battery["time_to_go"].get<double>(), e["endurance_s"].get<double>());
    }

    const auto text = pmu::test::run_capture(p + "--timeout 5 energy");
    EXPECT_EQ(text.status, 0);
    EXPECT_NE(text.out.find("sim/battery2"), std::string::npos) << text.out;
    EXPECT_NE(text.out.find("to 10 % SoC, capacity 20.0 Ah"), std::string::npos) << text.out;
    // --address names a PMU: the battery is not shown.
    const auto pmu_only = pmu::test::run_capture(p + "--timeout 5 --json --address 1 energy");
    EXPECT_EQ(pmu_only.status, 0);
    EXPECT_TRUE(battery_line(pmu_only.out).is_null()) << pmu_only.out;
  });
}

TEST(BmsEnergyOverDds, ChargedByTheSunNoEndurance) {
  with_figures("    mppts:\n      - device: 0\n", [](const std::string&, const Measured& m, double volts, double amps) {
    const Json& e = m.energy["values"];
    ASSERT_GT(amps, 0) << "the MPPT's panels give more than the load takes";
    // The sun drifts slowly, so the power read a few seconds apart is close, not equal.
    expect_close(e["power"], volts * amps, 0.1 * volts * amps, "power: V x I, positive into the battery");
    EXPECT_LT(e["used_wh"].get<double>(), 0) << "charged: less used than none";
    EXPECT_TRUE(e["endurance_s"].is_null()) << "charging: no endurance";
  });
}

}  // namespace
}  // namespace bms_energy_pmuctl_test
