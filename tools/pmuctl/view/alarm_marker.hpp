#pragma once
// pmu/alarms (interface.md section 1.6) as pmuctl shows it, without DDS: the alarm as plain
// values, its `--json` object (the same for `pmuctl alarms` and `pmuctl watch`), and the
// marker watch puts beside a device or bus that has alarms not NORMAL.

#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace pmu::tools {

// ISA-18.2's states, as pmu::v5::AlarmState.
enum class AlarmStatus { Normal, ActiveUnacknowledged, ActiveAcknowledged, ClearedUnacknowledged };

// "NORMAL", "ACTIVE_UNACKNOWLEDGED", ...: the contract's names, as `--json` and tables show them.
const char* to_string(AlarmStatus s);

// One alarm instance's latest sample.
struct AlarmEntry {
  std::string vehicle;
  std::string bus;
  std::string kind;          // "pmu", "battery", "mppt", "bus"
  std::uint16_t device = 0;  // the PMU's address, battery's node, MPPT's id; 0 for the bus
  std::string code;
  bool critical = false;  // else a warning
  AlarmStatus state = AlarmStatus::Normal;
  float value = std::numeric_limits<float>::quiet_NaN();  // NaN for a flag
  float limit = std::numeric_limits<float>::quiet_NaN();
  std::uint64_t since = 0;  // ns since the Unix epoch
  std::string message;
};

// Whose alarm it is, labelled as watch labels its rows: "uav1/can0/1", "can0/battery2",
// "can0/mppt4", and the bus itself "can0".
std::string alarm_source(const AlarmEntry& a);

// The `--json` line's object: topic "alarms", the keys of interface.md 3.2, "contract" last.
nlohmann::ordered_json alarm_json(const AlarmEntry& a, int contract);

// "ALARM 2 CRIT unacked (thermal_shutdown)": how many of `alarms` are not NORMAL and the worst
// of them: its severity (CRIT, WARN), whether someone acknowledged it (unacked, acked, or
// "cleared unacked" for a critical that cleared before it was) and its code. The worst is the
// critical before the warning, then the active before the cleared, then the unacknowledged
// before the acknowledged, then the first code. Empty when every alarm is NORMAL.
std::string alarm_marker(const std::vector<AlarmEntry>& alarms);

// The alarms of `source` (alarm_source) among `alarms`.
std::vector<AlarmEntry> alarms_of(const std::vector<AlarmEntry>& alarms, const std::string& source);

}  // namespace pmu::tools
