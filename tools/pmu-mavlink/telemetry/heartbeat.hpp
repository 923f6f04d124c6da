#pragma once
// pmu-mavlink's HEARTBEAT (0). A power system is not a flight controller: type
// MAV_TYPE_BATTERY, the type the devguide's battery service asks of a battery that is its
// own component, and autopilot MAV_AUTOPILOT_INVALID, so no ground station mistakes it for a
// vehicle (QGroundControl, Mission Planner and MAVProxy key vehicles on the autopilot).
#include <optional>

#include "pmu/mavlink/messages.hpp"

namespace pmu::mavlink_bridge {

// What the service said last of the vehicle: nothing yet, ready, or not ready.
enum class ServiceReadiness { not_heard, ready, not_ready };

// system_status: BOOT until the service's readiness is heard (nothing to vouch for yet),
// STANDBY while not ready, ACTIVE when ready. Never CRITICAL or EMERGENCY: those say the
// aircraft is in a failsafe, which a not-ready power system on the ground is not.
pmu::mavlink::Heartbeat heartbeat(ServiceReadiness readiness);

}  // namespace pmu::mavlink_bridge
