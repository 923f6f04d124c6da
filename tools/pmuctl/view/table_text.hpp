#pragma once
// pmuctl's human tables as pure functions of the values shown (interface.md section 3.2), so
// each layout is tested without DDS: watch's one row per device and topic, the aligned
// columns of `list`, and the name/value blocks of info, health and config get.

#include <optional>
#include <string>
#include <vector>

#include "pmu/idl/state.h"
#include "pmuctl/view/alarm_marker.hpp"
#include "pmuctl/view/sample_fields.hpp"

namespace pmu::tools {

// How old values are: "0.2s", "12s", "5m", "3h" (a negative age, clock skew, is "0.0s").
std::string age_text(double seconds);

// What watch prints before a row's values: the device's health state (UNKNOWN when no
// pmu/health sample of it has arrived) and the age of the values: "ONLINE 0.2s",
// "OFFLINE 9.1s", so an old value never looks live.
std::string freshness(std::optional<pmu::v5::HealthState> state, double age_seconds);

// "avionics=12.3V output_28v=28V ...": one watch row's values, units attached.
std::string row_values(const SampleFields& fields);

// One row of watch's refreshing table: a device's latest sample of one topic.
struct WatchRow {
  std::string label;  // "can0/1"
  std::string topic;  // "voltages"
  std::optional<pmu::v5::HealthState> state;
  double age = 0;  // s since the sample's source time
  SampleFields values;
};
// The refreshing table: per topic, in the order the rows come, a "topic:" line, then one
// line per device, its label, state and age aligned within the topic. When an alarm is not
// NORMAL, an "alarms:" section comes first, a line per bus or device with its alarm_marker,
// so a bus (which has no row) and a device with no row yet are seen too; and a device's rows
// carry its marker after the age (the column is there only in a topic where one has one).
std::vector<std::string> watch_table(const std::vector<WatchRow>& rows, const std::vector<AlarmEntry>& alarms = {});

// Rows of cells as lines, each column as wide as its widest cell, two spaces apart; the
// last column is not padded. Rows may have fewer cells than others.
std::vector<std::string> aligned_columns(const std::vector<std::vector<std::string>>& rows);

// "can0/1\n  avionics_voltage         12.0 V\n...": one device's values, one per line.
std::string value_block(const std::string& label, const SampleFields& fields);

}  // namespace pmu::tools
