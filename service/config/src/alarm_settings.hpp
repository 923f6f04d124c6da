#pragma once
// `alarms:` of a PMU (a device, or `discover:`), a battery, an MPPT or a bus, read into the
// alarms room's DeviceSettings (interface.md 1.6 and 4.1). Private to config.cpp: it takes
// yaml-cpp nodes, which no header of the room shows.

#include <yaml-cpp/yaml.h>

#include <string>

#include "pmu/alarms/settings.hpp"

namespace pmu::service {

// `n` is the value of an `alarms:` key: a mapping of CODE: {limit, deadband, on_delay,
// off_delay, severity, enabled}, or nothing (null). Throws ConfigError "SOURCE:LINE: ..."
// at the offending key or value: an unknown code or key, a code that is not an alarm of
// `kind`, a value of the wrong type, and whatever alarms::resolve refuses, in its words.
alarms::DeviceSettings parse_alarm_settings(const YAML::Node& n, alarms::DeviceKind kind, const std::string& source);

}  // namespace pmu::service
