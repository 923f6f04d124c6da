#include "pmu/session/canopen_session.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>

namespace pmu::service {

std::optional<DeviceKey> canopen_device(const std::string& bus, const codec::CanFrame& frame) noexcept {
  namespace co = codec::canopen;
  if (!co::is_canopen_id(frame.id, frame.extended)) return std::nullopt;
  DeviceKey key;
  key.bus = bus;
  if (frame.id >= co::kMpptBase) {  // every battery id lies below the MPPT blocks
    key.kind = DeviceKind::Mppt;
    key.address = static_cast<std::uint16_t>((frame.id - co::kMpptBase) / co::kMpptStride);
  } else {
    key.kind = DeviceKind::Battery;
    key.address = static_cast<std::uint16_t>(frame.id & 0x7F);  // CANopen: function code | node id
  }
  return key;
}

CanOpenSession::CanOpenSession(DeviceKey key, std::chrono::milliseconds period,
                               std::chrono::milliseconds publish_period, const Timeouts& timeouts, StateSink& sink,
                               SteadyTime now)
    : key_(std::move(key)), period_(period), publish_period_(publish_period), sink_(sink), health_(now, timeouts) {}

void CanOpenSession::on_frame(const codec::CanFrame& frame, SteadyTime now, WallTime received) {
  const bool was_offline = health_.offline();
  health_.on_frame(now);
  if (was_offline) forget(now);  // even a frame that does not decode says the unit is back
  const auto m = codec::canopen::decode(frame);
  if (!m) {
    health_.on_decode_error();
    return;
  }
  const Applied a = key_.kind == DeviceKind::Mppt ? apply(*m, mppt_) : apply(*m, battery_, cells_);
  auto mark = [&](Schedule& s) {
    s.dirty = true;
    s.newest = std::max(s.newest, received);
  };
  if (a.battery || a.mppt) mark(values_);
  if (a.cells) mark(cell_schedule_);
}

void CanOpenSession::forget(SteadyTime now) {
  health_.on_reconnect();
  battery_.clear();
  cells_.clear();
  mppt_.clear();
  // The first sample after a reconnect goes out at once, with the new unit's values only.
  values_ = Schedule{};
  cell_schedule_ = Schedule{};
  values_.next_allowed = cell_schedule_.next_allowed = now;
}

bool CanOpenSession::due(Schedule& s, SteadyTime now) const noexcept {
  if (!s.dirty || now < s.next_allowed) return false;
  s.dirty = false;
  s.next_allowed = now + publish_period_;
  return true;
}

void CanOpenSession::tick(SteadyTime now) {
  if (due(values_, now)) {
    if (key_.kind == DeviceKind::Mppt)
      sink_.on_mppt(key_, mppt_, values_.newest);
    else
      sink_.on_battery(key_, battery_, values_.newest);
  }
  if (due(cell_schedule_, now)) sink_.on_battery_cells(key_, cells_, cell_schedule_.newest);
  update_health(now, false);
}

void CanOpenSession::on_bus_state(transport::BusState state, SteadyTime now) {
  if (health_.on_bus_state(state)) update_health(now, true);
}

void CanOpenSession::update_health(SteadyTime now, bool force) {
  const auto u = health_.update(now, period_, force);
  const auto& report = health_.report();
  if (u.changed && report.state != HealthState::Unknown)
    spdlog::log(report.state == HealthState::Online ? spdlog::level::info : spdlog::level::warn,
                "{}/{}{}: {} (last frame {:.1f} s ago)", key_.bus, to_string(key_.kind), key_.address,
                to_string(report.state), report.last_frame_age);
  if (u.publish) sink_.on_health(key_, report);
}

}  // namespace pmu::service
