#include "telemetry/wire_units.hpp"

#include <cmath>
#include <limits>

namespace pmu::mavlink_bridge {

std::int32_t scaled_or(float x, float scale, std::int32_t low, std::int32_t high, std::int32_t missing) noexcept {
  if (!std::isfinite(x)) return missing;
  const double v = std::round(static_cast<double>(x) * static_cast<double>(scale));
  if (v <= low) return low;
  if (v >= high) return high;
  return static_cast<std::int32_t>(v);
}

std::uint16_t millivolts(float volts) noexcept {
  return static_cast<std::uint16_t>(scaled_or(volts, 1000.0F, 0, 65534, 65535));
}

std::uint16_t millivolts_ext(float volts) noexcept {
  return static_cast<std::uint16_t>(scaled_or(volts, 1000.0F, 1, 65535, 0));
}

std::int16_t centidegrees(float celsius) noexcept {
  return static_cast<std::int16_t>(scaled_or(celsius, 100.0F, -32768, 32766, std::numeric_limits<std::int16_t>::max()));
}

std::int16_t whole_degrees(float celsius) noexcept {
  return static_cast<std::int16_t>(scaled_or(celsius, 1.0F, -32768, 32766, std::numeric_limits<std::int16_t>::max()));
}

std::int16_t centiamperes(float amperes_out) noexcept {
  const std::int32_t v = scaled_or(amperes_out, 100.0F, -32768, 32767, -1);
  if (v == -1 && std::isfinite(amperes_out)) return 0;
  return static_cast<std::int16_t>(v);
}

}  // namespace pmu::mavlink_bridge
