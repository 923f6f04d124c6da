#pragma once
// BusRunner: simulated PMUs, solar-boat batteries and MPPTs living on a CanBus. Each turn
// drains the bus into every PMU model, ticks every model, and lets them send what they emit.
// The batteries and MPPTs of one runner share one SolarPlant (the sun and the load), made
// when the first of them is added. Used by pmu-sim (on SocketCAN), by
// `pmu-service --bus sim` (on the in-process bus) and by integration tests.
//
// The turns are those of a transport::EventLoop (event_loop.hpp) watching the bus; a
// one-shot timer on it, re-armed before every wait, ends the wait at the models' earliest
// next_deadline(), and no wait is longer than 50 ms (start()) or run_once's max_wait.
//
// Lifetime: `clock` must outlive the runner, which keeps a reference (main.cpp's SystemClock
// outlives every BusRuntime). The runner owns its bus and its models, whose FrameSink refers
// back to it; the destructor stops the thread first.
//
// Thread safety: start() turns in its own thread; with_model(), with_battery() and
// with_mppt() run harness code (faults, plant changes) under the same lock, so a test can
// change a running simulator. A change of a model's deadline made while the loop waits is
// seen within one turn (<= 50 ms).

#include <chrono>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <thread>

#include "pmu/sim/battery_model.hpp"
#include "pmu/sim/mppt_model.hpp"
#include "pmu/sim/pmu_model.hpp"
#include "pmu/sim/solar_config.hpp"
#include "pmu/sim/solar_plant.hpp"
#include "pmu/transport/can_bus.hpp"
#include "pmu/transport/clock.hpp"
#include "pmu/transport/event_loop.hpp"

namespace pmu::sim {

class BusRunner final : private transport::BusHandler {
 public:
  // Throws std::system_error when the event loop cannot be set up (start-up).
  BusRunner(std::unique_ptr<transport::CanBus> bus, const transport::Clock& clock);
  ~BusRunner();  // stops the thread if running
  BusRunner(const BusRunner&) = delete;
  BusRunner& operator=(const BusRunner&) = delete;

  // Adds a PMU (before start(), or through with_model's lock). Throws for a broadcast address.
  void add(const DeviceConfig& config);
  // Adds (or replaces, by node / device) a battery or an MPPT, before start() or while
  // running. Throws std::invalid_argument for a config the model refuses (start-up).
  void add_battery(const BatterySimConfig& config);
  void add_mppt(const MpptSimConfig& config);

  // One turn: wait up to max_wait (or the next model deadline) for frames, then act.
  void run_once(std::chrono::milliseconds max_wait);
  void start();  // runs turns in a thread until stop()
  void stop();   // ends the thread's turns and joins it; nothing when not started

  // Runs `fn` on the model at `address` under the runner's lock; false if there is none.
  bool with_model(std::uint16_t address, const std::function<void(PmuModel&)>& fn);
  // The same for a battery (by node) or an MPPT (by device); their plant() is the shared one.
  bool with_battery(std::uint8_t node, const std::function<void(BatteryModel&)>& fn);
  bool with_mppt(std::uint8_t device, const std::function<void(MpptModel&)>& fn);
  transport::CanBus& bus() noexcept { return *bus_; }

 private:
  void on_frame(const transport::ReceivedFrame& frame) override;
  void on_event(const transport::BusEvent& event) override;
  // Arms the wake-up timer for the earliest model deadline (disarms it with no models).
  void wake_at_next_deadline();
  void end_turn();  // ticks every model and maintains the bus
  FrameSink sink();
  SolarPlant& plant();

  std::unique_ptr<transport::CanBus> bus_;
  const transport::Clock& clock_;
  std::map<std::uint16_t, std::unique_ptr<PmuModel>> models_;
  std::shared_ptr<SolarPlant> plant_;  // made by the first add_battery / add_mppt
  std::map<std::uint8_t, std::unique_ptr<BatteryModel>> batteries_;
  std::map<std::uint8_t, std::unique_ptr<MpptModel>> mppts_;
  std::recursive_mutex mutex_;
  transport::EventLoop loop_;
  transport::EventLoop::TimerId deadline_timer_ = 0;
  std::thread thread_;
};

}  // namespace pmu::sim
