#include "pmu/transport/sim_bus.hpp"

#include <algorithm>
#include <cerrno>
#include <mutex>
#include <utility>

#include "eventfd.hpp"

namespace pmu::transport {
namespace detail {

// What the network object and its endpoints share, so either may be destroyed first.
struct SimShared {
  explicit SimShared(const Clock& c) : clock(c) {}
  const Clock& clock;
  mutable std::mutex mutex;
  // Guarded by mutex.
  BusState state = BusState::Up;
  std::size_t drop_next = 0;
  std::vector<SimBus*> endpoints;
};

}  // namespace detail

SimulatedNetwork::SimulatedNetwork(const Clock& clock) : shared_(std::make_shared<detail::SimShared>(clock)) {}

SimulatedNetwork::~SimulatedNetwork() = default;

std::unique_ptr<SimBus> SimulatedNetwork::attach(const std::string& name, SimBusOptions options) {
  auto bus = std::make_unique<SimBus>(SimBus::Private{}, shared_, name, std::move(options));
  const std::lock_guard<std::mutex> lock(shared_->mutex);
  shared_->endpoints.push_back(bus.get());
  return bus;
}

void SimulatedNetwork::set_state(BusState state) {
  const std::lock_guard<std::mutex> lock(shared_->mutex);
  if (state == shared_->state) return;
  BusEvent event;
  event.kind = BusEventKind::StateChanged;
  event.previous = shared_->state;
  event.state = state;
  event.time = shared_->clock.system_now();
  shared_->state = state;
  for (SimBus* endpoint : shared_->endpoints) endpoint->push_locked(event);
}

BusState SimulatedNetwork::state() const {
  const std::lock_guard<std::mutex> lock(shared_->mutex);
  return shared_->state;
}

void SimulatedNetwork::drop_next(std::size_t frames) {
  const std::lock_guard<std::mutex> lock(shared_->mutex);
  shared_->drop_next = frames;
}

std::size_t SimulatedNetwork::endpoint_count() const {
  const std::lock_guard<std::mutex> lock(shared_->mutex);
  return shared_->endpoints.size();
}

SimBus::SimBus(Private, std::shared_ptr<detail::SimShared> shared, std::string name, SimBusOptions options)
    : shared_(std::move(shared)),
      name_(std::move(name)),
      options_(std::move(options)),
      wake_fd_(detail::make_eventfd()) {}

SimBus::~SimBus() {
  const std::lock_guard<std::mutex> lock(shared_->mutex);
  auto& endpoints = shared_->endpoints;
  endpoints.erase(std::remove(endpoints.begin(), endpoints.end(), this), endpoints.end());
}

void SimBus::push_locked(Pending item) {
  // Signalled only on the empty -> non-empty edge: drain() empties the queue and resets the
  // eventfd under the same lock, so one write per batch is enough.
  if (queue_.empty()) detail::signal_eventfd(wake_fd_.get());
  queue_.push_back(std::move(item));
}

void SimBus::deliver_locked(const ReceivedFrame& frame) {
  if (!accepts(options_.filters, frame.frame)) {
    ++counters_.rx_filtered;
    return;
  }
  if (queued_frames_ >= options_.queue_limit) {
    ++counters_.rx_drops;
    return;
  }
  ++queued_frames_;
  push_locked(frame);
}

DrainResult SimBus::drain(BusHandler& handler) {
  std::deque<Pending> batch;
  {
    const std::lock_guard<std::mutex> lock(shared_->mutex);
    detail::clear_eventfd(wake_fd_.get());
    batch.swap(queue_);
    counters_.rx_frames += queued_frames_;
    queued_frames_ = 0;
  }
  // Delivered without the lock: a handler may send on this or another endpoint.
  DrainResult result;
  for (const auto& item : batch) {
    if (const auto* frame = std::get_if<ReceivedFrame>(&item)) {
      ++result.frames;
      handler.on_frame(*frame);
    } else {
      ++result.events;
      handler.on_event(std::get<BusEvent>(item));
    }
  }
  return result;
}

SendResult SimBus::send(const codec::CanFrame& frame, std::chrono::milliseconds /*max_wait*/) {
  const std::lock_guard<std::mutex> lock(shared_->mutex);
  SendResult result;
  if (!is_sendable(frame))
    result = {SendStatus::InvalidFrame, EINVAL};
  else if (shared_->state == BusState::Down)
    result = {SendStatus::Down, ENETDOWN};
  else if (shared_->state == BusState::BusOff)
    result = {SendStatus::BusOff, ENETDOWN};
  if (!result.ok()) {
    ++counters_.tx_failures;
    return result;
  }
  ++counters_.tx_frames;
  if (shared_->drop_next > 0) {
    --shared_->drop_next;  // lost on the wire: the sender cannot tell
    return result;
  }
  const ReceivedFrame received{frame, shared_->clock.system_now(), false};
  for (SimBus* endpoint : shared_->endpoints)
    if (endpoint != this) endpoint->deliver_locked(received);
  return result;
}

BusState SimBus::state() const noexcept {
  const std::lock_guard<std::mutex> lock(shared_->mutex);
  return shared_->state;
}

BusCounters SimBus::counters() const noexcept {
  const std::lock_guard<std::mutex> lock(shared_->mutex);
  return counters_;
}

void SimBus::maintain(std::chrono::steady_clock::time_point /*now*/) {}

}  // namespace pmu::transport
