// pmuctl, a separate process, reading batteries and MPPTs that the service (in this process,
// fake clock, frames from the document's tables: canopen_bus.hpp) publishes (interface.md 1.4).
#include <gtest/gtest.h>

#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <string>

#include "canopen_bus.hpp"
#include "pmu/dds/dds_context.hpp"
#include "pmu/endpoints/dds_publisher.hpp"
#include "support/domain.hpp"
#include "support/json_lines.hpp"
#include "support/process.hpp"

namespace pmu::service::test {
namespace {

using pmu::test::run_capture;

// pmuctl (another process) reads what the in-process service publishes: watch --json has one
// line per battery, cells and MPPT sample with the contract's field names, null for what was
// never received; list and health show each device with its kind.
TEST(DdsCanOpen, PmuctlWatchListAndHealthShowBatteriesAndMppts) {
  const int domain = pmu::test::exclusive_dds_domain();
  dds::DdsContext service_side(domain, "", "pmu-service-canopen-pmuctl");
  DdsPublisher publisher(service_side, 3s);
  Harness h(bus_with_battery_and_mppt(), {pmu(1)}, Timeouts{}, &publisher);
  BusThread bus(h, document_frames());
  const std::string pmuctl = std::string(PMUCTL_PATH) + " --domain " + std::to_string(domain);

  const auto watched = run_capture(pmuctl + " --json --timeout 20 watch --count 12");
  ASSERT_EQ(watched.status, 0) << watched.out;
  std::map<std::string, nlohmann::json> last;  // topic -> latest line
  for (const auto& j : pmu::test::json_lines(watched.out)) {
    ASSERT_FALSE(j.is_discarded()) << watched.out;
    last[j["topic"].get<std::string>()] = j;
  }
  ASSERT_TRUE(last.count("battery")) << watched.out;
  ASSERT_TRUE(last.count("battery_cells")) << watched.out;
  ASSERT_TRUE(last.count("mppt")) << watched.out;
  const auto& b = last["battery"];
  EXPECT_EQ(b["bus"], "sim0");
  EXPECT_EQ(b["node"], 2);
  EXPECT_FALSE(b.contains("address"));
  EXPECT_GE(b["time"].get<double>(), 1700000000.0);
  EXPECT_TRUE(b["values"]["current"].is_null()) << "never received";
  EXPECT_TRUE(b["values"].contains("time_to_go"));
  if (!b["values"]["voltage"].is_null()) {
    EXPECT_DOUBLE_EQ(b["values"]["voltage"].get<double>(), 48.123);
  }
  if (!b["values"]["bms_state"].is_null()) {
    EXPECT_EQ(b["values"]["bms_state"], 0x12345678);
  }
  const auto& c = last["battery_cells"];
  ASSERT_EQ(c["values"]["cells"].size(), 1u) << c;
  EXPECT_EQ(c["values"]["cells"][0]["cell"], 5);
  EXPECT_DOUBLE_EQ(c["values"]["cells"][0]["cell_voltage"].get<double>(), 3.301);
  const auto& m = last["mppt"];
  EXPECT_EQ(m["device"], 4);
  EXPECT_TRUE(m["values"]["pwm_enabled"].is_null()) << "a flag never received is null, not false";
  EXPECT_TRUE(m["values"]["current_output_raw"].is_null());
  if (!m["values"]["safety_enabled"].is_null()) {
    EXPECT_EQ(m["values"]["safety_enabled"], true);
  }

  const auto listed = run_capture(pmuctl + " --json --timeout 20 list");
  ASSERT_EQ(listed.status, 0) << listed.out;
  std::set<std::string> devices;
  for (const auto& j : pmu::test::json_lines(listed.out)) {
    ASSERT_FALSE(j.is_discarded()) << listed.out;
    const std::string kind = j["kind"];
    const char* number = kind == "battery" ? "node" : kind == "mppt" ? "device" : "address";
    ASSERT_TRUE(j.contains(number)) << j;
    devices.insert(kind + std::to_string(j[number].get<int>()));
    if (kind != "pmu") {
      EXPECT_TRUE(j["values"]["serial_number"].is_null());
    }
  }
  EXPECT_EQ(devices, (std::set<std::string>{"pmu1", "battery2", "mppt4"})) << listed.out;

  const auto table = run_capture(pmuctl + " --timeout 20 list");
  ASSERT_EQ(table.status, 0) << table.out;
  EXPECT_NE(table.out.find("battery2"), std::string::npos) << table.out;
  EXPECT_NE(table.out.find("mppt4"), std::string::npos) << table.out;

  // --address names a PMU: the battery and MPPT drop out.
  const auto one = run_capture(pmuctl + " --json --timeout 20 --address 1 health");
  ASSERT_EQ(one.status, 0) << one.out;
  for (const auto& j : pmu::test::json_lines(one.out)) EXPECT_EQ(j["kind"], "pmu") << j;
}

}  // namespace
}  // namespace pmu::service::test
