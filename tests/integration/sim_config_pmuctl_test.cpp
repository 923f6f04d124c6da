// pmu-service on a config whose `interface: sim` devices have `sim:` mappings
// (docs/interface.md section 4.4), read by pmuctl as a ground station would: what the
// service publishes shows the simulated world the config asked for. (Each key's effect in
// detail, without DDS: tests/service/app/simulated_bus_test.cpp.)
#include <gtest/gtest.h>

#include <chrono>
#include <string>
#include <thread>

#include "support/configured_service.hpp"
#include "support/domain.hpp"
#include "support/json_lines.hpp"
#include "support/process.hpp"

namespace {

using namespace std::chrono_literals;

TEST(SimConfigOverDds, StoppedEngineHotPmuAndSilentUnitAsConfigured) {
  const std::string domain = std::to_string(pmu::test::exclusive_dds_domain());
  pmu::test::ConfiguredService service(PMU_SERVICE_PATH,
                                       "domain: " + domain +
                                           "\nqos_file: " PMU_QOS_FILE
                                           "\nbuses:\n  - interface: sim\n    devices:\n"
                                           "      - address: 1\n        period: 0.5\n"
                                           "        sim: {engine: stopped, internal_temperature: 95}\n"
                                           "      - address: 2\n        period: 0.5\n"
                                           "        sim: {silent: true}\n");
  const std::string p = std::string(PMUCTL_PATH) + " --domain " + domain + " --json ";

  const auto watched = pmu::test::run_capture(p + "--timeout 30 --address 1 watch --count 10");
  ASSERT_EQ(watched.status, 0) << watched.out << service.describe();
  int status_lines = 0;
  for (const auto& j : pmu::test::json_lines(watched.out)) {
    if (j.is_discarded() || j.value("topic", "") != "status") continue;
    ++status_lines;
    EXPECT_EQ(j["values"]["generator_rpm"], 0) << "engine: stopped";
    EXPECT_EQ(j["values"]["thermal_shutdown"], true) << "95 degC above T_U 80";
  }
  EXPECT_GT(status_lines, 0) << watched.out;

  // The silent unit: UNKNOWN, then OFFLINE after offline_periods (10) x 0.5 s; never ONLINE.
  std::string state;
  for (int attempt = 0; attempt < 30 && state != "OFFLINE"; ++attempt) {
    const auto health = pmu::test::run_capture(p + "--timeout 10 --address 2 health");
    for (const auto& j : pmu::test::json_lines(health.out))
      if (!j.is_discarded() && j.contains("values")) state = j["values"].value("state", "");
    EXPECT_NE(state, "ONLINE") << health.out;
    if (state != "OFFLINE") std::this_thread::sleep_for(500ms);
  }
  EXPECT_EQ(state, "OFFLINE") << service.describe();
}

}  // namespace
