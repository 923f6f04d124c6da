#pragma once
// BusWorker: one CAN bus and the PMUs on it, driven by one thread.
//
// The loop is a transport::EventLoop (event_loop.hpp). Each turn drains every pending frame
// from the bus (transport contract) and hands each to the session of its address, runs
// posted work, fires the loop's timers (bus maintenance every 250 ms, the discovery
// broadcast), then ticks every session (timeouts, polling, health); a turn waits at most
// 20 ms. Work from other threads (commands, shutdown) arrives through post(), which wakes
// the loop, so sessions are only ever touched on the worker's thread.
//
// Discovery: when the bus config asks for it, a broadcast firmware request (0x31 to 0xFFFF)
// is sent at start and every 10 s; every address that answers
// gets a session with the bus's discovery settings. New units plugged in later are found
// by the same periodic broadcast.
//
// A PMU that moves to another CAN address stays one session, filed under its new address at
// the end of the turn (DeviceSession::move_to says what is published). Our own verified set
// of CA moves it; so does the unit itself, when another tool or its panel changed its
// address: a unit is taken for the same one moved when, at an address no session serves,
// its serial answer (0x30, the one value a unit keeps for life, v1.9 5.25) equals the
// serial read from a session whose address has gone silent (STALE or OFFLINE). A unit that
// speaks at such an address (telemetry, or a serial or firmware answer: frames only a PMU
// sends) while a session with a known serial is silent is asked its serial, at most once per
// second per address (every 10 s once it answered another serial). A serial that matches a session that still speaks is two units
// claiming one serial: logged, nothing moves. While a session with a known serial is OFFLINE,
// a broadcast serial request every 10 s finds a polled unit that streams nothing.
//
// Batteries and MPPTs (CANopen frames, read-only): each configured one has a CanOpenSession
// from the start (so a silent one goes OFFLINE); with `listen_canopen`, one heard but not
// configured gets a session at its first frame, with a period of 1 s.
//
// Bus alarms: the worker owns the bus's AlarmSet (bus_error_passive, bus_off; source Bus,
// device 0), fed from the bus state at start and at every change, its delays run every turn.
//
// Lifetime: `clock` and `sink` must outlive the worker, which keeps references to both
// (main.cpp makes the SystemClock and the DdsPublisher before any worker and destroys the
// workers first). The worker owns its bus and its sessions, whose send callback refers back
// to it. The thread running run() must be stopped and joined before the worker is destroyed.
// Threads: run(), run_once() and every callback they make (the sessions, on_moved's function,
// the StateSink) on the worker's thread; post(), stop(), device_count() and progress() from
// any thread; on_moved() before run(); session(), addresses(), canopen_session() and bus()
// on the worker's thread or before run(); config() from any thread (it never changes).

#include <atomic>
#include <chrono>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "pmu/config/config.hpp"
#include "pmu/session/canopen_session.hpp"
#include "pmu/session/device_session.hpp"
#include "pmu/transport/can_bus.hpp"
#include "pmu/transport/clock.hpp"
#include "pmu/transport/event_loop.hpp"

namespace pmu::service {

class BusWorker final : private transport::BusHandler {
 public:
  // Throws std::system_error when the event loop cannot be set up (start-up).
  BusWorker(BusConfig config, std::unique_ptr<transport::CanBus> bus, const transport::Clock& clock,
            const Timeouts& timeouts, StateSink& sink);
  ~BusWorker();
  BusWorker(const BusWorker&) = delete;
  BusWorker& operator=(const BusWorker&) = delete;

  // One turn of the loop: waits up to `max_wait` (at most 20 ms) for the bus, posted work
  // or a timer, then drains, runs posted work and due timers, and ticks sessions. Returns
  // the number of frames.
  std::size_t run_once(std::chrono::milliseconds max_wait);
  // Runs turns until stop() is called (from any thread).
  void run();
  void stop();

  // Runs `fn` on the worker's thread at its next turn. Thread-safe.
  void post(std::function<void()> fn);
  // As post(), ahead of the turn's frames and of all work posted with post(): an engine stop
  // waits behind no other command (docs/safety.md H4). Thread-safe.
  void post_urgent(std::function<void()> fn);

