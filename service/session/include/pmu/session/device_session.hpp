#pragma once
// DeviceSession: the service's conversation with one PMU, composed of three parts:
//   RequestQueue     request/response correlation: one request in flight, the rest queued
//                    in order, answers matched by packet id, retries, timeouts, expiry
//                    (request_queue.hpp);
//   ReadingMachine   the device's identity and stored values and the rounds of gets that
//                    read them (reading_machine.hpp);
//   HealthTracker    ONLINE / STALE / OFFLINE from frame age, and the counters
//                    (health_tracker.hpp).
// The session wires them together and owns what spans them: publishing, polling, and the
// streaming set-up.
//
// Life of a session: READING (serial, firmware, every stored parameter, outputs, generation)
// -> publishes info and config -> RUNNING (streaming: listen; polling: ask every period,
// with 0x0F from firmware 1.14 and single gets before). Health follows frame age:
// ONLINE while a frame came within stale_periods x period, STALE until offline_periods x
// period, then OFFLINE; a frame after OFFLINE re-reads info and config (the unit may have
// been swapped or reset).
//
// Frames arrive with their id already parsed (the bus worker parses it once to route the
// frame); the session decodes the payload with the firmware it knows, so firmware-
// dependent packets are read right from the first frame after the firmware is known.
//
// Alarms (alarms room, interface.md 1.6): the session owns the unit's AlarmSet, built from
// its config settings, feeds it from every decoded telemetry packet and from its health,
// and reports every change of state through StateSink::on_alarm. What feeds which code, and
// the rules for inputs the PMU does not report as such (an absent battery, a generator that
// does not produce, an engine that stops by itself), are in device_session.cpp at
// feed_alarms().
//
// No I/O and no clock of its own: frames go out through a send callback, time comes in
// through every call (steady for waits, wall for what is reported), so tests drive it with a
// fake clock.
//
// Lifetime: `sink` must outlive the session, which keeps a reference (the DdsPublisher in the
// daemon: main.cpp makes it before the bus workers that own the sessions, and destroys it
// after them). `send` may refer to the session's owner, the BusWorker. The command runs
// queued on the session keep a reference to it; they live in its request queue, so never
// longer than the session.
// Threads: no lock and no thread of its own: every member on the thread of the bus worker
// that owns it; other threads reach it only through BusWorker::post().

#include <chrono>
#include <cstdint>
#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "pmu/codec/decode.hpp"
#include "pmu/config/config.hpp"
#include "pmu/session/alarm_feed.hpp"
#include "pmu/session/state_sink.hpp"
#include "pmu/session/health_tracker.hpp"
#include "pmu/session/reading_machine.hpp"
#include "pmu/session/request_queue.hpp"

namespace pmu::service {

class DeviceSession {
 public:
  using SendFn = std::function<transport::SendResult(const codec::CanFrame&)>;

  DeviceSession(DeviceKey key, DeviceConfig device, const Timeouts& timeouts, StateSink& sink, SendFn send,
                SteadyTime now);

  const DeviceKey& key() const noexcept { return key_; }
  // A frame from this device's address (or alias) whose id the caller parsed into `id`.
  void on_frame(const codec::PmuId& id, const codec::CanFrame& frame, SteadyTime now, WallTime received);
  // A frame from this address that did not decode.
  void on_decode_error() noexcept { health_.on_decode_error(); }
  void on_bus_state(transport::BusState state, SteadyTime now);
  void on_bus_counters(const transport::BusCounters& counters) noexcept { health_.on_bus_counters(counters); }
  // Timeouts, polling, health, alarm delays. Call at least every few tens of ms; `wall` is
  // the wall time of `now`, for the alarms that change in it.
  void tick(SteadyTime now, WallTime wall);

  // Queues a request behind those already waiting.
  void submit(Request request, SteadyTime now);
  // Queues a request ahead of everything waiting (a read-back, an engine start's speed poll).
  void submit_front(Request request, SteadyTime now);

