#pragma once
// The values of each DDS sample as pmuctl shows them: one list per sample, in the contract's
// order and with its names (interface.md sections 1.3 and 1.4), each value with its JSON form
// and its table text. The JSON printer and every table read this one list, so a unit, a mask
// name or a sentinel word is decided once. Units come from the codec's tables (telemetry.hpp,
// parameters.hpp, the decode formatter frame_fields.hpp) and, for batteries and MPPTs, from
// the service's contract tables (canopen_state.hpp); none is typed here.
//
// Sentinels, values that stand for "no value" (JSON null, a word in tables):
//   - "no sensor": a PMU temperature of -128 on the wire (NaN; protocol v1.9 table 5)
//   - "no reading": generator_rpm 65535, the top of its 16 bits
//   - "n/a (not discharging)": a battery's time_to_go of 65535 min, the top of its 16 bits,
//     which the BMS sends while it is not discharging
//   - "never": Health last_frame_age -1 (no frame from the device yet)
//   - "-": a battery or MPPT value not received (NaN, or its `received` bit clear)
// Settings with a special meaning keep their number in JSON (a script may set it back) and
// say the meaning in tables: upper_temperature_limit 0 and 255, cranking_time 0 (tables 15, 17).

#include <string>
#include <string_view>
#include <vector>

#include "pmuctl/view/sample_json.hpp"

namespace pmu::tools {

struct SampleField {
  std::string name;  // the contract's field name, the JSON key
  Json json;         // the --json value; null for a sentinel or a value not received
  std::string text;  // the table text without the unit: "12.3", "avionics_servo (0x01)", "no sensor"
  std::string unit;  // "V", "A", "degC", "s", "rpm", "%", "mAh", or "" (none, or a sentinel word)
};
using SampleFields = std::vector<SampleField>;

SampleFields fields_of(const pmu::v5::Voltages& s);
SampleFields fields_of(const pmu::v5::Currents& s);
SampleFields fields_of(const pmu::v5::BatteryEnergy& s);
SampleFields fields_of(const pmu::v5::Temperatures& s);
SampleFields fields_of(const pmu::v5::Status& s);
SampleFields fields_of(const pmu::v5::Config& s);
SampleFields fields_of(const pmu::v5::DeviceInfo& s);
SampleFields fields_of(const pmu::v5::Health& s);
SampleFields fields_of(const pmu::v5::Battery& s);
// One field, `cells`: the JSON array of {cell, cell_voltage}, and in tables a summary
// ("12 cells 3.301..3.412 V": count, lowest and highest).
SampleFields fields_of(const pmu::v5::BatteryCells& s);
SampleFields fields_of(const pmu::v5::Mppt& s);

// The field of that name; nullptr when there is none.
const SampleField* find_field(const SampleFields& fields, std::string_view name);
// {"name": json, ...} in order.
Json json_of(const SampleFields& fields);
// "12.3 V" (`compact`: "12.3V"), or the text alone when there is no unit.
std::string text_with_unit(const SampleField& f, bool compact = false);

// The shortest decimal that reads back as the same float: 12.3f -> "12.3".
std::string shortest(float v);

// Sentinel words (interface.md section 3.2).
inline constexpr const char* kNoSensor = "no sensor";
inline constexpr const char* kNoReading = "no reading";
inline constexpr const char* kNotDischarging = "n/a (not discharging)";
inline constexpr const char* kNever = "never";
inline constexpr const char* kNotReceived = "-";

}  // namespace pmu::tools
