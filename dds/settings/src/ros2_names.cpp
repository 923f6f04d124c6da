#include "pmu/dds_settings/ros2_names.hpp"

namespace pmu::dds {
namespace ros2_names {

bool is_letter(char c) { return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z'); }
bool is_digit(char c) { return c >= '0' && c <= '9'; }

// A DDS topic name is at most 255 characters in Fast DDS and Cyclone DDS; "rt", a vehicle
// (15), a bus (15), a device and a leaf leave this much for the namespace.
constexpr std::size_t kMaxNamespace = 150;

void append_token(std::string& path, std::string_view token) {
  if (token.empty()) return;
  path += '/';
  path += token;
}

std::string absolute(std::string_view ns) {
  if (ns.empty() || ns == "/") return {};
  std::string s(ns);
  if (s.front() != '/') s.insert(s.begin(), '/');
  return s;
}

}  // namespace ros2_names

std::string ros2_namespace_problem(std::string_view ns) {
  using namespace ros2_names;
  if (ns.size() > kMaxNamespace)
    return "is " + std::to_string(ns.size()) + " characters; at most " + std::to_string(kMaxNamespace) +
           " leave room for the vehicle, bus and device in a DDS topic name";
  if (ns.empty() || ns == "/") return {};
  const std::string s = absolute(ns);
  if (s.back() == '/') return "ends with '/'; a ROS 2 namespace does not";
  std::size_t start = 1;
  while (start <= s.size()) {
    const std::size_t end = std::min(s.find('/', start), s.size());
    const std::string_view token = std::string_view(s).substr(start, end - start);
    if (token.empty()) return "has an empty token ('//'); ROS 2 names separate tokens by one '/'";
    if (is_digit(token.front()))
      return "has the token '" + std::string(token) + "', which starts with a digit; a ROS 2 name token may not";
    for (const char c : token)
      if (!is_letter(c) && !is_digit(c) && c != '_')
        return "contains '" + std::string(1, c) + "'; a ROS 2 name is letters, digits, '_' and '/' between tokens";
    start = end + 1;
  }
  return {};
}

std::string ros2_token(std::string_view text) {
  using namespace ros2_names;
  std::string t;
  t.reserve(text.size() + 1);
  for (const char c : text) t += (is_letter(c) || is_digit(c) || c == '_') ? c : '_';
  if (!t.empty() && is_digit(t.front())) t.insert(t.begin(), '_');
  return t;
}

std::string ros2_device_token(Ros2Device kind, std::uint16_t address) {
  const char* prefix = kind == Ros2Device::Pmu ? "pmu_" : kind == Ros2Device::Bms ? "bms_" : "mppt_";
  return prefix + std::to_string(address);
}

std::string ros2_device_namespace(std::string_view ns, std::string_view vehicle, std::string_view bus, Ros2Device kind,
                                  std::uint16_t address) {
  using namespace ros2_names;
  std::string path = absolute(ns);
  append_token(path, ros2_token(vehicle));
  append_token(path, ros2_token(bus));
  append_token(path, ros2_device_token(kind, address));
  return path;
}

std::string ros2_dds_topic(std::string_view ros_name) { return "rt" + std::string(ros_name); }

std::string ros2_status_name(std::string_view ns, std::string_view vehicle, std::string_view bus, Ros2Device kind,
                             std::uint16_t address) {
  return ros2_device_namespace(ns, vehicle, bus, kind, address).substr(1);
}

}  // namespace pmu::dds
