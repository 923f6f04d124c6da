#pragma once
// SimulatedNetwork / SimBus: an in-process CAN bus.
//
// Purpose
//   Lets the service, pmu-sim and tests run whole conversations without a kernel CAN stack
//   (this machine has none) and without timing noise. Each SimBus endpoint is a CanBus; a
//   frame sent by one endpoint reaches every other endpoint, never the sender (as CAN_RAW
//   without CAN_RAW_RECV_OWN_MSGS behaves).
//
// Assumptions
//   * Each endpoint's fd() is an eventfd, readable while frames or events wait, so the same
//     epoll loop drives a SimBus and a SocketCanBus.
//   * Receive timestamps are the injected clock's system_now() at send time: all receivers
//     of one frame see the same timestamp, as on a real bus.
//   * Endpoints of one network may be used from different threads (the service in one, a
//     simulated PMU in another); one mutex per network serialises them. The clock must be
//     safe to read from those threads (SystemClock and ManualClock are).
//
// Error handling
//   * Nothing throws after attach() (which throws std::system_error if eventfd fails).
//   * A full endpoint queue (options.queue_limit frames) drops further frames for that
//     endpoint and counts them in rx_drops, as a full socket receive queue would.
//
// Fault knobs (for tests)
//   * set_state(): DOWN and BUS_OFF stop delivery and make send() fail (Down / BusOff);
//     ERROR_WARNING and ERROR_PASSIVE only report. Every endpoint gets a StateChanged event.
//   * drop_next(n): the next n frames sent are lost on the wire; senders still see Sent.
//
// Security considerations
//   * None beyond can_bus.hpp: nothing leaves the process.

#include <chrono>
#include <cstddef>
#include <deque>
#include <memory>
#include <string>
#include <variant>
#include <vector>

#include "pmu/transport/can_bus.hpp"
#include "pmu/transport/clock.hpp"
#include "pmu/transport/filters.hpp"
#include "pmu/transport/unique_fd.hpp"

namespace pmu::transport {

namespace detail {
struct SimShared;
}

class SimBus;

struct SimBusOptions {
  std::vector<IdFilter> filters;    // empty: every frame
  std::size_t queue_limit = 65536;  // frames waiting for drain() before the endpoint drops
};

class SimulatedNetwork {
 public:
  // `clock` must outlive the network and every endpoint attached to it.
  explicit SimulatedNetwork(const Clock& clock);
  ~SimulatedNetwork();
  SimulatedNetwork(const SimulatedNetwork&) = delete;
  SimulatedNetwork& operator=(const SimulatedNetwork&) = delete;
  SimulatedNetwork(SimulatedNetwork&&) noexcept = default;
  SimulatedNetwork& operator=(SimulatedNetwork&&) noexcept = default;

  // A new endpoint named `name`. Endpoints may outlive the network object (they share its
  // state); a destroyed endpoint simply stops receiving.
  std::unique_ptr<SimBus> attach(const std::string& name, SimBusOptions options = {});

  void set_state(BusState state);
  BusState state() const;
  void drop_next(std::size_t frames);
  std::size_t endpoint_count() const;

 private:
  std::shared_ptr<detail::SimShared> shared_;
};

class SimBus final : public CanBus {
  struct Private {
    explicit Private() = default;
  };

 public:
  // Public for make_unique; use SimulatedNetwork::attach().
  SimBus(Private, std::shared_ptr<detail::SimShared> shared, std::string name, SimBusOptions options);
  ~SimBus() override;

  const std::string& name() const noexcept override { return name_; }
  int fd() const noexcept override { return wake_fd_.get(); }
  DrainResult drain(BusHandler& handler) override;
  // Never waits: a simulated bus has no transmit queue to fill.
  SendResult send(const codec::CanFrame& frame, std::chrono::milliseconds max_wait) override;
  BusState state() const noexcept override;
  BusCounters counters() const noexcept override;
  // Nothing to do: a simulated bus never disappears.
  void maintain(std::chrono::steady_clock::time_point now) override;

 private:
  friend class SimulatedNetwork;
  using Pending = std::variant<ReceivedFrame, BusEvent>;

  // Both called with the network mutex held.
  void deliver_locked(const ReceivedFrame& frame);
  void push_locked(Pending item);

  std::shared_ptr<detail::SimShared> shared_;
  std::string name_;
  SimBusOptions options_;
  UniqueFd wake_fd_;
  // Guarded by the network mutex.
  std::deque<Pending> queue_;
  std::size_t queued_frames_ = 0;
  BusCounters counters_;
};

}  // namespace pmu::transport
