#include "pmuctl/record/ros2_topics.hpp"

#include <vector>

#include "pmu/dds_settings/ros2_names.hpp"
#include "pmu/ros2/msg_text.hpp"

namespace pmu::tools {
namespace {

bool ends_with(std::string_view s, std::string_view tail) {
  return s.size() >= tail.size() && s.substr(s.size() - tail.size()) == tail;
}

std::vector<std::string_view> segments(std::string_view s) {
  std::vector<std::string_view> out;
  while (!s.empty()) {
    const auto slash = s.find('/');
    out.push_back(s.substr(0, slash));
    if (slash == std::string_view::npos) break;
    s.remove_prefix(slash + 1);
  }
  return out;
}

}  // namespace

std::optional<Ros2TopicName> ros2_topic_named(std::string_view name) {
  std::string_view ros;  // the ROS 2 name without its leading '/'
  if (name.substr(0, 3) == "rt/")
    ros = name.substr(3);
  else if (name.substr(0, 1) == "/")
    ros = name.substr(1);
  else
    return std::nullopt;
  if (ros == "diagnostics") return Ros2TopicName{"rt/diagnostics", kRos2DiagnosticsType};
  const auto parts = segments(ros);
  // <bus>/<device>/<battery> at least, no empty token
  if (parts.size() < 3) return std::nullopt;
  for (const auto p : parts)
    if (p.empty()) return std::nullopt;
  if (!(ends_with(ros, "/battery_a") || ends_with(ros, "/battery_b") || ends_with(ros, "/battery")))
    return std::nullopt;
  return Ros2TopicName{"rt/" + std::string(ros), kRos2BatteryType};
}

bool ros2_topic_of_vehicle(std::string_view dds_topic, std::string_view vehicle) {
  if (dds_topic == "rt/diagnostics") return true;
  const auto parts = segments(dds_topic);  // "rt", [ns...], vehicle, bus, device, battery
  return !vehicle.empty() && parts.size() >= 5 && parts[parts.size() - 4] == dds::ros2_token(vehicle);
}

const RecordedTopic* Ros2Topics::get(const Ros2TopicName& name) {
  for (const auto& o : topics_)
    if (o.dds_topic == name.dds_topic) return &o.topic;
  const bool diagnostics = std::string_view(name.type_name) == kRos2DiagnosticsType;
  auto& o = topics_.emplace_back();
  o.dds_topic = name.dds_topic;
  o.channel = name.dds_topic.substr(2);  // "rt/x" -> "/x"
  o.topic.topic = o.dds_topic.c_str();
  o.topic.type_name = diagnostics ? kRos2DiagnosticsType : kRos2BatteryType;
  o.topic.idl = diagnostics ? ros2_msg_text::k_DiagnosticArray : ros2_msg_text::k_BatteryState;
  o.topic.qos_profile = "";
  o.topic.by_default = true;
  o.topic.ros2 = true;
  o.topic.channel = o.channel.c_str();
  o.topic.schema_name = diagnostics ? "diagnostic_msgs/msg/DiagnosticArray" : "sensor_msgs/msg/BatteryState";
  return &o.topic;
}

}  // namespace pmu::tools
