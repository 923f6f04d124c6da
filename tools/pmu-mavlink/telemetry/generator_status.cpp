#include "telemetry/generator_status.hpp"

#include <cmath>
#include <limits>

#include "telemetry/wire_units.hpp"

namespace pmu::mavlink_bridge {

namespace nm = pmu::mavlink;
namespace flag = pmu::mavlink::mav_generator_status_flag;

namespace {

constexpr float kNotKnown = std::numeric_limits<float>::quiet_NaN();

float sum_or_nan(float x, float y) noexcept { return std::isfinite(x) && std::isfinite(y) ? x + y : kNotKnown; }

}  // namespace

nm::GeneratorStatus generator_status(const PmuView& pmu) {
  nm::GeneratorStatus m;
  if (!pmu.online) {
    m.status = flag::kCommunicationWarning;
    m.bus_voltage = kNotKnown;
    return m;
  }
  // The field defines no "not provided" value; NaN says it as the message's other floats do.
  m.bus_voltage = pmu.voltages ? pmu.voltages->generator() : kNotKnown;
  if (pmu.currents) {
    // Positive out of the batteries, as the field says; the contract's are positive into them.
    const float into = sum_or_nan(pmu.currents->battery_a(), pmu.currents->battery_b());
    m.battery_current = std::isfinite(into) ? -into : kNotKnown;
  }
  if (pmu.energy) m.power_generated = pmu.energy->generator_power();
  if (pmu.temperatures) m.generator_temperature = whole_degrees(pmu.temperatures->generator());
  if (pmu.status) {
    const auto& s = *pmu.status;
    m.generator_speed = static_cast<std::uint16_t>(scaled_or(s.generator_rpm(), 1.0F, 0, 65534, 65535));
    std::uint64_t f = 0;
    if (!s.generation_enabled()) {
      f |= flag::kOff;
    } else if (std::isfinite(s.generator_rpm()) && s.generator_rpm() > 0.0F) {
      f |= flag::kGenerating;
    } else {
      f |= flag::kReady;
    }
    if (std::isfinite(m.battery_current) && m.battery_current <= -0.1F) f |= flag::kCharging;
    // The PMU's own thermal shutdown: its electronics, not the engine.
    if (s.thermal_shutdown()) f |= flag::kElectronicsOvertempFault;
    // Safe-operating-area shutdown: the PMU cut the generator path for its load.
    if (s.soa_shutdown()) f |= flag::kOvercurrentFault;
    if (s.payload_shed()) f |= flag::kReducedPower;
    m.status = f;
  }
  return m;
}

}  // namespace pmu::mavlink_bridge