  // A PMU session moved from one address to another (after the move; worker thread). Also,
  // with from == to == first, a session expecting a recorded serial that read its unit at its
  // configured address: the unit is where the config says.
  struct Moved {
    std::string bus;
    std::uint16_t from = 0, to = 0;
    std::uint16_t first = 0;  // where it started: the config's address, or discovery's
    std::optional<std::uint16_t> serial;
    std::string config_line;  // "FILE:LINE" of its `address:`; empty when not configured
  };
  // Called on the worker's thread after every move. Set before run().
  void on_moved(std::function<void(const Moved&)> fn) { moved_ = std::move(fn); }
  // Every PMU session's reading gets asked again (DeviceSession::repeat_reading_gets), for a
  // hot-standby peer that has just joined. Worker thread.
  void repeat_readings();
  // Runs `fn` on the worker's thread every `period` from the first turn on, with the loop's
  // reading of the clock: work that must share the bus's thread (a hot-standby pair's
  // heartbeat). Before run().
  void every(std::chrono::milliseconds period, std::function<void(std::chrono::steady_clock::time_point)> fn);

  // Worker thread only (or before run()):
  // The session serving `address` now (a session that moved this turn included).
  DeviceSession* session(std::uint16_t address);
  // The session of the unit that last left `address` for another, while no session serves
  // `address`: where a stop addressed to a unit that just moved must go (interface.md 2.6).
  DeviceSession* session_moved_from(std::uint16_t address);
  std::vector<std::uint16_t> addresses() const;
  // The battery (node) or MPPT (device id) session, or null.
  CanOpenSession* canopen_session(DeviceKind kind, std::uint16_t id);

  // Devices served now (configured and discovered). Thread-safe: sessions_ belongs to the
  // worker thread, so the worker publishes its size here after every change, for the
  // main thread's status line.
  std::size_t device_count() const noexcept { return device_count_.load(std::memory_order_relaxed); }
  const BusConfig& config() const noexcept { return config_; }
  transport::CanBus& bus() noexcept { return *bus_; }
  // The bus's own alarms. Worker thread only (or before run()).
  const alarms::AlarmSet& bus_alarms() const noexcept { return bus_alarms_.set(); }
  // As DeviceSession::acknowledge_alarm, at the worker's clock's time.
  alarms::AckResult acknowledge_bus_alarm(alarms::Code code) {
    return bus_alarms_.acknowledge(code, clock_.steady_now(), clock_.system_now());
  }

  // Incremented every turn: the watchdog feeds only while this moves. Thread-safe.
  std::uint64_t progress() const noexcept { return progress_.load(std::memory_order_relaxed); }

 private:
  void on_frame(const transport::ReceivedFrame& frame) override;
  void on_event(const transport::BusEvent& event) override;
  DeviceSession& add_session(const DeviceConfig& device);
  CanOpenSession& add_canopen_session(DeviceKey key, std::chrono::milliseconds period,
                                      const alarms::DeviceSettings& alarms = {});
  void feed_bus_alarms(transport::BusState state);
  void on_canopen_frame(const transport::ReceivedFrame& frame);
  void discover();  // the broadcast firmware request (a loop timer, when config_.discover)
  void rekey_moved_sessions();
  void confirm_expected(DeviceSession& s);
  // A PMU frame from an address no session serves: a moved unit found by its serial, a new
  // one found by discovery, or nothing. Returns the session the frame belongs to, if any.
  DeviceSession* on_stranger(const codec::PmuId& id, const transport::ReceivedFrame& rx);
  DeviceSession* session_with_serial(std::uint16_t serial);  // not one mid-way through our own move
  bool any_silent_known(HealthState at_least) const;
  void search();    // the broadcast serial request while a known session is OFFLINE (a loop timer)
  void end_turn();  // ticks every session; the watchdog's progress

  BusConfig config_;
  std::unique_ptr<transport::CanBus> bus_;
  const transport::Clock& clock_;
  Timeouts timeouts_;
  StateSink& sink_;
  std::map<std::uint16_t, std::unique_ptr<DeviceSession>> sessions_;
  std::map<std::pair<DeviceKind, std::uint16_t>, std::unique_ptr<CanOpenSession>> canopen_;
  std::map<std::uint16_t, std::chrono::steady_clock::time_point> asked_;  // stranger -> next serial get allowed
  std::map<std::uint16_t, std::uint16_t> left_;  // an address a unit moved away from -> where it is now
  std::function<void(const Moved&)> moved_;
  AlarmFeed bus_alarms_;

  transport::EventLoop loop_;
  std::size_t turn_frames_ = 0;  // frames drained in the run_once() turn in progress
  std::atomic<std::uint64_t> progress_{0};
  std::atomic<std::size_t> device_count_{0};
};

}  // namespace pmu::service
