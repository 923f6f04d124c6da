#include "outbox.hpp"

#include <utility>

namespace pmu::sim::detail {

Outbox::Outbox(FrameSink sink) : sink_(std::move(sink)) {}

void Outbox::set_faults(const Faults& faults) noexcept {
  faults_ = faults;
  rng_.seed(faults.loss_seed);
}

void Outbox::send(const codec::CanFrame& frame, TimePoint now) noexcept {
  if (faults_.silent) {
    ++suppressed_;
    return;
  }
  if (faults_.loss_probability > 0.0) {
    // Drawn for every frame (not only when p < 1) so a given seed drops the same frames.
    const double u = std::uniform_real_distribution<double>(0.0, 1.0)(rng_);
    if (u < faults_.loss_probability) {
      ++lost_;
      return;
    }
  }
  if (faults_.delay > Duration::zero() || !held_.empty()) {
    held_.push_back({now + faults_.delay, frame});
    release(now);
    return;
  }
  deliver(frame);
}

void Outbox::release(TimePoint now) noexcept {
  while (!held_.empty() && held_.front().due <= now) {
    const codec::CanFrame frame = held_.front().frame;
    held_.pop_front();
    // Silence that began while the frame was held still keeps it off the bus.
    if (faults_.silent)
      ++suppressed_;
    else
      deliver(frame);
  }
}

std::optional<TimePoint> Outbox::next_release() const noexcept {
  if (held_.empty()) return std::nullopt;
  return held_.front().due;
}

void Outbox::deliver(const codec::CanFrame& frame) noexcept {
  ready_.push_back(frame);
  flush();
}

void Outbox::end() noexcept {
  --depth_;
  flush();
}

void Outbox::flush() noexcept {
  // Inside a batch, or an outer flush() further up the stack is draining the queue.
  if (depth_ > 0 || flushing_) return;
  flushing_ = true;
  while (!ready_.empty()) {
    const codec::CanFrame next = ready_.front();
    ready_.pop_front();
    ++frames_out_;
    if (sink_) sink_(next);
  }
  flushing_ = false;
}

}  // namespace pmu::sim::detail
