// The `ros2:` section and the ROS 2 names built from it (ros2_names.hpp): ROS 2's name rules
// (tokens of letters, digits and '_', not starting with a digit, one '/' between tokens), and
// every bad value refused at its line.
#include <gtest/gtest.h>

#include <string>

#include "pmu/config/config.hpp"
#include "pmu/dds_settings/ros2_names.hpp"

namespace pmu::service {
namespace {

const char* const kBuses = "buses:\n  - name: can0\n    interface: can0\n    discover: true\n";

TEST(Ros2Names, NamespacesFollowRos2sRules) {
  struct Case {
    const char* ns;
    const char* problem;  // "" = accepted
  };
  const Case cases[] = {
      {"", ""},
      {"/", ""},
      {"/fleet_a", ""},
      {"fleet_a/b2", ""},  // relative: made absolute
      {"/_9", ""},
      {"/fleet/", "ends with '/'; a ROS 2 namespace does not"},
      {"/a//b", "has an empty token ('//'); ROS 2 names separate tokens by one '/'"},
      {"/9lives", "has the token '9lives', which starts with a digit; a ROS 2 name token may not"},
      {"/a/2b", "has the token '2b', which starts with a digit; a ROS 2 name token may not"},
      {"/uav-1", "contains '-'; a ROS 2 name is letters, digits, '_' and '/' between tokens"},
      {"/a b", "contains ' '; a ROS 2 name is letters, digits, '_' and '/' between tokens"},
      {"~/x", "contains '~'; a ROS 2 name is letters, digits, '_' and '/' between tokens"},
  };
  for (const auto& c : cases) EXPECT_EQ(dds::ros2_namespace_problem(c.ns), c.problem) << c.ns;
  EXPECT_NE(dds::ros2_namespace_problem(std::string(151, 'a')), "");
  EXPECT_EQ(dds::ros2_namespace_problem(std::string(150, 'a')), "");
}

TEST(Ros2Names, VehicleAndBusBecomeTokens) {
  struct Case {
    const char* text;
    const char* token;
  };
  const Case cases[] = {{"uav1", "uav1"}, {"uav-1", "uav_1"}, {"uav.1", "uav_1"}, {"1st", "_1st"},
                        {"can0", "can0"}, {"", ""},           {"A_b", "A_b"}};
  for (const auto& c : cases) EXPECT_EQ(dds::ros2_token(c.text), c.token) << c.text;
}

TEST(Ros2Names, DeviceTopicsAndStatusNames) {
  EXPECT_EQ(dds::ros2_device_namespace("", "uav1", "can0", dds::Ros2Device::Pmu, 1), "/uav1/can0/pmu_1");
  EXPECT_EQ(dds::ros2_device_namespace("/", "uav1", "can0", dds::Ros2Device::Pmu, 1), "/uav1/can0/pmu_1");
  EXPECT_EQ(dds::ros2_device_namespace("fleet", "uav-7", "can0", dds::Ros2Device::Bms, 2), "/fleet/uav_7/can0/bms_2");
  EXPECT_EQ(dds::ros2_device_namespace("/fleet/a", "", "0can", dds::Ros2Device::Mppt, 0), "/fleet/a/_0can/mppt_0");
  EXPECT_EQ(dds::ros2_dds_topic("/uav1/can0/pmu_1/battery_a"), "rt/uav1/can0/pmu_1/battery_a");
  EXPECT_EQ(dds::ros2_status_name("", "uav1", "can0", dds::Ros2Device::Pmu, 3), "uav1/can0/pmu_3");
  EXPECT_EQ(dds::ros2_status_name("/fleet", "", "can0", dds::Ros2Device::Bms, 2), "fleet/can0/bms_2");
  // Every name made is a valid ROS 2 namespace (the same rules as a topic name).
  EXPECT_EQ(dds::ros2_namespace_problem(ros2_device_namespace("/f", "9-x.y", "b.1", dds::Ros2Device::Pmu, 255)), "");
}

TEST(Ros2Config, OffUnlessEnabledAndTheNamespaceIsKept) {
  EXPECT_FALSE(parse_config(kBuses, "c.yaml").ros2.enabled);
  const auto c = parse_config(std::string("ros2:\n  enabled: true\n  namespace: /fleet_a\n") + kBuses, "c.yaml");
  EXPECT_TRUE(c.ros2.enabled);
  EXPECT_EQ(c.ros2.name_space, "/fleet_a");
  EXPECT_EQ(c.ros2.source_line, "c.yaml:2");
  const auto off = parse_config(std::string("ros2:\n  enabled: false\n") + kBuses, "c.yaml");
  EXPECT_FALSE(off.ros2.enabled);
  EXPECT_EQ(off.ros2.name_space, "");
}

TEST(Ros2Config, EveryBadValueIsRefusedWithItsLine) {
  struct Case {
    std::string yaml;
    const char* message;
  };
  const Case cases[] = {
      {std::string("ros2: true\n") + kBuses, "bad.yaml:1: ros2 must be a map: {enabled: true, namespace: /fleet}"},
      {std::string("ros2:\n  enabled: yes please\n") + kBuses,
       "bad.yaml:2: ros2 enabled must be true or false, not 'yes please'"},
      {std::string("ros2:\n  enabled: true\n  namespace: /uav-1\n") + kBuses,
       "bad.yaml:3: ros2 namespace '/uav-1' contains '-'; a ROS 2 name is letters, digits, '_' and '/' between tokens"},
      {std::string("ros2:\n  enabled: true\n  name_space: /a\n") + kBuses,
       "bad.yaml:3: unknown key 'name_space' in ros2 (known: enabled, namespace)"},
      {"ros2:\n  enabled: true\nbuses:\n  - name: can-0\n    interface: can0\n    discover: true\n"
       "  - name: can_0\n    interface: can1\n    discover: true\n",
       "bad.yaml:7: bus names 'can-0' and 'can_0' are both 'can_0' in ROS 2 topic names (ros2 enabled); rename one"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.yaml);
    try {
      (void)parse_config(c.yaml, "bad.yaml");
      ADD_FAILURE() << "accepted";
    } catch (const ConfigError& e) {
      EXPECT_EQ(std::string(e.what()), c.message);
    }
  }
  // Without ros2 the two bus names are fine: they differ.
  EXPECT_NO_THROW(
      (void)parse_config("buses:\n  - name: can-0\n    interface: can0\n    discover: true\n"
                         "  - name: can_0\n    interface: can1\n    discover: true\n",
                         "ok.yaml"));
}

}  // namespace
}  // namespace pmu::service
