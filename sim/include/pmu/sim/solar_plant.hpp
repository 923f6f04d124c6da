#pragma once
// SolarPlant: the physics the simulated batteries and MPPTs on one bus share.
//
// Sun on the panels (a slow sine, or a value a test fixes) gives each MPPT's panels their
// maximum-power-point voltage and current; the MPPTs convert that power (96 %) onto the
// battery bus, where it charges the batteries; the load discharges them. Parallel batteries
// share the charge and the load equally. Each battery's state of charge integrates its
// current; its cells' voltage follows a Li-ion open-circuit curve of the state of charge plus
// I*R (a few mV of fixed spread between cells), the pack voltage is their sum and the
// temperatures rise with current above the ambient. A full battery makes the MPPTs limit
// their output to the load; an empty one is disconnected from the load by its BMS until it
// has 5 % again.
//
// Pure like PmuModel: time is passed in (advance(now)), nothing is read from a clock. The
// models call advance() before each frame, so whichever device sends first moves the world.
// Values are SI here; the models clamp them into what each field carries.

#include <array>
#include <cstdint>
#include <map>
#include <optional>

#include "pmu/sim/config.hpp"
#include "pmu/sim/solar_config.hpp"

namespace pmu::sim {

inline constexpr int kMaxCells = 15;

// 0x402/0x0E BMS state: the document defines no bits; these are the simulator's own.
namespace bms_bit {
inline constexpr std::uint32_t Charging = 1u << 0;
inline constexpr std::uint32_t Discharging = 1u << 1;
inline constexpr std::uint32_t Full = 1u << 2;
inline constexpr std::uint32_t Empty = 1u << 3;  // load disconnected (empty, until 5 %)
}  // namespace bms_bit

// 0x302/0x07 when the battery is not discharging (no time to empty): the uint16's largest.
inline constexpr double kTimeToGoNotDischarging = 65535.0;

struct BatteryReading {
  double voltage = 0;            // V, the sum of the cells
  double current = 0;            // A, + charging (current_charge - current_discharge)
  double current_charge = 0;     // A in from the MPPTs, >= 0
  double current_discharge = 0;  // A out to the load, >= 0
  double state_of_charge = 0;    // %
  double time_to_go = 0;         // min to empty at this discharge, or kTimeToGoNotDischarging
  int cells = 0;
  std::array<double, kMaxCells> cell_voltages{};  // V, cell 1 first
  double cell_voltage_high = 0, cell_voltage_low = 0;
  std::array<double, 4> temperatures{};  // degC, the pack's four sensors
  double cell_temperature_high = 0, cell_temperature_low = 0;
  std::uint32_t bms_state = 0;  // bms_bit
  double power_level = 0;       // %: the document does not say of what; the state of charge
};

// 0x4E6+8d/0x03 MPPT state: the simulator's own values.
namespace mppt_state {
inline constexpr std::uint8_t Idle = 0;      // no sun, converter off
inline constexpr std::uint8_t Tracking = 1;  // at the panels' maximum power point
inline constexpr std::uint8_t Limiting = 2;  // batteries full: output held to the load
}  // namespace mppt_state

// The document gives MPPT voltages and currents no resolution; the simulator sends them as
// counts of these (so +-327 V / A fit the int16).
inline constexpr double kMpptVoltsPerCount = 0.01;
inline constexpr double kMpptAmpsPerCount = 0.01;

struct MpptReading {
  double output_voltage = 0;  // V on the battery bus
  double output_current = 0;  // A into the battery bus
  double out_sw_voltage = 0;  // V after the output switch (closed while safety is enabled)
  std::uint8_t state = mppt_state::Idle;
  bool safety_enabled = true;
  bool pwm_enabled = false;
  double temperature = 0;                                  // degC
  std::array<double, 4> panel_voltage{}, panel_current{};  // V, A per channel
  std::array<double, 4> duty_cycle{};                      // % (boost: 1 - Vpanel / Vout)
  std::array<std::uint8_t, 4> channel_active{};            // 1 while the panel delivers
};

class SolarPlant {
 public:
  explicit SolarPlant(const SolarWorld& world, TimePoint now) noexcept;

  // A device joins (or replaces the one with its node / device number). Only the models
  // call these; configs are checked by the models' constructors. The token returned makes
  // remove_* a no-op for a device already replaced, so a replacement may be built before
  // the model it replaces is destroyed.
  std::uint64_t add_battery(const BatterySimConfig& config) noexcept;
  void remove_battery(std::uint8_t node, std::uint64_t token) noexcept;
  std::uint64_t add_mppt(const MpptSimConfig& config) noexcept;
  void remove_mppt(std::uint8_t device, std::uint64_t token) noexcept;

  // Integrates the batteries' charge up to `now` (steps of at most 1 s, with the currents at
  // each step's start). Times before the last one are ignored.
  void advance(TimePoint now) noexcept;

  // ---- harness controls; each applies from `now` (the time before is integrated first) ----
  // W/m2, or nullopt to return to the world's slow sine.
  void set_irradiance(std::optional<double> w_per_m2, TimePoint now) noexcept;
  void set_load(double amps, TimePoint now) noexcept;
  void set_world(const SolarWorld& world, TimePoint now) noexcept;
  void set_state_of_charge(std::uint8_t node, double soc, TimePoint now) noexcept;  // 0..1

  // ---- observation, at the last advance() ----
  const SolarWorld& world() const noexcept { return world_; }
  double irradiance() const noexcept;                                       // W/m2
  std::optional<double> state_of_charge(std::uint8_t node) const noexcept;  // 0..1, unrounded
  BatteryReading battery(std::uint8_t node) const noexcept;                 // all zero for an unknown node
  MpptReading mppt(std::uint8_t device) const noexcept;                     // all zero for an unknown device

 private:
  struct Battery {
    BatterySimConfig config;
    double soc = 0;
    bool load_cut = false;  // the BMS disconnected the load (empty), until kReconnect
    std::uint64_t token = 0;
  };
  struct Mppt {
    MpptSimConfig config;
    std::uint64_t token = 0;
  };
  // Where the power goes at the present state.
  struct Flows {
    double bus_voltage = 0;
    double charge_per_battery = 0;     // A from the MPPTs into each battery
    double discharge_per_battery = 0;  // A from each battery to the load
    double limit = 1;                  // fraction of the MPPTs' available power taken
  };
  Flows flows() const noexcept;
  double irradiance_at(TimePoint t) const noexcept;
  void step(Duration dt) noexcept;
  static void update_cut(Battery& b) noexcept;

  SolarWorld world_;
  std::optional<double> fixed_irradiance_;
  std::map<std::uint8_t, Battery> batteries_;
  std::map<std::uint8_t, Mppt> mppts_;
  std::uint64_t next_token_ = 1;
  TimePoint start_;
  TimePoint last_;
};

}  // namespace pmu::sim
