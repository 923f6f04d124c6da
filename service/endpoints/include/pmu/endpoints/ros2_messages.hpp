#pragma once
// The service's view of a device as ROS 2 messages (docs/interface.md section 11): a PMU's
// battery inputs and a BMS as sensor_msgs/BatteryState, each device as one
// diagnostic_msgs/DiagnosticStatus. Pure: values in, a message out; no DDS entity, clock or
// lock, so any thread may call them.
//
// BatteryState follows its .msg: current positive into the battery (charging) and negative
// when discharging (the contract's sign too), percentage 0..1, NaN for what is not measured.

#include <chrono>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "diagnostic_msgs/msg/DiagnosticStatus.h"
#include "pmu/session/device_state.hpp"
#include "sensor_msgs/msg/BatteryState.h"

namespace pmu::service {

// Below this magnitude (A) a battery is taken as neither charging nor discharging: the PMU
// reports its currents in 0.1 A steps.
inline constexpr double kIdleCurrent = 0.1;
inline constexpr double kUnknown = std::numeric_limits<double>::quiet_NaN();

// A PMU's battery input A or B, from its newest pmu/voltages, currents and temperatures.
struct PmuBatteryView {
  char input = 'A';  // 'A' or 'B'
  double voltage = kUnknown;
  double current = kUnknown;
  double temperature = kUnknown;  // NaN: no sensor, or firmware before 1.12
  std::optional<std::uint16_t> pmu_serial;
  HealthState health = HealthState::Unknown;
  std::vector<AlarmReport> active;                // the PMU's active alarms
  std::chrono::system_clock::time_point stamp{};  // receive time of the pmu/voltages frame
  std::string frame_id;                           // ros2_status_name of the PMU
};
sensor_msgs::msg::BatteryState pmu_battery_message(const PmuBatteryView& v);

// A BMS-reported battery (pmu/battery and pmu/battery_cells).
struct BmsView {
  BatteryState values;
  BatteryCellsState cells;
  std::optional<double> capacity_ah;  // the config's nameplate capacity
  HealthState health = HealthState::Unknown;
  std::vector<AlarmReport> active;
  std::chrono::system_clock::time_point stamp{};  // receive time of the newest frame
  std::string frame_id;
  std::string location;
};
sensor_msgs::msg::BatteryState bms_battery_message(const BmsView& v);

// One device's DiagnosticStatus: level from its health and active alarms, the health
// counters, `extra` (firmware, serial) and the active alarms as key/values.
struct DeviceDiagnosticsView {
  std::string name;         // ros2_status_name
  std::string hardware_id;  // "pmu serial 1234", "bms node 2", "mppt 0"
  HealthReport health;
  std::vector<AlarmReport> active;
  std::vector<std::pair<std::string, std::string>> extra;
};
diagnostic_msgs::msg::DiagnosticStatus device_status(const DeviceDiagnosticsView& v);

// The alarm states that count as active (raised, acknowledged or not).
bool alarm_active(const AlarmReport& a) noexcept;

// ROS 2's builtin_interfaces/Time of a wall-clock time (seconds and nanoseconds).
void set_stamp(std_msgs::msg::Header& header, std::chrono::system_clock::time_point t);

}  // namespace pmu::service
