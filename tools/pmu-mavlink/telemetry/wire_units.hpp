#pragma once
// Contract values (SI floats, NaN = not known; interface.md 1.1) into MAVLink's integer
// fields, each with its "not provided" sentinel. Total: NaN and every out-of-range value have
// an answer, and a known value never comes out as the sentinel (it is clamped one step
// inside the range), so a ground station never reads a measurement as "not provided" or the
// other way round.
#include <cstdint>

namespace pmu::mavlink_bridge {

// x * scale rounded, clamped to [low, high]; `missing` for NaN or infinity.
std::int32_t scaled_or(float x, float scale, std::int32_t low, std::int32_t high, std::int32_t missing) noexcept;

// Volts to mV for a voltages[] cell: UINT16_MAX when not known, else 0..65534.
std::uint16_t millivolts(float volts) noexcept;
// Volts to mV for a voltages_ext[] cell: 0 when not known, and a measured 0 is sent as 1, as
// the field's description asks.
std::uint16_t millivolts_ext(float volts) noexcept;
// degC to cdegC: INT16_MAX when not known.
std::int16_t centidegrees(float celsius) noexcept;
// degC to whole degC (GENERATOR_STATUS temperatures): INT16_MAX when not known.
std::int16_t whole_degrees(float celsius) noexcept;
// A current in A, positive out of the battery (discharging), to BATTERY_STATUS cA: -1 when
// not known. A measured -0.01 A, which would read as the sentinel, is sent as 0 cA.
std::int16_t centiamperes(float amperes_out) noexcept;

}  // namespace pmu::mavlink_bridge
