#include "pmu/standby/fenced_bus.hpp"

#include <utility>

#include "pmu/redundancy/can_beat.hpp"

namespace pmu::standby {

FencedBus::FencedBus(std::unique_ptr<transport::CanBus> inner, RoleHolder& holder, const transport::Clock& clock,
                     Tap tap)
    : inner_(std::move(inner)), holder_(holder), clock_(clock), tap_(std::move(tap)) {
  holder_.attach(*inner_, clock_.steady_now());
}

transport::DrainResult FencedBus::drain(transport::BusHandler& handler) {
  handler_ = &handler;
  beats_ = 0;
  auto result = inner_->drain(*this);
  handler_ = nullptr;
  result.frames -= beats_;
  return result;
}

void FencedBus::on_frame(const transport::ReceivedFrame& frame) {
  if (redundancy::is_can_beat_id(frame.frame.id, frame.frame.extended)) {
    ++beats_;
    holder_.on_can_frame(clock_.steady_now(), frame.frame);
    return;
  }
  // Before the frame reaches a session: a holder frozen while it owned the bus (also one stopped
  // in the middle of a drain) learns it here and closes its gates, so nothing it decodes now is
  // published beside the new owner's.
  holder_.tick(clock_.steady_now());
  if (tap_) tap_(inner_->name(), frame);
  handler_->on_frame(frame);
}

void FencedBus::on_event(const transport::BusEvent& event) {
  if (event.kind == transport::BusEventKind::StateChanged || event.kind == transport::BusEventKind::Reopened)
    holder_.on_bus_state(clock_.steady_now(), event.state);
  handler_->on_event(event);
}

transport::SendResult FencedBus::send(const codec::CanFrame& frame, std::chrono::milliseconds max_wait) {
  if (!holder_.may_transmit(clock_.steady_now())) {
    fenced_.fetch_add(1, std::memory_order_relaxed);
    return {transport::SendStatus::Fenced, 0};
  }
  return inner_->send(frame, max_wait);
}

void FencedBus::maintain(std::chrono::steady_clock::time_point now) { inner_->maintain(now); }

}  // namespace pmu::standby
