// The ROS 2 topics pmuctl record and serve carry (tools/pmuctl/record/ros2_topics.hpp,
// docs/interface.md 9.1): which --topic names are the service's ROS 2 topics, whose vehicle a
// battery topic is, and each topic's channel and ros2msg schema.
#include <gtest/gtest.h>

#include <string>

#include "pmuctl/record/ros2_topics.hpp"

namespace pmu::tools {
namespace {

TEST(Ros2Topics, NamesTheServiceWrites) {
  struct Case {
    const char* name;
    const char* dds_topic;  // nullptr: not a ROS 2 topic of the service
    const char* type;
  };
  const Case cases[] = {
      {"/diagnostics", "rt/diagnostics", kRos2DiagnosticsType},
      {"rt/diagnostics", "rt/diagnostics", kRos2DiagnosticsType},
      {"/uav1/can0/pmu_1/battery_a", "rt/uav1/can0/pmu_1/battery_a", kRos2BatteryType},
      {"rt/uav1/can0/pmu_1/battery_b", "rt/uav1/can0/pmu_1/battery_b", kRos2BatteryType},
      {"/fleet/uav1/can0/bms_2/battery", "rt/fleet/uav1/can0/bms_2/battery", kRos2BatteryType},
      {"/can0/pmu_1/battery_a", "rt/can0/pmu_1/battery_a", kRos2BatteryType},  // the unnamed vehicle
      {"diagnostics", nullptr, nullptr},                                       // a contract name's form
      {"voltages", nullptr, nullptr},
      {"pmu/voltages", nullptr, nullptr},
      {"/uav1/can0/pmu_1/voltage", nullptr, nullptr},
      {"/pmu_1/battery_a", nullptr, nullptr},  // no bus
      {"/uav1//pmu_1/battery_a", nullptr, nullptr},
      {"/uav1/can0/pmu_1/battery_c", nullptr, nullptr},
      {"/", nullptr, nullptr},
      {"", nullptr, nullptr},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.name);
    const auto r = ros2_topic_named(c.name);
    ASSERT_EQ(r.has_value(), c.dds_topic != nullptr);
    if (!r) continue;
    EXPECT_EQ(r->dds_topic, c.dds_topic);
    EXPECT_EQ(std::string(r->type_name), c.type);
  }
}

TEST(Ros2Topics, ABatteryTopicIsItsVehiclesAndDiagnosticsEveryVehicles) {
  struct Case {
    const char* dds_topic;
    const char* vehicle;
    bool of_it;
  };
  const Case cases[] = {
      {"rt/uav1/can0/pmu_1/battery_a", "uav1", true},
      {"rt/uav1/can0/pmu_1/battery_a", "uav2", false},
      {"rt/fleet/uav1/can0/bms_2/battery", "uav1", true},
      {"rt/uav_1/can0/pmu_1/battery_a", "uav-1", true},  // the vehicle's ROS 2 token
      {"rt/can0/pmu_1/battery_a", "can0", false},        // no vehicle token: the bus is not one
      {"rt/can0/pmu_1/battery_a", "", false},
      {"rt/diagnostics", "uav1", true},
      {"rt/diagnostics", "", true},
  };
  for (const auto& c : cases)
    EXPECT_EQ(ros2_topic_of_vehicle(c.dds_topic, c.vehicle), c.of_it) << c.dds_topic << " " << c.vehicle;
}

TEST(Ros2Topics, ChannelsAreTheRos2NamesWithRos2msgSchemas) {
  Ros2Topics topics;
  const auto* d = topics.get({"rt/diagnostics", kRos2DiagnosticsType});
  const auto* b = topics.get({"rt/uav1/can0/pmu_1/battery_a", kRos2BatteryType});
  EXPECT_EQ(topics.get({"rt/diagnostics", kRos2DiagnosticsType}), d) << "made once";
  EXPECT_EQ(std::string(d->topic), "rt/diagnostics");
  EXPECT_EQ(std::string(d->channel_name()), "/diagnostics");
  EXPECT_EQ(std::string(d->schema()), "diagnostic_msgs/msg/DiagnosticArray");
  EXPECT_EQ(std::string(d->schema_encoding()), "ros2msg");
  EXPECT_EQ(std::string(d->type_name), kRos2DiagnosticsType);
  EXPECT_EQ(std::string(b->channel_name()), "/uav1/can0/pmu_1/battery_a");
  EXPECT_EQ(std::string(b->schema()), "sensor_msgs/msg/BatteryState");
  // MCAP's ros2msg: the message's text, then each dependency after a line of 80 '='.
  const std::string separator = std::string(80, '=') + "\nMSG: ";
  const std::string dtext(d->idl), btext(b->idl);
  EXPECT_EQ(dtext.find("DiagnosticStatus[] status"), dtext.find("DiagnosticStatus[]"));
  EXPECT_NE(dtext.find(separator + "std_msgs/Header\n"), std::string::npos);
  EXPECT_NE(dtext.find(separator + "diagnostic_msgs/DiagnosticStatus\n"), std::string::npos);
  EXPECT_NE(dtext.find(separator + "diagnostic_msgs/KeyValue\n"), std::string::npos);
  EXPECT_LT(btext.find("float32 voltage"), btext.find(separator)) << "the message's own text first";
  EXPECT_NE(btext.find(separator + "std_msgs/Header\n"), std::string::npos);
}

}  // namespace
}  // namespace pmu::tools
