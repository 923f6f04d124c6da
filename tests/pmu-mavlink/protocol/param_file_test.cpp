// A ground station's parameter file against `pmuctl config snapshot`: the values a file
// saves are the snapshot's wire values, and loading it back changes nothing.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>

#include "pmu/baseline/config_file.hpp"
#include "pmu/mavlink_params/confirm_set.hpp"
#include "pmu/mavlink_params/param_server.hpp"

namespace pmu::mavlink_params {
namespace param_file_test {  // named: the unity build joins this file with others of its target
namespace {

using namespace std::chrono_literals;

const Time t0 = Time{} + 1h;

// A snapshot as pmuctl writes it, with values that are not whole numbers where a setting
// has steps.
constexpr const char* kSnapshot = R"(device:
  vehicle: "uav1"
  bus: "can0"
  address: 1
parameters:
  avionics_voltage: 23.7
  payload_voltage: 12.3
  servo_voltage: 7.4
  battery_voltage: 25.1
  packet_period: 0.3
  packets_streamed: [voltages, currents, temperatures, status]
  temperature_offset: 17
  upper_temperature_limit: 85
  power_up_state: [avionics_servo, payload]
  cranking_time: 4.7
  can_address: 1
outputs: [avionics_servo, charger_b]
generation_enabled: false
)";

// How ground stations write a REAL32 into their files: MAVProxy "%f", QGroundControl and
// Mission Planner with the float's shortest exact digits.
enum class Format { Fixed, Exact };
std::string as_file_text(float v, Format format) {
  char buf[64];
  if (format == Format::Fixed)
    std::snprintf(buf, sizeof buf, "%f", static_cast<double>(v));
  else
    std::snprintf(buf, sizeof buf, "%.9g", static_cast<double>(v));
  return buf;
}

TEST(ParamFile, SavedValuesAreTheSnapshotsAndLoadBackToTheSameWireValues) {
  const auto file = baseline::read_config_file(kSnapshot);
  ASSERT_TRUE(file) << file.error().message;
  ParamServer server({});
  server.set_device(0, file->settings);
  for (const auto format : {Format::Fixed, Format::Exact}) {
    for (const auto& row : param_table()) {
      SCOPED_TRACE(std::string(row.suffix) + (format == Format::Fixed ? " %f" : " %.9g"));
      const auto raw = file->settings[row.setting];
      ASSERT_TRUE(raw);
      const auto text = as_file_text(to_real32(row.setting, *raw), format);
      const float loaded = std::strtof(text.c_str(), nullptr);
      const auto back = from_real32(row.setting, loaded);
      ASSERT_TRUE(back) << back.error();
      EXPECT_EQ(*back, *raw) << text;
      // Loading the file back: each set is answered at once with the same value, nothing
      // goes to the service.
      mavlink::ParamSet set;
      set.param_id = param_name({0, row.setting});
      set.param_value = loaded;
      const auto out = server.on_param_set({255, 190}, set, t0);
      EXPECT_FALSE(out.request);
      ASSERT_EQ(out.send.size(), 1U);
      EXPECT_FLOAT_EQ(std::get<mavlink::ParamValue>(out.send[0]).param_value, to_real32(row.setting, *raw));
    }
  }
  EXPECT_EQ(server.counters().sets_sent, 0U);
}

TEST(ConfirmSet, NamesTheRulesAndRefusesUnknownOnes) {
  const auto set = confirm_set({"engine_start", "reset", "engine_start"});
  ASSERT_TRUE(set);
  for (std::size_t i = 0; i < set->size(); ++i) {
    const auto rule = static_cast<service::ConfirmRule>(i);
    EXPECT_EQ((*set)[i], rule == service::ConfirmRule::EngineStart || rule == service::ConfirmRule::Reset);
  }
  const auto bad = confirm_set({"reset", "engine-start\n"});
  ASSERT_FALSE(bad);
  EXPECT_NE(bad.error().find("'engine-start\\x0A'"), std::string::npos) << bad.error();
  EXPECT_NE(bad.error().find("disable_avionics"), std::string::npos);
  EXPECT_TRUE(confirm_set({}));
}

}  // namespace
}  // namespace param_file_test
}  // namespace pmu::mavlink_params
