#pragma once
// The unit's transmit path with fault injection: silence, random loss and delay, in that
// order. Kept apart from the protocol logic so each fault is one small rule here and the
// model only ever says "send this frame now".

#include <cstdint>
#include <deque>
#include <optional>
#include <random>

#include "pmu/codec/can_frame.hpp"
#include "pmu/sim/config.hpp"
#include "pmu/sim/pmu_model.hpp"

namespace pmu::sim::detail {

class Outbox {
 public:
  explicit Outbox(FrameSink sink);

  void set_faults(const Faults& faults) noexcept;  // reseeds the loss generator
  const Faults& faults() const noexcept { return faults_; }

  // A frame the unit transmits at `now`.
  void send(const codec::CanFrame& frame, TimePoint now) noexcept;
  // Hands over the delayed frames whose time has come.
  void release(TimePoint now) noexcept;
  std::optional<TimePoint> next_release() const noexcept;
  std::size_t held() const noexcept { return held_.size(); }

  // Frames sent between begin() and end() reach the sink together at end(), so what the
  // unit sends for one event (a 0x0F burst) is never split by frames a re-entrant call
  // produces. Nests; Batch is the scoped form.
  void begin() noexcept { ++depth_; }
  void end() noexcept;
  class Batch {
   public:
    explicit Batch(Outbox& outbox) noexcept : outbox_(outbox) { outbox_.begin(); }
    ~Batch() { outbox_.end(); }
    Batch(const Batch&) = delete;
    Batch& operator=(const Batch&) = delete;

   private:
    Outbox& outbox_;
  };

  std::uint64_t frames_out() const noexcept { return frames_out_; }
  std::uint64_t lost() const noexcept { return lost_; }
  std::uint64_t suppressed() const noexcept { return suppressed_; }

 private:
  struct Held {
    TimePoint due;
    codec::CanFrame frame;
  };
  void deliver(const codec::CanFrame& frame) noexcept;
  void flush() noexcept;

  FrameSink sink_;
  Faults faults_{};
  std::mt19937_64 rng_{1};
  // FIFO like a CAN controller's transmit queue: a frame never overtakes an earlier one,
  // even when the delay is shortened while frames are held.
  std::deque<Held> held_;
  // Frames waiting for the sink; lets the sink call back into the model (see FrameSink).
  std::deque<codec::CanFrame> ready_;
  bool flushing_ = false;
  int depth_ = 0;
  std::uint64_t frames_out_ = 0, lost_ = 0, suppressed_ = 0;
};

}  // namespace pmu::sim::detail