  // Sends `frame`, a frame for this unit that nothing answers (an engine stop), at once: not
  // queued, neither behind the requests waiting nor behind the one in flight, which goes on
  // waiting for its answer (docs/safety.md H4). It goes to the address the unit is at now,
  // whatever address `frame` names; while an address change of ours is under way (alias),
  // to both addresses, as the unit answers at one of them (interface.md 2.6).
  struct UrgentSent {
    transport::SendResult result;          // the first refusal, else Sent
    std::vector<std::uint16_t> addresses;  // where it went, this unit's address first
  };
  UrgentSent send_urgent(const codec::CanFrame& frame, SteadyTime now);
  // An engine stop sent after the unit was last heard at its address may never have reached
  // it: the unit may have moved by itself (interface.md 2.6). Found at a new address within
  // this time of that stop, it is sent the stop again there (docs/safety.md H4, H5): longer
  // than the longest cranking time (25.5 s, v1.9 5.16) plus the time to find a moved unit
  // with the default settings (3 periods of silence, then its serial).
  static constexpr std::chrono::seconds kStopFollowsFor{30};
  // Reads identity and every stored value again (after a reset).
  void reread(SteadyTime now) { start_reading(now); }
  // The reading round's gets asked again without starting a round: the answers keep the stored
  // values current as any answer does, and nothing this session serves pauses. A bus owner does
  // it for a hot-standby peer that has just joined and cannot ask itself.
  void repeat_reading_gets(SteadyTime now);

  // Calls `fn` from tick() once `at` has come (within the worker's tick, 20 ms). A command
  // that waits on the device's behaviour rather than on one answer (an engine start, which
  // watches the generator speed) paces itself with these. Dropped with the session.
  void at(SteadyTime when, std::function<void(SteadyTime)> fn);

  // The engine start being verified on this unit, if any (dispatch's engine_start.hpp). Its
  // `on_stop` ends it when an engine stop is sent meanwhile; the session only holds it so that
  // the stop, and a second start, find it.
  struct EngineStartInProgress {
    std::string request_id;
    std::function<void(const std::string& stop_request_id, SteadyTime now)> on_stop;
  };
  void set_engine_start(std::optional<EngineStartInProgress> start) { engine_start_ = std::move(start); }
  const std::optional<EngineStartInProgress>& engine_start() const noexcept { return engine_start_; }
  // An engine stop (`request_id`) is on its way to this unit: ends the start in progress, and
  // the engine's next fall below running speed is not uncommanded_engine_stop.
  void on_engine_stop(const std::string& request_id, SteadyTime now);

  // During a CAN address change, frames from `alias` belong to this session too; move_to()
  // moves the session to its new address once the change is verified.
  void set_alias(std::optional<std::uint16_t> alias) noexcept { alias_ = alias; }
  std::optional<std::uint16_t> alias() const noexcept { return alias_; }

  enum class MoveCause : std::uint8_t {
    Commanded,  // our own set of CA (0x1B), read back at the new address
    ByItself,   // its serial (0x30) answered at `address` while its old address is silent
  };
  // The unit answers at `address` now. The old key gets its health once more, OFFLINE,
  // and is gone (StateSink::on_gone) kGoneDelay later, unless the unit is back there by
  // then; the new key gets the identity and configuration carried over (CA = `address`)
  // and the health, at once. ByItself also counts as a frame heard now and reads
  // everything again: whoever changed the address may have changed more. The bus worker
  // files the session under its new key at the end of its turn.
  void move_to(std::uint16_t address, MoveCause cause, SteadyTime now);
  // Between the old key's OFFLINE and its disposal: a state reader keeps one sample per
  // instance, and a disposal that comes first replaces the OFFLINE it has not taken yet.
  // Short, so that `list` shows the new key alone well within the usual packet periods.
  static constexpr std::chrono::milliseconds kGoneDelay{250};
  // The serial this PMU has when none was read yet: what the service recorded before it
  // restarted (moved_addresses.hpp), so a unit that moved is followed before it is heard.
  void expect_serial(std::optional<std::uint16_t> serial) noexcept { expected_serial_ = serial; }
  bool expects_serial() const noexcept { return expected_serial_.has_value(); }
  // The serial read from the unit, else the one expected.
  std::optional<std::uint16_t> serial() const noexcept {
    if (reading_.info()) return reading_.info()->serial_number;
    return expected_serial_;
  }
  // Where the session started (the config's address, or where discovery found it).
  std::uint16_t first_address() const noexcept { return settings_.address; }
  const DeviceConfig& settings() const noexcept { return settings_; }

