#pragma once
// The PMU's electrical and thermal behaviour as pure functions of the plant and the unit's
// operating state. The spec describes what the outputs do, not the power electronics, so
// this is the simplest model that follows every rule it states (sections 5.14, 5.21, 5.22).

#include <cstdint>
#include <optional>

#include "pmu/codec/messages.hpp"
#include "pmu/sim/config.hpp"
#include "pmu/sim/pmu_model.hpp"

namespace pmu::sim::detail {

struct Operating {
  std::uint8_t outputs = 0;  // codec::output_bit::*
  bool generation_on = true;
  bool thermal_shutdown = false;
  EngineState engine = EngineState::Stopped;
  double avionics_setpoint = 0;  // V_A, V_P, V_S in volts
  double payload_setpoint = 0;
  double servo_setpoint = 0;
};

// The generator feeds the outputs and chargers only while the engine runs, generation is
// on and the unit is not in thermal shutdown; otherwise the batteries feed the outputs
// (5.14: outputs unaffected "as long as at least one battery is connected").
bool generator_supplies(const Operating& op) noexcept;

// Measured values, unclamped. Battery currents are positive into the battery (table 4).
codec::Voltages voltages(const Plant& plant, const Operating& op) noexcept;
codec::Currents currents(const Plant& plant, const Operating& op) noexcept;
std::uint16_t generator_rpm(const Plant& plant, const Operating& op) noexcept;

// Into each field's range (tables 2..5, as codec/telemetry.hpp holds them): a real reading
// beyond what the field can carry is reported at the field's limit. NaN passes through (a
// temperature's "no sensor").
codec::Voltages clamped(const codec::Voltages& v) noexcept;
codec::Currents clamped(const codec::Currents& c) noexcept;
codec::Temperatures clamped(const codec::Temperatures& t) noexcept;
codec::BatteryEnergy energy_field(double battery_a_mah, double battery_b_mah) noexcept;

// Thermal shutdown after a temperature reading (5.14): T_U = 0 forces it, T_U = 255
// disables it; otherwise it starts above T_U and ends below T_U less 10% (the spec's
// "approximately 10% hysteresis"). An unreadable temperature (NaN) changes nothing.
bool next_thermal_shutdown(bool in_shutdown, double temperature, std::uint32_t limit) noexcept;

// How and when cranking that began at `since` ends by itself: the engine fires after
// `starts_after`, or the starter gives up after `timeout` (CT; zero = no timeout). If both
// fall on the same instant the engine is taken to have fired. nullopt: it cranks until 0x25.
struct CrankOutcome {
  TimePoint at;
  EngineState result;
};
std::optional<CrankOutcome> crank_outcome(TimePoint since, std::optional<Duration> starts_after,
                                          Duration timeout) noexcept;

}  // namespace pmu::sim::detail
