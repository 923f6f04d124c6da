#include "pmu/sim/pmu_model.hpp"

#include <algorithm>
#include <stdexcept>
#include <utility>

#include "model_state.hpp"

namespace pmu::sim {

using detail::ModelState;

struct PmuModel::Impl : ModelState {
  using ModelState::ModelState;
};

PmuModel::PmuModel(const DeviceConfig& config, FrameSink sink, TimePoint now) {
  if (config.address == codec::kBroadcastAddress)
    throw std::invalid_argument("PMU address 65535 is the broadcast address (v1.9 4.3); use 0..65534");
  impl_ = std::make_unique<Impl>(config, std::move(sink), now);
}

PmuModel::~PmuModel() = default;
PmuModel::PmuModel(PmuModel&&) noexcept = default;
PmuModel& PmuModel::operator=(PmuModel&&) noexcept = default;

void PmuModel::on_frame(const codec::CanFrame& frame, TimePoint now) noexcept { impl_->on_frame(frame, now); }

void PmuModel::tick(TimePoint now) noexcept { impl_->tick(now); }

TimePoint PmuModel::next_deadline() const noexcept { return impl_->next_deadline(); }

void PmuModel::set_plant(const Plant& plant, TimePoint now) noexcept {
  impl_->advance(impl_->clamp_time(now));
  impl_->plant = plant;
  impl_->update_thermal();
}

const Plant& PmuModel::plant() const noexcept { return impl_->plant; }

void PmuModel::set_faults(const Faults& faults) noexcept { impl_->outbox.set_faults(faults); }

const Faults& PmuModel::faults() const noexcept { return impl_->outbox.faults(); }

void PmuModel::set_engine_running(bool running, TimePoint now) noexcept {
  impl_->advance(impl_->clamp_time(now));
  impl_->engine = running ? EngineState::Running : EngineState::Stopped;
}

void PmuModel::power_cycle(TimePoint now) noexcept {
  const TimePoint t = impl_->clamp_time(now);
  impl_->advance(t);
  impl_->restart(t);
}

std::uint16_t PmuModel::address() const noexcept { return impl_->address; }
codec::FirmwareVersion PmuModel::firmware() const noexcept { return impl_->firmware; }
std::uint32_t PmuModel::parameter(codec::Parameter p) const noexcept { return impl_->params.raw(p); }
std::uint8_t PmuModel::outputs() const noexcept { return impl_->outputs; }
bool PmuModel::generation_enabled() const noexcept { return impl_->generation_on; }
bool PmuModel::thermal_shutdown() const noexcept { return impl_->thermal; }
EngineState PmuModel::engine_state() const noexcept { return impl_->engine; }
double PmuModel::battery_a_mah() const noexcept { return impl_->mah_a; }
double PmuModel::battery_b_mah() const noexcept { return impl_->mah_b; }
Telemetry PmuModel::telemetry() const noexcept { return impl_->telemetry(); }
std::size_t PmuModel::frames_held() const noexcept { return impl_->outbox.held(); }

Counters PmuModel::counters() const noexcept {
  Counters c = impl_->counters;
  c.frames_out = impl_->outbox.frames_out();
  c.lost = impl_->outbox.lost();
  c.suppressed = impl_->outbox.suppressed();
  return c;
}

}  // namespace pmu::sim