  // The latest time any call brought: callbacks that queue follow-up work use it.
  SteadyTime now() const noexcept { return now_; }
  const ConfigState& config_state() const noexcept { return reading_.config(); }
  const std::optional<InfoState>& info() const noexcept { return reading_.info(); }
  std::optional<codec::FirmwareVersion> firmware() const noexcept { return reading_.firmware(); }
  const HealthReport& health() const noexcept { return health_.report(); }
  const alarms::AlarmSet& alarms() const noexcept { return alarms_.set(); }
  // An operator acknowledged `code` (ACTIVE -> ACTIVE_ACKNOWLEDGED, CLEARED -> NORMAL).
  alarms::AckResult acknowledge_alarm(alarms::Code code, SteadyTime now, WallTime wall) {
    now_ = now;
    return alarms_.acknowledge(code, now, wall);
  }
  bool ready() const noexcept { return reading_.running(); }
  // The internal temperature (v1.9 table 5) of the latest temperatures packet, while that is
  // not stale (stale_periods x the period, as the health counts); nullopt when none came or
  // it is stale. The confirm rules judged by effect read it (policy.hpp's DeviceUse).
  std::optional<double> internal_temperature(SteadyTime now) const noexcept;
  std::size_t queued() const noexcept { return queue_.size(); }

 private:
  static constexpr int kReadingTag = 1;
  static constexpr int kPollTag = 2;
  static constexpr int kRepeatTag = 3;

  transport::SendResult send_one(const codec::CanFrame& frame);  // counted in the health when sent
  void start_reading(SteadyTime now);
  std::vector<Request> reading_gets(int tag) const;  // one get per packet of a reading round
  void on_reading_done(const RequestOutcome& outcome, std::uint64_t round);
  void configure_streaming();
  void poll(SteadyTime now);
  void run_timers(SteadyTime now);
  void absorb(const codec::PmuMessage& m);
  void update_health(SteadyTime now, bool force);
  std::chrono::milliseconds period() const noexcept;
  void feed_alarms(const codec::PmuMessage& m, SteadyTime now, WallTime wall);
  void feed_engine_alarms(SteadyTime now, WallTime wall);
  void feed_health_alarms(SteadyTime now, WallTime wall);

  DeviceKey key_;
  DeviceConfig settings_;  // the config file's settings for it; what the device stores: reading_.config()
  Timeouts timeouts_;
  StateSink& sink_;
  SendFn send_;

  HealthTracker health_;
  ReadingMachine reading_;
  RequestQueue queue_;

  std::optional<std::uint16_t> alias_;
  std::optional<std::uint16_t> expected_serial_;
  struct Gone {
    DeviceKey key;
    SteadyTime at;
  };
  std::vector<Gone> gone_;  // old keys to dispose, once due (tick)
  struct Timer {
    SteadyTime at;
    std::function<void(SteadyTime)> fn;
  };
  std::vector<Timer> timers_;  // at(); run by tick()
  std::optional<EngineStartInProgress> engine_start_;
  std::optional<SteadyTime> last_heard_;  // the last frame from the unit's address (or alias)
  std::optional<SteadyTime> last_stop_;   // the last engine stop sent to it (send_urgent)

  AlarmFeed alarms_;
  // What the alarms derived from more than one packet last heard; forgotten at OFFLINE.
  struct EngineView {
    std::optional<codec::Status> status;                                // the latest 0x04
    double generator_volts = std::numeric_limits<double>::quiet_NaN();  // the latest 0x00's
    bool running = false;                                               // the speed was at or above running_rpm
    bool stop_commanded = false;     // an engine stop was sent since it last came up to speed
    bool stopped_by_itself = false;  // it fell below running speed with no stop sent
  };
  EngineView engine_;
  struct Latest {
    double value = 0;
    SteadyTime at{};
  };
  std::optional<Latest> internal_temperature_;  // from the latest 0x03
  SteadyTime now_{};                            // the latest time any call brought
  SteadyTime next_poll_{};
};

}  // namespace pmu::service
