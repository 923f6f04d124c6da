#include "telemetry/battery_status.hpp"

#include <cmath>
#include <limits>

#include "telemetry/wire_units.hpp"

namespace pmu::mavlink_bridge {

namespace nm = pmu::mavlink;

namespace {

constexpr float kUnknown = std::numeric_limits<float>::quiet_NaN();

// Wh to hJ (1 Wh = 3600 J = 36 hJ). The energy used is discharge less charge since the
// service started; a net charge is sent as 0 consumed, not as a negative the field does not
// define (and -1 would read as "not provided").
std::int32_t hectojoules(double used_wh) noexcept {
  if (!std::isfinite(used_wh)) return nm::not_provided::kEnergyConsumed;
  return scaled_or(static_cast<float>(used_wh), 36.0F, 0, std::numeric_limits<std::int32_t>::max() - 127,
                   nm::not_provided::kEnergyConsumed);
}

// Endurance in s: 0 is the field's "not provided"; a known endurance under half a second is 1.
std::int32_t seconds_remaining(float endurance_s) noexcept {
  return scaled_or(endurance_s, 1.0F, 1, std::numeric_limits<std::int32_t>::max() - 127,
                   nm::not_provided::kTimeRemaining);
}

}  // namespace

std::uint8_t charge_state(float current_in) noexcept {
  if (std::isfinite(current_in) && current_in >= 0.1F) return nm::mav_battery_charge_state::kCharging;
  return nm::mav_battery_charge_state::kUndefined;
}

nm::BatteryStatus pmu_battery_status(const PmuView& pmu, BatteryInput input, std::uint8_t id) {
  nm::BatteryStatus m;
  m.id = id;
  if (!pmu.online) return m;
  const bool a = input == BatteryInput::a;
  // The PMU measures the pack, not its cells: the devguide puts the pack voltage in cell 0.
  if (pmu.voltages) m.voltages[0] = millivolts(a ? pmu.voltages->battery_a() : pmu.voltages->battery_b());
  const float current_in = pmu.currents ? (a ? pmu.currents->battery_a() : pmu.currents->battery_b()) : kUnknown;
  m.current_battery = centiamperes(-current_in);
  m.charge_state = charge_state(current_in);
  if (pmu.temperatures) m.temperature = centidegrees(a ? pmu.temperatures->battery_a() : pmu.temperatures->battery_b());
  if (pmu.battery_energy) {
    // The PMU's counter is charge into the battery since its power-up (interface.md 1.2).
    const std::int64_t into = a ? pmu.battery_energy->battery_a_mah() : pmu.battery_energy->battery_b_mah();
    const std::int64_t consumed = -into;
    m.current_consumed = consumed <= 0 ? 0
                         : consumed >= std::numeric_limits<std::int32_t>::max()
                             ? std::numeric_limits<std::int32_t>::max()
                             : static_cast<std::int32_t>(consumed);
  }
  if (pmu.energy) {
    const auto& e = a ? pmu.energy->battery_a() : pmu.energy->battery_b();
    m.energy_consumed = hectojoules(e.used_wh());
    m.time_remaining = seconds_remaining(e.endurance_s());
  }
  // battery_remaining stays -1: the PMU does not know a state of charge.
  return m;
}

nm::BatteryStatus bms_battery_status(const BmsView& bms, std::uint8_t id) {
  nm::BatteryStatus m;
  m.id = id;
  if (!bms.online) return m;
  bool cells_known = false;
  if (bms.cells) {
    // Cell n (the 0x482 subindex, from 1) into voltages[n-1], cells 11..14 into voltages_ext.
    for (const auto& c : bms.cells->cells()) {
      if (c.cell() >= 1 && c.cell() <= 10) {
        m.voltages[c.cell() - 1U] = millivolts(c.cell_voltage());
        cells_known = cells_known || m.voltages[c.cell() - 1U] != nm::not_provided::kCellVoltage;
      } else if (c.cell() >= 11 && c.cell() <= 14) {
        m.voltages_ext[c.cell() - 11U] = millivolts_ext(c.cell_voltage());
      }
    }
  }
  if (bms.battery) {
    const auto& b = *bms.battery;
    if (!cells_known) m.voltages[0] = millivolts(b.voltage());
    // The BMS's current is positive into the battery (interface.md 1.8).
    m.current_battery = centiamperes(-b.current());
    m.charge_state = charge_state(b.current());
    m.temperature = centidegrees(b.cell_temperature_high());
    m.battery_remaining =
        static_cast<std::int8_t>(scaled_or(b.state_of_charge(), 1.0F, 0, 100, nm::not_provided::kBatteryRemaining));
  }
  if (bms.energy) {
    m.energy_consumed = hectojoules(bms.energy->used_wh());
    m.time_remaining = seconds_remaining(bms.energy->endurance_s());
  }
  return m;
}

}  // namespace pmu::mavlink_bridge
