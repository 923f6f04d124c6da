#pragma once
// The enum values and "not provided" sentinels pmu-mavlink uses, named as in minimal.xml and
// common.xml (mavlink/README.md gives the commit). Only what the bridge needs, not the
// whole dialect.

#include <cstdint>
#include <limits>

namespace pmu::mavlink {

// HEARTBEAT.mavlink_version: the protocol version the definitions carry (minimal.xml <version>).
inline constexpr std::uint8_t kMavlinkVersion = 3;

namespace mav_type {  // MAV_TYPE
inline constexpr std::uint8_t kGeneric = 0;
inline constexpr std::uint8_t kGcs = 6;
inline constexpr std::uint8_t kOnboardController = 18;
inline constexpr std::uint8_t kChargingStation = 31;
inline constexpr std::uint8_t kBattery = 36;
}  // namespace mav_type

namespace mav_autopilot {  // MAV_AUTOPILOT
inline constexpr std::uint8_t kGeneric = 0;
// "Use MAV_AUTOPILOT_INVALID for components that are not flight controllers."
inline constexpr std::uint8_t kInvalid = 8;
}  // namespace mav_autopilot

namespace mav_component {  // MAV_COMPONENT
inline constexpr std::uint8_t kAll = 0;
inline constexpr std::uint8_t kAutopilot1 = 1;
inline constexpr std::uint8_t kBattery = 180;
inline constexpr std::uint8_t kBattery2 = 181;
inline constexpr std::uint8_t kOnboardComputer = 191;
}  // namespace mav_component

namespace mav_state {  // MAV_STATE
inline constexpr std::uint8_t kUninit = 0;
inline constexpr std::uint8_t kBoot = 1;
inline constexpr std::uint8_t kCalibrating = 2;
inline constexpr std::uint8_t kStandby = 3;
inline constexpr std::uint8_t kActive = 4;
inline constexpr std::uint8_t kCritical = 5;
inline constexpr std::uint8_t kEmergency = 6;
inline constexpr std::uint8_t kPoweroff = 7;
inline constexpr std::uint8_t kFlightTermination = 8;
}  // namespace mav_state

namespace mav_severity {  // MAV_SEVERITY (RFC 5424)
inline constexpr std::uint8_t kEmergency = 0;
inline constexpr std::uint8_t kAlert = 1;
inline constexpr std::uint8_t kCritical = 2;
inline constexpr std::uint8_t kError = 3;
inline constexpr std::uint8_t kWarning = 4;
inline constexpr std::uint8_t kNotice = 5;
inline constexpr std::uint8_t kInfo = 6;
inline constexpr std::uint8_t kDebug = 7;
}  // namespace mav_severity

namespace mav_result {  // MAV_RESULT
inline constexpr std::uint8_t kAccepted = 0;
inline constexpr std::uint8_t kTemporarilyRejected = 1;
inline constexpr std::uint8_t kDenied = 2;
inline constexpr std::uint8_t kUnsupported = 3;
inline constexpr std::uint8_t kFailed = 4;
inline constexpr std::uint8_t kInProgress = 5;
inline constexpr std::uint8_t kCancelled = 6;
inline constexpr std::uint8_t kCommandLongOnly = 7;
inline constexpr std::uint8_t kCommandIntOnly = 8;
inline constexpr std::uint8_t kCommandUnsupportedMavFrame = 9;
}  // namespace mav_result

namespace mav_cmd {  // MAV_CMD (COMMAND_LONG.command)
inline constexpr std::uint16_t kDoSetRelay = 181;
inline constexpr std::uint16_t kDoEngineControl = 223;
inline constexpr std::uint16_t kPreflightRebootShutdown = 246;
inline constexpr std::uint16_t kRunPrearmChecks = 401;
inline constexpr std::uint16_t kSetMessageInterval = 511;
inline constexpr std::uint16_t kRequestMessage = 512;
}  // namespace mav_cmd

namespace mav_param_type {  // MAV_PARAM_TYPE
// REAL32 is the one type C-cast and byte-wise parameter encodings agree on.
inline constexpr std::uint8_t kReal32 = 9;
}  // namespace mav_param_type

namespace mav_battery_function {  // MAV_BATTERY_FUNCTION
inline constexpr std::uint8_t kUnknown = 0;
inline constexpr std::uint8_t kAll = 1;
inline constexpr std::uint8_t kPropulsion = 2;
inline constexpr std::uint8_t kAvionics = 3;
inline constexpr std::uint8_t kPayload = 4;
}  // namespace mav_battery_function

namespace mav_battery_type {  // MAV_BATTERY_TYPE
inline constexpr std::uint8_t kUnknown = 0;
inline constexpr std::uint8_t kLipo = 1;
inline constexpr std::uint8_t kLife = 2;
inline constexpr std::uint8_t kLion = 3;
inline constexpr std::uint8_t kNimh = 4;
}  // namespace mav_battery_type

namespace mav_battery_charge_state {  // MAV_BATTERY_CHARGE_STATE
inline constexpr std::uint8_t kUndefined = 0;
inline constexpr std::uint8_t kOk = 1;
inline constexpr std::uint8_t kLow = 2;
inline constexpr std::uint8_t kCritical = 3;
inline constexpr std::uint8_t kEmergency = 4;
inline constexpr std::uint8_t kFailed = 5;
inline constexpr std::uint8_t kUnhealthy = 6;
inline constexpr std::uint8_t kCharging = 7;
}  // namespace mav_battery_charge_state

namespace mav_battery_mode {  // MAV_BATTERY_MODE
inline constexpr std::uint8_t kUnknown = 0;
inline constexpr std::uint8_t kAutoDischarging = 1;
inline constexpr std::uint8_t kHotSwap = 2;
}  // namespace mav_battery_mode

namespace mav_battery_fault {  // MAV_BATTERY_FAULT (bitmask)
inline constexpr std::uint32_t kDeepDischarge = 1;
inline constexpr std::uint32_t kSpikes = 2;
inline constexpr std::uint32_t kCellFail = 4;
inline constexpr std::uint32_t kOverCurrent = 8;
inline constexpr std::uint32_t kOverTemperature = 16;
inline constexpr std::uint32_t kUnderTemperature = 32;
inline constexpr std::uint32_t kIncompatibleVoltage = 64;
inline constexpr std::uint32_t kIncompatibleFirmware = 128;
inline constexpr std::uint32_t kIncompatibleCellsConfiguration = 256;
}  // namespace mav_battery_fault

namespace mav_generator_status_flag {  // MAV_GENERATOR_STATUS_FLAG (bitmask)
inline constexpr std::uint64_t kOff = 1;
inline constexpr std::uint64_t kReady = 2;
inline constexpr std::uint64_t kGenerating = 4;
inline constexpr std::uint64_t kCharging = 8;
inline constexpr std::uint64_t kReducedPower = 16;
inline constexpr std::uint64_t kMaxpower = 32;
inline constexpr std::uint64_t kOvertempWarning = 64;
inline constexpr std::uint64_t kOvertempFault = 128;
inline constexpr std::uint64_t kElectronicsOvertempWarning = 256;
inline constexpr std::uint64_t kElectronicsOvertempFault = 512;
inline constexpr std::uint64_t kElectronicsFault = 1024;
inline constexpr std::uint64_t kPowersourceFault = 2048;
inline constexpr std::uint64_t kCommunicationWarning = 4096;
inline constexpr std::uint64_t kCoolingWarning = 8192;
inline constexpr std::uint64_t kPowerRailFault = 16384;
inline constexpr std::uint64_t kOvercurrentFault = 32768;
inline constexpr std::uint64_t kBatteryOverchargeCurrentFault = 65536;
inline constexpr std::uint64_t kOvervoltageFault = 131072;
inline constexpr std::uint64_t kBatteryUndervoltFault = 262144;
inline constexpr std::uint64_t kStartInhibited = 524288;
inline constexpr std::uint64_t kMaintenanceRequired = 1048576;
inline constexpr std::uint64_t kWarmingUp = 2097152;
inline constexpr std::uint64_t kIdle = 4194304;
}  // namespace mav_generator_status_flag

// "Not provided" values, each as the field's description in common.xml states it.
namespace not_provided {
// BATTERY_STATUS.voltages: "Cells ... above the valid cell count ... should have the UINT16_MAX value".
inline constexpr std::uint16_t kCellVoltage = std::numeric_limits<std::uint16_t>::max();
// BATTERY_STATUS.voltages_ext: "a value of 0, where zero indicates not supported" (a measured
// 0 is sent as 1).
inline constexpr std::uint16_t kCellVoltageExt = 0;
// BATTERY_STATUS.temperature: "INT16_MAX for unknown temperature"; GENERATOR_STATUS
// rectifier_temperature and generator_temperature: "INT16_MAX: field not provided".
inline constexpr std::int16_t kTemperature = std::numeric_limits<std::int16_t>::max();
// BATTERY_STATUS current_battery, current_consumed, energy_consumed, battery_remaining: -1.
inline constexpr std::int16_t kBatteryCurrent = -1;
inline constexpr std::int32_t kCurrentConsumed = -1;
inline constexpr std::int32_t kEnergyConsumed = -1;
inline constexpr std::int8_t kBatteryRemaining = -1;
// BATTERY_STATUS.time_remaining: "0: autopilot does not provide remaining battery time estimate".
inline constexpr std::int32_t kTimeRemaining = 0;
// GENERATOR_STATUS.generator_speed: "UINT16_MAX: field not provided".
inline constexpr std::uint16_t kGeneratorSpeed = std::numeric_limits<std::uint16_t>::max();
// GENERATOR_STATUS battery_current, load_current, power_generated, bat_current_setpoint: NaN.
inline constexpr float kFloat = std::numeric_limits<float>::quiet_NaN();
// GENERATOR_STATUS.runtime: "UINT32_MAX: field not provided".
inline constexpr std::uint32_t kRuntime = std::numeric_limits<std::uint32_t>::max();
// GENERATOR_STATUS.time_until_maintenance: "INT32_MAX: field not provided".
inline constexpr std::int32_t kTimeUntilMaintenance = std::numeric_limits<std::int32_t>::max();
// COMMAND_ACK.progress: "UINT8_MAX if the progress is unknown".
inline constexpr std::uint8_t kProgress = std::numeric_limits<std::uint8_t>::max();
// PARAM_REQUEST_READ.param_index: "Send -1 to use the param ID field as identifier".
inline constexpr std::int16_t kParamIndex = -1;
}  // namespace not_provided

}  // namespace pmu::mavlink
