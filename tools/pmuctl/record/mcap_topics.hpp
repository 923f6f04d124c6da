#pragma once
// The topics pmuctl writes into MCAP files (`record`, `decode --mcap`): one channel per
// topic, message encoding `cdr`, schema encoding `omgidl`, schema name = the DDS type name,
// schema text = the idl/ file that defines the type (docs/interface.md, "MCAP recordings").
// No DDS here: the names and texts only.

#include <string>
#include <string_view>
#include <vector>

namespace pmu::tools {

struct RecordedTopic {
  const char* topic;        // "pmu/voltages"
  const char* type_name;    // "pmu::v5::Voltages": the DDS type name and the MCAP schema name
  std::string_view idl;     // the schema text
  const char* qos_profile;  // deploy/qos.xml's reader profile
  bool by_default;          // recorded when no --topic is given
  // A ROS 2 topic pmu-service writes (ros2_topics.hpp, docs/interface.md 11): read in the
  // default partition with a ROS 2 subscriber's QoS (qos_profile unused); its channel is named
  // as ROS 2 names the topic and its schema is the ros2msg definition.
  bool ros2 = false;
  const char* channel = nullptr;      // the MCAP/Foxglove topic ("/diagnostics"); nullptr: `topic`
  const char* schema_name = nullptr;  // "diagnostic_msgs/msg/DiagnosticArray"; nullptr: `type_name`

  const char* channel_name() const { return channel ? channel : topic; }
  const char* schema() const { return schema_name ? schema_name : type_name; }
  const char* schema_encoding() const { return ros2 ? "ros2msg" : "omgidl"; }
};

// Every topic `record` knows, in the contract's order.
const std::vector<RecordedTopic>& recorded_topics();
// By its name ("pmu/voltages") or its last part after "pmu/" ("voltages", "low_rate/voltages");
// nullptr when none.
const RecordedTopic* find_recorded_topic(std::string_view name);

// The topics `--topic NAME` options name (each once, in the order given), or every topic
// recorded by default when there are none: the selection of both `record` and `serve`.
// Empty, with `error` set ("--topic x is not a topic of the contract (pmu/voltages, ...)"),
// when a name is unknown.
std::vector<const RecordedTopic*> select_topics(const std::vector<std::string>& names, std::string& error);

}  // namespace pmu::tools
