#pragma once
// The `ros2:` settings and the ROS 2 names built from them (docs/interface.md section 11).
//
// ROS 2 (rmw_fastrtps, rmw_cyclonedds) sees a DDS topic named "rt" + a fully qualified ROS
// name: "/" then tokens separated by "/", each token letters, digits and '_', not starting
// with a digit. A device's topics are named from the namespace, the vehicle, the bus and the
// device, so two aircraft, buses or devices never share a ROS topic. Vehicle and bus names
// allow characters ROS does not ('-', '.'): those become '_' (ros2_token), so "uav-1" and
// "uav_1" would share names; the config refuses such a pair (Config::ros2 is checked with the
// buses). Pure functions: no DDS, callable from any thread.

#include <cstdint>
#include <string>
#include <string_view>

namespace pmu::dds {

struct Ros2Settings {
  // Off by default: every participant that joins the domain, over a radio link too, gets the
  // discovery of each ROS 2 topic (about 400 bytes per topic and joining participant), and a
  // vehicle without ROS 2 on board gains nothing from them.
  bool enabled = false;
  // "" or an absolute ROS namespace ("/fleet_a"); a relative one is made absolute.
  std::string name_space;
  std::string source_line;  // "FILE:LINE" of the section, for later messages
};

// Why `ns` is no ROS 2 namespace ("" when it is one); "" and "/" are the root.
std::string ros2_namespace_problem(std::string_view ns);

// `text` as one ROS 2 name token: every character other than a letter, digit or '_' becomes
// '_', and a token that would start with a digit gets a leading '_'. "" stays "".
std::string ros2_token(std::string_view text);

// The device's part of a name: "pmu_1", "bms_2", "mppt_0".
enum class Ros2Device : std::uint8_t { Pmu, Bms, Mppt };
std::string ros2_device_token(Ros2Device kind, std::uint16_t address);

// "/<ns>/<vehicle>/<bus>/<device>": the ROS 2 namespace of one device's topics. An empty
// namespace or vehicle is left out.
std::string ros2_device_namespace(std::string_view ns, std::string_view vehicle, std::string_view bus, Ros2Device kind,
                                  std::uint16_t address);

// The DDS topic of the ROS 2 topic `ros_name` (absolute): "rt" + ros_name.
std::string ros2_dds_topic(std::string_view ros_name);

// The DiagnosticStatus name of a device: its namespace without the leading '/'
// ("uav1/can0/pmu_1"), the path rqt_robot_monitor and the aggregator group by.
std::string ros2_status_name(std::string_view ns, std::string_view vehicle, std::string_view bus, Ros2Device kind,
                             std::uint16_t address);

}  // namespace pmu::dds
