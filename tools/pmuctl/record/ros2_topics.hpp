#pragma once
// The ROS 2 topics pmu-service writes with `ros2: {enabled: true}` (docs/interface.md 11), as
// `pmuctl record` and `serve` carry them: `/diagnostics`, and the battery topics, which are
// named for the devices (`/uav1/can0/pmu_1/battery_a`) and so are found in DDS discovery
// (dds_remote_writers.hpp) by their type. No DDS here: names and RecordedTopics only.
// Not thread-safe: the verb's main thread uses it.

#include <deque>
#include <optional>
#include <string>
#include <string_view>

#include "pmuctl/record/mcap_topics.hpp"

namespace pmu::tools {

// ROS 2's DDS type names (rmw_fastrtps, rmw_cyclonedds), which the service's writers announce.
inline constexpr const char* kRos2BatteryType = "sensor_msgs::msg::dds_::BatteryState_";
inline constexpr const char* kRos2DiagnosticsType = "diagnostic_msgs::msg::dds_::DiagnosticArray_";

struct Ros2TopicName {
  std::string dds_topic;  // "rt/diagnostics", "rt/uav1/can0/pmu_1/battery_a"
  const char* type_name;  // kRos2BatteryType or kRos2DiagnosticsType
};
// A name `--topic` gives for a ROS 2 topic of the service: `/diagnostics`, `rt/diagnostics`, or
// a battery topic by its ROS 2 name or DDS name (ending in battery_a, battery_b or battery);
// nullopt for any other name.
std::optional<Ros2TopicName> ros2_topic_named(std::string_view name);

// Whether the battery topic `dds_topic` is one of `vehicle`'s: its token (ros2_token) is the
// name's part before bus, device and battery (`rt/<ns>/<vehicle>/<bus>/<device>/<battery>`).
// `/diagnostics` is every vehicle's.
bool ros2_topic_of_vehicle(std::string_view dds_topic, std::string_view vehicle);

// The RecordedTopics of the ROS 2 topics met so far, each made once; the pointers stay valid
// while the object lives.
class Ros2Topics {
 public:
  const RecordedTopic* get(const Ros2TopicName& name);

 private:
  struct Owned {
    std::string dds_topic, channel;
    RecordedTopic topic;
  };
  std::deque<Owned> topics_;
};

}  // namespace pmu::tools
