#pragma once
// FencedBus: the bus of one instance of a hot-standby pair, as its BusWorker sees it
// (docs/design.md, "Hot standby"). Every PMU frame the service would send (the start-up
// reading, polls, commands, discovery) passes may_transmit() of the RoleHolder right before
// it goes out: an instance that does not own the bus sends none, and send() says
// SendStatus::Fenced. Received frames on the heartbeat identifiers go to the holder and no
// further; every other frame and event goes to the worker as it came, and each frame also to
// `tap` (what a standby hears of its peer's commands), and each change of bus state to the
// holder too. The holder's own CAN heartbeat goes out on the bus underneath, past the fence.
// Each frame first ticks the holder: after a freeze, the role is judged before the next frame is
// decoded, also when the process was stopped in the middle of a drain.
//
// Lifetime: owns the bus underneath; `holder` and `clock` must outlive it. The holder is
// attached to the bus underneath at construction and must not be used from the bus's thread
// after this bus is destroyed. Threads: as transport::CanBus (one thread at a time: the
// worker's); `tap` is called on that thread.

#include <atomic>
#include <functional>
#include <memory>

#include "pmu/standby/role_holder.hpp"
#include "pmu/transport/can_bus.hpp"
#include "pmu/transport/clock.hpp"

namespace pmu::standby {

class FencedBus final : public transport::CanBus, private transport::BusHandler {
 public:
  using Tap = std::function<void(const std::string& bus, const transport::ReceivedFrame& frame)>;

  FencedBus(std::unique_ptr<transport::CanBus> inner, RoleHolder& holder, const transport::Clock& clock, Tap tap = {});

  const std::string& name() const noexcept override { return inner_->name(); }
  int fd() const noexcept override { return inner_->fd(); }
  transport::DrainResult drain(transport::BusHandler& handler) override;
  transport::SendResult send(const codec::CanFrame& frame, std::chrono::milliseconds max_wait) override;
  transport::BusState state() const noexcept override { return inner_->state(); }
  transport::BusCounters counters() const noexcept override { return inner_->counters(); }
  void maintain(std::chrono::steady_clock::time_point now) override;

  // Frames not sent because this instance did not own the bus. Any thread.
  std::uint64_t fenced() const noexcept { return fenced_.load(std::memory_order_relaxed); }
  transport::CanBus& inner() noexcept { return *inner_; }

 private:
  void on_frame(const transport::ReceivedFrame& frame) override;
  void on_event(const transport::BusEvent& event) override;

  std::unique_ptr<transport::CanBus> inner_;
  RoleHolder& holder_;
  const transport::Clock& clock_;
  Tap tap_;
  transport::BusHandler* handler_ = nullptr;  // during drain() only
  std::size_t beats_ = 0;                     // heartbeat frames in the drain() in progress
  std::atomic<std::uint64_t> fenced_{0};
};

}  // namespace pmu::standby
