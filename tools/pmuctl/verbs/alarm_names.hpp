#pragma once
// The words pmuctl prints for the alarm enums of the contract (interface.md 1.6), shared by
// every verb that shows an alarm, so `alarms`, `preflight` and `alarms ack` agree.

#include "pmu/idl/alarms.h"

namespace pmu::tools {

// "pmu", "battery", "mppt", "bus".
const char* alarm_source_name(pmu::v5::AlarmSource k) noexcept;
// "NORMAL", "ACTIVE_UNACKNOWLEDGED", "ACTIVE_ACKNOWLEDGED", "CLEARED_UNACKNOWLEDGED".
const char* alarm_state_name(pmu::v5::AlarmState s) noexcept;

}  // namespace pmu::tools
