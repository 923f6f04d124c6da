#pragma once
// Topic and QoS profile names of interface.md sections 1.2 and 5.1, in one place for the service,
// pmuctl and the tests.

namespace pmu::topics {

inline constexpr const char* kVoltages = "pmu/voltages";
inline constexpr const char* kCurrents = "pmu/currents";
inline constexpr const char* kBatteryEnergy = "pmu/battery_energy";
inline constexpr const char* kTemperatures = "pmu/temperatures";
inline constexpr const char* kStatus = "pmu/status";
inline constexpr const char* kConfig = "pmu/config";
inline constexpr const char* kInfo = "pmu/info";
inline constexpr const char* kHealth = "pmu/health";
// The same telemetry at most once per configured period (config low_rate_period), for
// subscribers on slow links: docs/interface.md 1.5.
inline constexpr const char* kLowRateVoltages = "pmu/low_rate/voltages";
inline constexpr const char* kLowRateCurrents = "pmu/low_rate/currents";
inline constexpr const char* kLowRateBatteryEnergy = "pmu/low_rate/battery_energy";
inline constexpr const char* kLowRateTemperatures = "pmu/low_rate/temperatures";
inline constexpr const char* kLowRateStatus = "pmu/low_rate/status";
// pmu/health when a device's state or bus state changes, without the once-a-second repeats
// of its frame age and counters: what a watcher on a slow link shows (interface.md 1.5).
inline constexpr const char* kLowRateHealth = "pmu/low_rate/health";
// Batteries and MPPTs on the PMUs' buses (CANopen frames): docs/interface.md 1.4.
inline constexpr const char* kBattery = "pmu/battery";
inline constexpr const char* kBatteryCells = "pmu/battery_cells";
inline constexpr const char* kMppt = "pmu/mppt";
// Alarms of every device and bus: docs/interface.md 1.6.
inline constexpr const char* kAlarms = "pmu/alarms";
// Whether the vehicle may fly, and why not: docs/interface.md 1.7.
inline constexpr const char* kReadiness = "pmu/readiness";
// Power, energy and endurance derived from each PMU's telemetry: docs/interface.md 1.8.
inline constexpr const char* kEnergy = "pmu/energy";
// The configuration file each configured PMU is watched against: docs/interface.md 1.9.
inline constexpr const char* kBaseline = "pmu/baseline";
// Power, energy and endurance derived from each BMS's pmu/battery: docs/interface.md 1.8.
inline constexpr const char* kBmsEnergy = "pmu/bms_energy";
// Acknowledging an alarm, and its reply (QoS profile `command`): docs/interface.md 1.6.
inline constexpr const char* kAlarmAck = "pmu/alarm_ack";
inline constexpr const char* kAlarmAckReply = "pmu/alarm_ack_reply";
inline constexpr const char* kCommand = "pmu/command";
inline constexpr const char* kCommandReply = "pmu/command_reply";
// Hot standby: each instance's role heartbeat (QoS profile `role`), and the request that moves
// the role with its reply (QoS profile `command`): docs/interface.md 1.10.
inline constexpr const char* kRole = "pmu/role";
inline constexpr const char* kRoleMove = "pmu/role_move";
inline constexpr const char* kRoleMoveReply = "pmu/role_move_reply";

}  // namespace pmu::topics

namespace pmu::qos_profiles {

// deploy/qos.xml defines each as both a <data_writer> and a <data_reader> profile.
inline constexpr const char* kTelemetry = "telemetry";
inline constexpr const char* kState = "state";
inline constexpr const char* kCommand = "command";
inline constexpr const char* kAlarms = "alarms";
inline constexpr const char* kRole = "role";

}  // namespace pmu::qos_profiles
