#include "pmu/sim/battery_model.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>
#include <utility>

#include "canopen_sender.hpp"
#include "pmu/codec/canopen_encode.hpp"

namespace pmu::sim {
namespace {

using codec::canopen::BatteryValue;

// The table's order (spec "Battery (MG) CAN-format"): 0x302, then 0x402; the cells and 0x202
// follow.
constexpr BatteryValue k302[] = {BatteryValue::Voltage,          BatteryValue::Current,
                                 BatteryValue::CurrentDischarge, BatteryValue::CurrentCharge,
                                 BatteryValue::StateOfCharge,    BatteryValue::TimeToGo};
constexpr BatteryValue k402[] = {BatteryValue::CellTemperatureHigh, BatteryValue::CellTemperatureLow,
                                 BatteryValue::CellVoltageHigh, BatteryValue::CellVoltageLow, BatteryValue::BmsState};
constexpr std::size_t kFixedBefore = std::size(k302) + std::size(k402) + 1;  // + temperature collection

// Readings beyond a field are clamped, as PmuModel does: a real BMS saturates, it does not
// fall silent. Ranges are the types of the document's rows.
double fit(BatteryValue v, double x) noexcept {
  switch (v) {
    case BatteryValue::Voltage:
    case BatteryValue::CellVoltageHigh:
    case BatteryValue::CellVoltageLow: return std::clamp(x, 0.0, 65.535);
    case BatteryValue::Current:
    case BatteryValue::CurrentDischarge:
    case BatteryValue::CurrentCharge: return std::clamp(x, -327.68, 327.67);
    case BatteryValue::StateOfCharge:
    case BatteryValue::CellTemperatureHigh:
    case BatteryValue::CellTemperatureLow: return std::clamp(x, -128.0, 127.0);
    case BatteryValue::TimeToGo: return std::clamp(x, 0.0, 65535.0);
    case BatteryValue::BmsState: return x;
    case BatteryValue::PowerLevel: return std::clamp(x, 0.0, 255.0);
  }
  return x;
}

double value_of(BatteryValue v, const BatteryReading& r) noexcept {
  switch (v) {
    case BatteryValue::Voltage: return r.voltage;
    case BatteryValue::Current: return r.current;
    case BatteryValue::CurrentDischarge: return r.current_discharge;
    case BatteryValue::CurrentCharge: return r.current_charge;
    case BatteryValue::StateOfCharge: return r.state_of_charge;
    case BatteryValue::TimeToGo: return r.time_to_go;
    case BatteryValue::CellTemperatureHigh: return r.cell_temperature_high;
    case BatteryValue::CellTemperatureLow: return r.cell_temperature_low;
    case BatteryValue::CellVoltageHigh: return r.cell_voltage_high;
    case BatteryValue::CellVoltageLow: return r.cell_voltage_low;
    case BatteryValue::BmsState: return r.bms_state;
    case BatteryValue::PowerLevel: return r.power_level;
  }
  return 0;
}

void check(const BatterySimConfig& c) {
  const auto bad = [&](const std::string& what) {
    throw std::invalid_argument("battery node " + std::to_string(c.node) + ": " + what);
  };
  if (c.node < 1 || c.node > codec::canopen::kMaxNode) bad("node must be 1..127");
  if (c.cells < 1 || c.cells > kMaxCells) bad("cells must be 1..15 (the pack voltage must fit 65.535 V)");
  if (c.period.count() <= 0) bad("period must be positive");
  if (!(c.capacity_ah > 0)) bad("capacity must be positive");
  if (!(c.initial_soc >= 0 && c.initial_soc <= 1)) bad("initial state of charge must be 0..1");
  if (!c.cell_voltages.empty() && c.cell_voltages.size() != static_cast<std::size_t>(c.cells))
    bad("cell voltages must be given for every cell or none (" + std::to_string(c.cells) + " cells, " +
        std::to_string(c.cell_voltages.size()) + " voltages)");
  for (const double v : c.cell_voltages)
    if (!(v >= 0 && v <= 65.535)) bad("a cell voltage must be 0..65.535 V (what 0x482 carries)");
}

}  // namespace

struct BatteryModel::Sender {
  detail::Spread spread;
  detail::CanOpenSender out;
};

BatteryModel::BatteryModel(const BatterySimConfig& config, std::shared_ptr<SolarPlant> plant, FrameSink sink,
                           TimePoint now)
    : config_(config), plant_(std::move(plant)), last_(now) {
  check(config_);
  if (!plant_) plant_ = std::make_shared<SolarPlant>(SolarWorld{}, now);
  token_ = plant_->add_battery(config_);
  sender_ = std::make_unique<Sender>(
      Sender{detail::Spread(config_.period, frames_per_period(), now), detail::CanOpenSender(std::move(sink))});
}

BatteryModel::~BatteryModel() { plant_->remove_battery(config_.node, token_); }

std::size_t BatteryModel::frames_per_period() const noexcept {
  return kFixedBefore + static_cast<std::size_t>(config_.cells) + 1;
}

void BatteryModel::tick(TimePoint now) noexcept {
  now = std::max(now, last_);
  last_ = now;
  plant_->advance(now);
  sender_->spread.due(now, [this](std::size_t slot) { send_frame(slot); });
}

TimePoint BatteryModel::next_deadline() const noexcept { return std::max(sender_->spread.next(), last_); }

void BatteryModel::send_frame(std::size_t slot) noexcept {
  namespace co = codec::canopen;
  const BatteryReading r = plant_->battery(config_.node);
  const std::uint8_t node = config_.node;
  const auto scalar = [&](BatteryValue v) { return co::encode_battery(v, fit(v, value_of(v, r)), node); };
  const std::size_t cells = static_cast<std::size_t>(config_.cells);
  if (slot < std::size(k302)) {
    sender_->out.send(scalar(k302[slot]), {0x06, std::nullopt});  // 0x06: blank row of 0x302
  } else if (slot < std::size(k302) + std::size(k402)) {
    sender_->out.send(scalar(k402[slot - std::size(k302)]), {0x0A, std::nullopt});  // blank row of 0x402
  } else if (slot < kFixedBefore) {
    std::array<double, 4> t{};
    for (std::size_t i = 0; i < 4; ++i) t[i] = std::clamp(r.temperatures[i], 0.0, 255.0);
    sender_->out.send(co::encode_temperature_collection(t, node), {0x0A, std::nullopt});
  } else if (slot < kFixedBefore + cells) {
    const std::size_t i = slot - kFixedBefore;
    // Every subindex is a cell number on 0x482: spoil the index instead.
    sender_->out.send(
        co::encode_cell_voltage(static_cast<std::uint8_t>(i + 1), std::clamp(r.cell_voltages[i], 0.0, 65.535), node),
        {std::nullopt, 0x2001});
  } else {
    sender_->out.send(scalar(BatteryValue::PowerLevel), {});  // 0x202 checks neither: cut short
  }
}

void BatteryModel::set_faults(const CanOpenFaults& faults) noexcept { sender_->out.set_faults(faults); }
const CanOpenFaults& BatteryModel::faults() const noexcept { return sender_->out.faults(); }
BatteryReading BatteryModel::reading() const noexcept { return plant_->battery(config_.node); }
CanOpenCounters BatteryModel::counters() const noexcept { return sender_->out.counters(); }

}  // namespace pmu::sim
