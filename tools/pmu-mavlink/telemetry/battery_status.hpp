#pragma once
// BATTERY_STATUS (147) from a PMU's battery input A or B and from a BMS (interface.md
// "pmu-mavlink"). Pure: views in, message out.
//
// Every field the service does not know goes out as MAVLink's "not provided" value, never a
// made-up 0 (docs/safety.md H7): NaN, a topic not received yet, and every measured field
// while the device is not ONLINE. Current sign: MAVLink's batteries count discharge as
// positive (ArduPilot, PX4, BATTERY_STATUS_V2's text), the contract counts charge as positive
// (interface.md 1.8), so the sign is turned here.
#include <cstdint>

#include "pmu/mavlink/messages.hpp"
#include "telemetry/device_views.hpp"

namespace pmu::mavlink_bridge {

enum class BatteryInput { a, b };

pmu::mavlink::BatteryStatus pmu_battery_status(const PmuView& pmu, BatteryInput input, std::uint8_t id);
pmu::mavlink::BatteryStatus bms_battery_status(const BmsView& bms, std::uint8_t id);

// The charge state a current says, positive into the battery: CHARGING at 0.1 A and above
// (interface.md 11.2's threshold), else UNDEFINED: OK or LOW would be a judgement the
// service's alarms make, not the current (docs/safety.md H6).
std::uint8_t charge_state(float current_in) noexcept;

}  // namespace pmu::mavlink_bridge
