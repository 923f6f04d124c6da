#include "physics.hpp"

#include <algorithm>
#include <cmath>

#include "pmu/codec/telemetry.hpp"

namespace pmu::sim::detail {
namespace {

namespace ob = codec::output_bit;

bool on(const Operating& op, std::uint8_t bit) noexcept { return (op.outputs & bit) != 0; }

// A battery below this reads as absent and cannot supply the outputs.
constexpr double kBatteryPresentVolts = 1.0;

double highest_battery(const Plant& p) noexcept { return std::max({0.0, p.battery_a_voltage, p.battery_b_voltage}); }

}  // namespace

bool generator_supplies(const Operating& op) noexcept {
  return op.engine == EngineState::Running && op.generation_on && !op.thermal_shutdown;
}

codec::Voltages voltages(const Plant& p, const Operating& op) noexcept {
  codec::Voltages v;
  // A disabled output reads 0 V; an enabled one its stored set point (tables 8..10).
  v.avionics = on(op, ob::AvionicsServo) ? op.avionics_setpoint : 0.0;
  v.servo = on(op, ob::AvionicsServo) ? op.servo_setpoint : 0.0;
  v.payload = on(op, ob::Payload) ? op.payload_setpoint : 0.0;
  // 5.14: without the generator the 28 V output "will assume the highest battery voltage".
  v.output_28v = generator_supplies(op) ? p.output_28v_voltage : highest_battery(p);
  v.battery_a = p.battery_a_voltage;
  v.battery_b = p.battery_b_voltage;
  // Chosen: the generator reads its voltage whenever it is driven and generating; switching
  // generation off removes the electrical load (5.21), modelled as no output at all.
  v.generator = op.engine == EngineState::Running && op.generation_on ? p.generator_voltage : 0.0;
  return v;
}

codec::Currents currents(const Plant& p, const Operating& op) noexcept {
  codec::Currents c;
  c.avionics = on(op, ob::AvionicsServo) ? p.avionics_load : 0.0;
  c.servo = on(op, ob::AvionicsServo) ? p.servo_load : 0.0;
  c.payload = on(op, ob::Payload) ? p.payload_load : 0.0;
  c.output_28v = p.output_28v_load;
  if (generator_supplies(op)) {
    // 5.14: chargers run only off the generator and never in thermal shutdown.
    c.battery_a = on(op, ob::ChargerA) ? p.charge_current : 0.0;
    c.battery_b = on(op, ob::ChargerB) ? p.charge_current : 0.0;
    return c;
  }
  // The batteries share the output power equally (chosen: the spec says nothing about how
  // the PMU splits the load); each draws that share at its own voltage.
  const codec::Voltages v = voltages(p, op);
  const double power =
      v.avionics * c.avionics + v.servo * c.servo + v.payload * c.payload + v.output_28v * c.output_28v;
  const bool a = p.battery_a_voltage >= kBatteryPresentVolts;
  const bool b = p.battery_b_voltage >= kBatteryPresentVolts;
  const int supplying = (a ? 1 : 0) + (b ? 1 : 0);
  if (supplying == 0) return c;
  const double share = power / supplying;
  c.battery_a = a ? -share / p.battery_a_voltage : 0.0;
  c.battery_b = b ? -share / p.battery_b_voltage : 0.0;
  return c;
}

std::uint16_t generator_rpm(const Plant& p, const Operating& op) noexcept {
  // Chosen: the generator is on the engine's shaft, so it turns (and its speed is measured)
  // whenever the engine does, cranked or running, whether or not it is generating; the
  // service tells a started engine from a failed start by this speed alone.
  if (op.engine == EngineState::Cranking) return p.cranking_rpm;
  return op.engine == EngineState::Running ? p.engine_rpm : 0;
}

codec::Voltages clamped(const codec::Voltages& v) noexcept { return codec::clamped_to_fields(v); }
codec::Currents clamped(const codec::Currents& c) noexcept { return codec::clamped_to_fields(c); }
codec::Temperatures clamped(const codec::Temperatures& t) noexcept { return codec::clamped_to_fields(t); }

codec::BatteryEnergy energy_field(double battery_a_mah, double battery_b_mah) noexcept {
  // The integral saturates at the field's limits rather than wrapping.
  const auto to_field = [](const auto& field, double mah) {
    if (std::isnan(mah)) return std::int16_t{0};
    return static_cast<std::int16_t>(std::lround(codec::clamp_to_field(field, mah)));
  };
  const auto& f = codec::Telemetry<codec::BatteryEnergy>::fields;
  return {to_field(f[0], battery_a_mah), to_field(f[1], battery_b_mah)};
}

bool next_thermal_shutdown(bool in_shutdown, double temperature, std::uint32_t limit) noexcept {
  if (limit == 0) return true;     // table 15: forces thermal shutdown
  if (limit >= 255) return false;  // table 15: disables it
  if (std::isnan(temperature)) return in_shutdown;
  const double upper = static_cast<double>(limit);
  if (!in_shutdown) return temperature > upper;
  return temperature >= upper * 0.9;  // stays shut down until 10% below the limit
}

std::optional<CrankOutcome> crank_outcome(TimePoint since, std::optional<Duration> starts_after,
                                          Duration timeout) noexcept {
  std::optional<CrankOutcome> out;
  if (starts_after) out = CrankOutcome{since + *starts_after, EngineState::Running};
  if (timeout > Duration::zero() && (!out || since + timeout < out->at))
    out = CrankOutcome{since + timeout, EngineState::Stopped};
  return out;
}

}  // namespace pmu::sim::detail
