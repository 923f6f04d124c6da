#include "pmu/standby/role_holder.hpp"

#include <utility>

namespace pmu::standby {

using redundancy::Role;

redundancy::BusState machine_bus_state(transport::BusState state) noexcept {
  switch (state) {
    case transport::BusState::BusOff: return redundancy::BusState::BusOff;
    case transport::BusState::Down: return redundancy::BusState::Down;
    case transport::BusState::Up:
    case transport::BusState::ErrorWarning:
    case transport::BusState::ErrorPassive: break;
  }
  return redundancy::BusState::Ok;
}

RoleHolder::RoleHolder(redundancy::Settings settings, Time now, Outputs outputs)
    : settings_(std::move(settings)), outputs_(std::move(outputs)), machine_(settings_, now) {}

void RoleHolder::attach(transport::CanBus& bus, Time now) {
  Due due;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    bus_ = &bus;
    bus_state_ = machine_bus_state(bus.state());
    machine_.on_bus_state(now, bus_state_);
    due = collect(now);
  }
  act(due);
}

RoleHolder::Due RoleHolder::collect(Time now) {
  Due due;
  const auto actions = machine_.poll(now);
  if (actions.dds) {
    redundancy::RoleReport r;
    r.name = settings_.name;
    r.peer = settings_.peer;
    r.beat = *actions.dds;
    r.bus = bus_state_;
    r.alarm = machine_.alarm();
    due.report = std::move(r);
  }
  due.can = actions.can;
  if (peer_joined_ && machine_.role() == Role::Active) due.peer_joined = true;
  if (machine_.role() == Role::Active || machine_.role() == Role::Claiming) peer_joined_ = false;
  if (machine_.role() != reported_role_ || machine_.alarm() != reported_alarm_) {
    due.change = RoleChange{reported_role_, machine_.role(), machine_.term(), machine_.alarm()};
    reported_role_ = machine_.role();
    reported_alarm_ = machine_.alarm();
  }
  return due;
}

void RoleHolder::act(const Due& due) {
  // The change first: a new owner's gates open before its first heartbeat says ACTIVE, and a
  // demoted one's close before anything else is written.
  if (due.change && outputs_.changed) outputs_.changed(*due.change);
  if (due.can && bus_ != nullptr) {
    codec::CanFrame f;
    f.id = redundancy::can_beat_id(settings_.priority);
    f.extended = true;
    const auto data = redundancy::encode_can_beat(*due.can);
    f.length = static_cast<std::uint8_t>(data.size());
    for (std::size_t i = 0; i < data.size(); ++i) f.data[i] = data[i];
    // Never waits: a full transmit queue loses one heartbeat of three per can_silence.
    (void)bus_->send(f, std::chrono::milliseconds(0));
  }
  if (due.report && outputs_.publish) outputs_.publish(*due.report);
  if (due.peer_joined && outputs_.peer_joined) outputs_.peer_joined();
}

void RoleHolder::tick(Time now) {
  Due due;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    due = collect(now);
  }
  act(due);
}

bool RoleHolder::may_transmit(Time now) {
  Due due;
  bool may = false;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    due = collect(now);
    may = machine_.may_transmit();
  }
  act(due);
  return may;
}

void RoleHolder::on_can_frame(Time now, const codec::CanFrame& frame) {
  Due due;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    const auto beat = redundancy::decode_can_beat(frame.id, frame.extended, frame.data.data(), frame.length);
    if (!beat) return;
    machine_.on_peer_can(now, *beat);
    due = collect(now);
  }
  act(due);
}

void RoleHolder::on_bus_state(Time now, transport::BusState state) {
  Due due;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    bus_state_ = machine_bus_state(state);
    machine_.on_bus_state(now, bus_state_);
    due = collect(now);
  }
  act(due);
}

void RoleHolder::on_report(const redundancy::RoleReport& report, Time arrival) {
  if (report.name != settings_.peer) return;
  std::lock_guard<std::mutex> lock(mutex_);
  machine_.on_peer_heartbeat(arrival, report.beat);
  if (!peer_ || arrival - peer_seen_ >= settings_.lease) peer_joined_ = true;
  peer_ = report;
  peer_seen_ = arrival;
}

void RoleHolder::leave(Time now) {
  std::lock_guard<std::mutex> lock(mutex_);
  machine_.leave(now);
}

redundancy::MoveResult RoleHolder::hand_over(Time now) {
  std::lock_guard<std::mutex> lock(mutex_);
  return machine_.hand_over(now);
}

Role RoleHolder::role() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return machine_.role();
}

bool RoleHolder::owns_bus(Time now) const {
  std::lock_guard<std::mutex> lock(mutex_);
  return machine_.owns_at(now);
}

std::string RoleHolder::status() const {
  std::lock_guard<std::mutex> lock(mutex_);
  std::string s(redundancy::role_name(machine_.role()));
  s += ", term " + std::to_string(machine_.term());
  if (machine_.alarm() != redundancy::PeerAlarm::None)
    s += ", alarm " + std::string(redundancy::alarm_name(machine_.alarm()));
  s += peer_ ? ", peer " + settings_.peer + " " + std::string(redundancy::role_name(peer_->beat.role))
             : ", peer " + settings_.peer + " not heard";
  return s;
}

}  // namespace pmu::standby
