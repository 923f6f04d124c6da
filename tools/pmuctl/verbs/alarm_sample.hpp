#pragma once
// The edge between pmu/alarms and pmuctl's views: a pmu::v5::Alarm sample as the plain
// AlarmEntry of view/alarm_marker.hpp, and which alarms the global options select.

#include "pmu/idl/alarms.h"
#include "pmuctl/verbs/state_verbs.hpp"
#include "pmuctl/view/alarm_marker.hpp"

namespace pmu::tools {

AlarmEntry alarm_entry_of(const pmu::v5::Alarm& a);

// --address names a PMU: the alarms of batteries, MPPTs and buses drop out then.
bool selected(const GlobalOptions& o, const AlarmEntry& a);

}  // namespace pmu::tools
