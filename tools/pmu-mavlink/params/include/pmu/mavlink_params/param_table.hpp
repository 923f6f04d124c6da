#pragma once
// The parameter table pmu-mavlink serves (interface.md, "pmu-mavlink", "Parameters"): each
// of a PMU's thirteen stored settings (pmu::baseline::Setting) as a MAVLink parameter.
//
// All PMUs of a bridge are parameters of its one component, told apart by a prefix: PMU n
// (1..9, the bridge's order of its PMUs) is `PMUn_`, so a name is `PMU1_AVION_V`, at most 16
// characters (PARAM_VALUE.param_id carries 16, without a terminator at 16). One component,
// not one per PMU: QGroundControl lists a non-autopilot component as "Component N" and
// searches only the autopilot's parameters, Mission Planner shows one component's
// parameters at a time, MAVProxy keeps a parameter file per (system, component); one
// component keeps every PMU in one list, one selection and one file.
//
// Values are REAL32 only (MAV_PARAM_TYPE_REAL32): the one type QGroundControl's byte-wise and
// MAVProxy's C-cast encodings agree on. A value is the setting in the unit of `pmuctl config
// get` (V, s, degC, a whole number, a mask as its number, 0/1 for generation), so a ground
// station's parameter file holds the numbers `pmuctl config snapshot` writes. Index order is
// fixed: PMU by PMU, settings in Setting's order; the count is the bridge's PMUs times 13.

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "pmu/baseline/settings.hpp"
#include "pmu/codec/result.hpp"

namespace pmu::mavlink_params {

using baseline::kSettingCount;
using baseline::Setting;

// PMUs one bridge serves through parameters: the prefix has room for one digit.
inline constexpr std::size_t kMaxPmus = 9;
// PARAM_VALUE.param_id's length.
inline constexpr std::size_t kMaxNameLength = 16;

struct ParamSpec {
  Setting setting;
  std::string_view suffix;  // after the prefix `PMUn_`: at most 11 characters
  std::string_view unit;    // of the REAL32 value: "V", "s", "degC", "" for numbers and masks
  bool writable;
};

// One row per Setting, in Setting's order.
const ParamSpec (&param_table() noexcept)[kSettingCount];
const ParamSpec& spec_of(Setting s) noexcept;

// A parameter: which PMU (0-based, the bridge's order), which setting.
struct ParamRef {
  std::size_t pmu = 0;
  Setting setting = Setting::AvionicsVoltage;
  bool operator==(const ParamRef& o) const noexcept { return pmu == o.pmu && setting == o.setting; }
};

// "PMU1_AVION_V" for pmu 0; pmu must be below kMaxPmus.
std::string param_name(ParamRef p);
// The reference a name gives among `pmu_count` PMUs; nullopt for any other name (wrong
// prefix, PMU beyond the count, unknown suffix, trailing bytes).
std::optional<ParamRef> param_from_name(std::string_view name, std::size_t pmu_count) noexcept;
// Index <-> reference among `pmu_count` PMUs.
std::uint16_t param_index(ParamRef p) noexcept;
std::optional<ParamRef> param_from_index(std::int64_t index, std::size_t pmu_count) noexcept;
inline std::size_t param_count(std::size_t pmu_count) noexcept { return pmu_count * kSettingCount; }

// The REAL32 a raw wire value is shown as: 240 -> 24.0 (V), 15 -> 1.5 (s), 0x13 -> 19.
float to_real32(Setting s, std::uint32_t raw) noexcept;
// The raw wire value a REAL32 stands for, checked against the spec's range and step (a value
// within 0.001 of a step is that step, as the service takes a float from DDS), or why not:
// "PMU1_AVION_V 30.0 out of range 12.0..24.0 V". Read-only settings are not judged here.
codec::Result<std::uint32_t, std::string> from_real32(Setting s, float value);

}  // namespace pmu::mavlink_params
