#include "pmu/sim/solar_plant.hpp"

#include <algorithm>
#include <cmath>
#include <iterator>

namespace pmu::sim {
namespace {

using std::chrono::duration;

constexpr double kPi = 3.14159265358979323846;
constexpr double kConverterEfficiency = 0.96;
constexpr double kStcIrradiance = 1000.0;  // W/m2 at which panel_vmp / panel_imp are rated
// A bus with no battery on it (only MPPTs simulated): a 12-cell pack's nominal voltage.
constexpr double kNominalBusVoltage = 12 * 3.7;
constexpr double kFull = 0.9999;  // state of charge at which the BMS calls the pack full
// An empty pack's BMS reconnects the load only once it has this much charge again, so it
// does not chatter on and off around zero.
constexpr double kReconnect = 0.05;

// Open-circuit voltage of a Li-ion (NMC) cell against state of charge, rising everywhere so a
// rising charge always shows as a rising voltage.
constexpr double kOcvSoc[] = {0.0, 0.05, 0.1, 0.2, 0.4, 0.6, 0.8, 0.9, 1.0};
constexpr double kOcvVolts[] = {3.00, 3.30, 3.45, 3.55, 3.65, 3.78, 3.95, 4.05, 4.15};

double cell_ocv(double soc) noexcept {
  soc = std::clamp(soc, 0.0, 1.0);
  for (std::size_t i = 1; i < std::size(kOcvSoc); ++i) {
    if (soc <= kOcvSoc[i]) {
      const double f = (soc - kOcvSoc[i - 1]) / (kOcvSoc[i] - kOcvSoc[i - 1]);
      return kOcvVolts[i - 1] + f * (kOcvVolts[i] - kOcvVolts[i - 1]);
    }
  }
  return kOcvVolts[std::size(kOcvVolts) - 1];
}

// Cells are never identical: a fixed spread of -6..+6 mV so high and low differ.
double cell_spread(int cell) noexcept { return static_cast<double>((cell * 7) % 5 - 2) * 0.003; }

// Offsets of the pack's four temperature sensors from its mean temperature.
constexpr double kSensorOffset[4] = {0.0, 0.8, 1.6, -0.5};

// The pack's terminal voltage: its cells in series, each at its open-circuit voltage plus
// the drop (or rise) across its resistance, unless the config fixes what the cells read.
double cell_voltage(const BatterySimConfig& c, double soc, double current, int cell) noexcept {
  const auto i = static_cast<std::size_t>(cell - 1);
  if (i < c.cell_voltages.size()) return c.cell_voltages[i];
  return cell_ocv(soc) + cell_spread(cell) + current * c.cell_resistance;
}
double pack_voltage(const BatterySimConfig& c, double soc, double current) noexcept {
  double v = 0;
  for (int i = 1; i <= std::clamp(c.cells, 0, kMaxCells); ++i) v += cell_voltage(c, soc, current, i);
  return v;
}

struct Panel {
  double voltage = 0, current = 0;
};

// A panel's maximum power point: current in proportion to the sun, voltage falling slowly
// (logarithmically) as it dims.
Panel panel_at(const MpptSimConfig& c, double irradiance) noexcept {
  if (irradiance <= 0) return {};
  const double g = irradiance / kStcIrradiance;
  return {std::clamp(c.panel_vmp * (1.0 + 0.06 * std::log(g)), 0.0, 1.2 * c.panel_vmp), c.panel_imp * g};
}

double available_power(const MpptSimConfig& c, double irradiance) noexcept {
  const Panel p = panel_at(c, irradiance);
  return std::clamp(c.panels, 0, 4) * p.voltage * p.current * kConverterEfficiency;
}

}  // namespace

SolarPlant::SolarPlant(const SolarWorld& world, TimePoint now) noexcept : world_(world), start_(now), last_(now) {}

std::uint64_t SolarPlant::add_battery(const BatterySimConfig& config) noexcept {
  const double soc = std::clamp(config.initial_soc, 0.0, 1.0);
  batteries_[config.node] = Battery{config, soc, soc <= 0, next_token_};
  return next_token_++;
}

void SolarPlant::remove_battery(std::uint8_t node, std::uint64_t token) noexcept {
  const auto it = batteries_.find(node);
  if (it != batteries_.end() && it->second.token == token) batteries_.erase(it);
}

std::uint64_t SolarPlant::add_mppt(const MpptSimConfig& config) noexcept {
  mppts_[config.device] = Mppt{config, next_token_};
  return next_token_++;
}

void SolarPlant::remove_mppt(std::uint8_t device, std::uint64_t token) noexcept {
  const auto it = mppts_.find(device);
  if (it != mppts_.end() && it->second.token == token) mppts_.erase(it);
}

double SolarPlant::irradiance_at(TimePoint t) const noexcept {
  if (fixed_irradiance_) return std::max(0.0, *fixed_irradiance_);
  const double cycle = duration<double>(world_.irradiance_cycle).count();
  if (cycle <= 0) return std::max(0.0, world_.irradiance_mean);
  const double phase = duration<double>(t - start_).count() / cycle;
  return std::max(0.0, world_.irradiance_mean + world_.irradiance_swing * std::sin(2 * kPi * phase));
}

double SolarPlant::irradiance() const noexcept { return irradiance_at(last_); }

SolarPlant::Flows SolarPlant::flows() const noexcept {
  Flows f;
  const double g = irradiance();
  double available = 0;
  for (const auto& [device, m] : mppts_) available += available_power(m.config, g);
  const double load = std::max(0.0, world_.load_current);
  if (batteries_.empty()) {
    // MPPTs alone: they can only feed the load directly.
    f.bus_voltage = kNominalBusVoltage;
    if (available > 0) f.limit = std::min(1.0, load * f.bus_voltage / available);
    return f;
  }
  bool full = true, empty = true;
  for (const auto& [node, b] : batteries_) {
    full = full && b.soc >= kFull;
    empty = empty && b.load_cut;
  }
  const auto n = static_cast<double>(batteries_.size());
  const auto bus_voltage = [&](double current_per_battery) {
    double v = 0;
    for (const auto& [node, b] : batteries_) v += pack_voltage(b.config, b.soc, current_per_battery);
    return v / n;
  };
  const double drawn = empty ? 0.0 : load;  // an empty pack's BMS disconnects the load
  // The current depends on the terminal voltage (power / V) and the voltage on the current
  // (I * R): a few rounds of substitution settle it well below the fields' resolution.
  f.bus_voltage = bus_voltage(0);
  for (int round = 0; round < 4; ++round) {
    double in = f.bus_voltage > 0 ? available / f.bus_voltage : 0;
    f.limit = 1;
    if (full && in > drawn) {
      f.limit = in > 0 ? drawn / in : 0;
      in = drawn;
    }
    f.charge_per_battery = in / n;
    f.discharge_per_battery = drawn / n;
    f.bus_voltage = bus_voltage(f.charge_per_battery - f.discharge_per_battery);
  }
  return f;
}

void SolarPlant::update_cut(Battery& b) noexcept {
  if (b.soc <= 0) b.load_cut = true;
  if (b.soc >= kReconnect) b.load_cut = false;
}

void SolarPlant::step(Duration dt) noexcept {
  const Flows f = flows();
  const double hours = duration<double>(dt).count() / 3600.0;
  for (auto& [node, b] : batteries_) {
    const double net = f.charge_per_battery - f.discharge_per_battery;
    if (b.config.capacity_ah > 0) b.soc = std::clamp(b.soc + net * hours / b.config.capacity_ah, 0.0, 1.0);
    update_cut(b);
  }
}

void SolarPlant::advance(TimePoint now) noexcept {
  constexpr Duration kMaxStep = std::chrono::seconds(1);
  while (last_ < now) {
    const Duration dt = std::min<Duration>(kMaxStep, now - last_);
    step(dt);
    last_ += dt;
  }
}

void SolarPlant::set_irradiance(std::optional<double> w_per_m2, TimePoint now) noexcept {
  advance(now);
  fixed_irradiance_ = w_per_m2;
}

void SolarPlant::set_load(double amps, TimePoint now) noexcept {
  advance(now);
  world_.load_current = amps;
}

void SolarPlant::set_world(const SolarWorld& world, TimePoint now) noexcept {
  advance(now);
  world_ = world;
}

void SolarPlant::set_state_of_charge(std::uint8_t node, double soc, TimePoint now) noexcept {
  advance(now);
  if (auto it = batteries_.find(node); it != batteries_.end()) {
    it->second.soc = std::clamp(soc, 0.0, 1.0);
    it->second.load_cut = false;
    update_cut(it->second);
  }
}

std::optional<double> SolarPlant::state_of_charge(std::uint8_t node) const noexcept {
  const auto it = batteries_.find(node);
  if (it == batteries_.end()) return std::nullopt;
  return it->second.soc;
}

BatteryReading SolarPlant::battery(std::uint8_t node) const noexcept {
  BatteryReading r;
  const auto it = batteries_.find(node);
  if (it == batteries_.end()) return r;
  const Battery& b = it->second;
  const Flows f = flows();
  r.current_charge = f.charge_per_battery;
  r.current_discharge = f.discharge_per_battery;
  r.current = r.current_charge - r.current_discharge;
  r.state_of_charge = b.soc * 100.0;
  r.time_to_go =
      r.current < -0.01 ? std::min(65534.0, b.soc * b.config.capacity_ah / -r.current * 60.0) : kTimeToGoNotDischarging;
  r.cells = std::clamp(b.config.cells, 0, kMaxCells);
  r.cell_voltage_low = 1e9;
  for (int i = 0; i < r.cells; ++i) {
    const double v = cell_voltage(b.config, b.soc, r.current, i + 1);
    r.cell_voltages[static_cast<std::size_t>(i)] = v;
    r.voltage += v;
    r.cell_voltage_high = std::max(r.cell_voltage_high, v);
    r.cell_voltage_low = std::min(r.cell_voltage_low, v);
  }
  if (r.cells == 0) r.cell_voltage_low = 0;
  // Resistive heating: a few degrees above ambient at tens of amps.
  const double mean = world_.ambient_temperature + 0.15 * std::abs(r.current);
  r.cell_temperature_high = r.cell_temperature_low = mean + kSensorOffset[0];
  for (std::size_t i = 0; i < 4; ++i) {
    r.temperatures[i] = mean + kSensorOffset[i];
    r.cell_temperature_high = std::max(r.cell_temperature_high, r.temperatures[i]);
    r.cell_temperature_low = std::min(r.cell_temperature_low, r.temperatures[i]);
  }
  if (r.current > 0.05) r.bms_state |= bms_bit::Charging;
  if (r.current < -0.05) r.bms_state |= bms_bit::Discharging;
  if (b.soc >= kFull) r.bms_state |= bms_bit::Full;
  if (b.load_cut) r.bms_state |= bms_bit::Empty;
  r.power_level = r.state_of_charge;
  return r;
}

MpptReading SolarPlant::mppt(std::uint8_t device) const noexcept {
  MpptReading r;
  const auto it = mppts_.find(device);
  if (it == mppts_.end()) return r;
  const MpptSimConfig& c = it->second.config;
  const Flows f = flows();
  const Panel p = panel_at(c, irradiance());
  r.output_voltage = f.bus_voltage;
  r.out_sw_voltage = f.bus_voltage;  // the output switch is closed while safety is enabled
  double power = 0;
  for (int k = 0; k < std::clamp(c.panels, 0, 4); ++k) {
    const auto i = static_cast<std::size_t>(k);
    if (p.current <= 0) continue;
    // Limiting moves the panels off their maximum power point: less current drawn.
    r.panel_voltage[i] = p.voltage;
    r.panel_current[i] = p.current * f.limit;
    r.channel_active[i] = 1;
    if (f.bus_voltage > 0) r.duty_cycle[i] = std::clamp(1.0 - p.voltage / f.bus_voltage, 0.0, 1.0) * 100.0;
    power += r.panel_voltage[i] * r.panel_current[i] * kConverterEfficiency;
  }
  r.output_current = f.bus_voltage > 0 ? power / f.bus_voltage : 0;
  const bool active = power > 0 || (p.current > 0 && c.panels > 0);
  r.state = !active ? mppt_state::Idle : f.limit < 0.999 ? mppt_state::Limiting : mppt_state::Tracking;
  r.pwm_enabled = active;
  r.temperature = world_.ambient_temperature + 0.02 * power;
  return r;
}

}  // namespace pmu::sim
