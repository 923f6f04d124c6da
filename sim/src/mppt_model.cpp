#include "pmu/sim/mppt_model.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

#include "canopen_sender.hpp"
#include "pmu/codec/canopen.hpp"
#include "pmu/codec/canopen_encode.hpp"

namespace pmu::sim {
namespace {

using codec::canopen::MpptValue;

constexpr std::size_t kValues = codec::canopen::kMpptValueCount;  // then the channel map
static_assert(MpptModel::frames_per_period() == kValues + 1);

// Counts of the sim's scale, clamped into the int16 the document gives them.
double counts(double si, double per_count) noexcept {
  return std::clamp(std::round(si / per_count), -32768.0, 32767.0);
}
double volts(double v) noexcept { return counts(v, kMpptVoltsPerCount); }
double amps(double a) noexcept { return counts(a, kMpptAmpsPerCount); }

double value_of(MpptValue v, const MpptReading& r) noexcept {
  switch (v) {
    case MpptValue::VoltageOutputRaw: return volts(r.output_voltage);
    case MpptValue::CurrentOutputRaw: return amps(r.output_current);
    case MpptValue::VoltageOutSwRaw: return volts(r.out_sw_voltage);
    case MpptValue::MpptState: return r.state;
    case MpptValue::SafetyEnabled: return r.safety_enabled ? 1 : 0;
    case MpptValue::PwmEnabled: return r.pwm_enabled ? 1 : 0;
    case MpptValue::Temperature: return std::clamp(r.temperature, -128.0, 127.0);
    case MpptValue::VoltagePanel1Raw: return volts(r.panel_voltage[0]);
    case MpptValue::CurrentPanel1Raw: return amps(r.panel_current[0]);
    case MpptValue::VoltagePanel2Raw: return volts(r.panel_voltage[1]);
    case MpptValue::CurrentPanel2Raw: return amps(r.panel_current[1]);
    case MpptValue::VoltagePanel3Raw: return volts(r.panel_voltage[2]);
    case MpptValue::CurrentPanel3Raw: return amps(r.panel_current[2]);
    case MpptValue::VoltagePanel4Raw: return volts(r.panel_voltage[3]);
    case MpptValue::CurrentPanel4Raw: return amps(r.panel_current[3]);
    case MpptValue::DutyCyclePanel1: return std::clamp(r.duty_cycle[0], 0.0, 100.0);
    case MpptValue::DutyCyclePanel2: return std::clamp(r.duty_cycle[1], 0.0, 100.0);
    case MpptValue::DutyCyclePanel3: return std::clamp(r.duty_cycle[2], 0.0, 100.0);
    case MpptValue::DutyCyclePanel4: return std::clamp(r.duty_cycle[3], 0.0, 100.0);
  }
  return 0;
}

void check(const MpptSimConfig& c) {
  const auto bad = [&](const std::string& what) {
    throw std::invalid_argument("MPPT device " + std::to_string(c.device) + ": " + what);
  };
  if (c.device >= codec::canopen::kMpptDevices) bad("device must be 0..7");
  if (c.panels < 0 || c.panels > 4) bad("panels must be 0..4");
  if (c.period.count() <= 0) bad("period must be positive");
  if (!(c.panel_vmp >= 0) || !(c.panel_imp >= 0)) bad("panel ratings must not be negative");
}

}  // namespace

struct MpptModel::Sender {
  detail::Spread spread;
  detail::CanOpenSender out;
};

MpptModel::MpptModel(const MpptSimConfig& config, std::shared_ptr<SolarPlant> plant, FrameSink sink, TimePoint now)
    : config_(config), plant_(std::move(plant)), last_(now) {
  check(config_);
  if (!plant_) plant_ = std::make_shared<SolarPlant>(SolarWorld{}, now);
  token_ = plant_->add_mppt(config_);
  sender_ = std::make_unique<Sender>(
      Sender{detail::Spread(config_.period, frames_per_period(), now), detail::CanOpenSender(std::move(sink))});
}

MpptModel::~MpptModel() { plant_->remove_mppt(config_.device, token_); }

void MpptModel::tick(TimePoint now) noexcept {
  now = std::max(now, last_);
  last_ = now;
  plant_->advance(now);
  sender_->spread.due(now, [this](std::size_t slot) { send_frame(slot); });
}

TimePoint MpptModel::next_deadline() const noexcept { return std::max(sender_->spread.next(), last_); }

void MpptModel::send_frame(std::size_t slot) noexcept {
  namespace co = codec::canopen;
  const MpptReading r = plant_->mppt(config_.device);
  if (slot < kValues) {
    const auto v = static_cast<MpptValue>(slot);
    // Blank subindexes: 0x07 on the base id (between the first two tables), 0x00 on base + 1.
    const std::uint8_t blank = v < MpptValue::DutyCyclePanel1 ? 0x07 : 0x00;
    sender_->out.send(co::encode_mppt(config_.device, v, value_of(v, r)), {blank, std::nullopt});
  } else {
    sender_->out.send(co::encode_channel_active_map(config_.device, r.channel_active), {0x00, std::nullopt});
  }
}

void MpptModel::set_faults(const CanOpenFaults& faults) noexcept { sender_->out.set_faults(faults); }
const CanOpenFaults& MpptModel::faults() const noexcept { return sender_->out.faults(); }
MpptReading MpptModel::reading() const noexcept { return plant_->mppt(config_.device); }
CanOpenCounters MpptModel::counters() const noexcept { return sender_->out.counters(); }

}  // namespace pmu::sim
