#include "pmu/session/canopen_session.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <limits>
#include <string_view>

namespace pmu::service {
namespace {

alarms::DeviceKind alarm_kind(DeviceKind k) noexcept {
  return k == DeviceKind::Mppt ? alarms::DeviceKind::Mppt : alarms::DeviceKind::Battery;
}

double value_of(const BatteryState& b, std::string_view name) noexcept {
  const auto slot = battery_slot(name);
  return slot ? b.values[*slot] : std::numeric_limits<double>::quiet_NaN();
}

}  // namespace

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
                               SteadyTime now, const alarms::DeviceSettings& alarms)
    : key_(std::move(key)),
      period_(period),
      publish_period_(publish_period),
      sink_(sink),
      health_(now, timeouts),
      alarms_(key_.bus, alarm_kind(key_.kind), key_.address, alarms, sink) {}

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
  if (a.battery) feed_alarms(now, received);
}

// From the BMS's own figures (0x302, 0x402), so the alarms agree with what pmu/battery
// shows: state of charge, its lowest cell, highest minus lowest cell, its highest cell
// temperature. A value not received (NaN) holds the alarm. The MPPT feeds only its health:
// the document names "MPPT State" (uint8) and "Safety Enabled" (bool) but gives none of their
// values, so nothing it sends says "fault", and mppt_fault is never raised rather than
// raised on a guess.
void CanOpenSession::feed_alarms(SteadyTime now, WallTime wall) {
  using alarms::Code;
  if (key_.kind != DeviceKind::Battery) return;
  const double soc = value_of(battery_, "state_of_charge");
  const double cell_high = value_of(battery_, "cell_voltage_high");
  const double cell_low = value_of(battery_, "cell_voltage_low");
  alarms_.observe(Code::BmsLowSoc, soc, now, wall);
  alarms_.observe(Code::BmsCriticalSoc, soc, now, wall);
  alarms_.observe(Code::CellLow, cell_low, now, wall);
  alarms_.observe(Code::CellImbalance, cell_high - cell_low, now, wall);  // NaN while either is
  alarms_.observe(Code::BmsOverTemperature, value_of(battery_, "cell_temperature_high"), now, wall);
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

void CanOpenSession::tick(SteadyTime now, WallTime wall) {
  if (due(values_, now)) {
    if (key_.kind == DeviceKind::Mppt)
      sink_.on_mppt(key_, mppt_, values_.newest);
    else
      sink_.on_battery(key_, battery_, values_.newest);
  }
  if (due(cell_schedule_, now)) sink_.on_battery_cells(key_, cells_, cell_schedule_.newest);
  update_health(now, false);
  // As a PMU's (device_session.cpp): stale while STALE or OFFLINE, offline while OFFLINE.
  const HealthState state = health_.report().state;
  alarms_.observe_flag(alarms::Code::DeviceStale, state == HealthState::Stale || state == HealthState::Offline, now,
                       wall);
  alarms_.observe_flag(alarms::Code::DeviceOffline, state == HealthState::Offline, now, wall);
  alarms_.tick(now, wall);
}

void CanOpenSession::on_bus_state(transport::BusState state, SteadyTime now) {
  if (health_.on_bus_state(state)) update_health(now, true);
}

void CanOpenSession::update_health(SteadyTime now, bool force) {
  const auto u = health_.update(now, period_, force);
  const auto& report = health_.report();
  if (u.changed && report.state != HealthState::Unknown)
    spdlog::log(report.state == HealthState::Online ? spdlog::level::info : spdlog::level::warn, "{}/{}{}: {} ({})",
                key_.bus, to_string(key_.kind), key_.address, to_string(report.state),
                last_frame_text(report.last_frame_age));
  if (u.publish) sink_.on_health(key_, report);
}

}  // namespace pmu::service
