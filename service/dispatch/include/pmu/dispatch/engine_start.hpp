#pragma once
// A verified engine start (interface.md 2.7). The PMU's start (0x24) only engages the
// starter, and nothing answers it; the starter lets go by itself when the engine fires,
// after the cranking time CT, or on a stop (0x25), which ends cranking only (v1.9 5.22,
// 5.23). So "the frame was sent" says nothing about the engine: the one sign that it runs
// is the generator speed of packet 0x04, and the service reads that packet before and
// after the start:
//
//   check   get 0x04. DENIED, with nothing more sent, while the generator already turns
//           at running speed, the starter is not ready (flag of firmware 1.12+), or the unit
//           is in thermal or SOA (firmware 1.16+) shutdown
//   crank   0x24; IN_PROGRESS at once and then at most once a second: phase, elapsed
//           time, rpm
//   watch   get 0x04 every poll period. COMPLETED once the speed has stayed at or above the
//           device's `engine_running_rpm` for `engine_running_hold`. FAILED "no start: ..."
//           when the deadline comes first: CT (25.5 s, the longest CT, when CT is 0, which
//           is no timeout on the unit) + hold + margin; a stop (0x25) then goes out in case
//           the starter still turns
//   stop    an ENGINE_STOP sent meanwhile ends the start: FAILED "cancelled by engine stop"
//           (the contract's results are a fixed enum: a new one would be a new major
//           version, interface.md 10.2)
//
// EngineStartWatch is the decision, pure, on times and speeds given to it (tests drive it
// with a fake clock); run_engine_start binds it to a DeviceSession.
//
// Lifetime: as command_executor.hpp: the steps and timers of a start keep a reference to
// `session` and are held by it, so they never outlive it.
// Threads: run_engine_start() and every reply on the thread of the bus worker that owns
// `session`.

#include <chrono>
#include <optional>
#include <string>

#include "pmu/codec/firmware.hpp"
#include "pmu/codec/messages.hpp"
#include "pmu/dispatch/command_plan.hpp"

namespace pmu::service {

struct EngineStartTiming {
  std::chrono::milliseconds poll{200};             // between gets of 0x04 while it is watched
  std::chrono::milliseconds progress_every{1000};  // IN_PROGRESS at most this often
  // Past CT + hold: room for the answer to the last poll and the speed to settle once the
  // starter lets go.
  std::chrono::milliseconds margin{1000};
};

// Why the unit must not be asked to start now, judged on a fresh 0x04 (its status flags are
// read as `fw` defines them); nullopt when it may.
std::optional<std::string> refuse_start(const codec::Status& status, std::optional<codec::FirmwareVersion> fw,
                                        const EngineSettings& engine);

// The outcome of one start, from the generator speeds read after the start was sent.
class EngineStartWatch {
 public:
  // `cranking_time`: the unit's CT in seconds; 0 means the unit never lets go by itself.
  EngineStartWatch(const EngineSettings& engine, const EngineStartTiming& timing, double cranking_time,
                   SteadyTime sent);

  // A speed read at `now` (65535, "no reading", counts as no speed): the final verdict once
  // the engine has run for the hold time.
  std::optional<Verdict> on_rpm(std::uint16_t rpm, SteadyTime now);
  // The final verdict once the deadline has passed without a start.
  std::optional<Verdict> on_time(SteadyTime now) const;
  // An IN_PROGRESS verdict when one is due at `now` (the first at once, then at most once per
  // `progress_every`); nullopt otherwise.
  std::optional<Verdict> progress(SteadyTime now);
  // The start ends because an engine stop was sent.
  Verdict cancelled(const std::string& stop_request_id, SteadyTime now) const;

  SteadyTime deadline() const noexcept { return deadline_; }
  double cranking_time() const noexcept { return cranking_time_; }

 private:
  double seconds_since_sent(SteadyTime now) const;

  EngineSettings engine_;
  EngineStartTiming timing_;
  double cranking_time_;
  SteadyTime sent_;
  SteadyTime deadline_;
  std::optional<SteadyTime> running_since_;
  std::uint16_t last_rpm_ = 0;
  bool read_any_ = false;
  std::optional<SteadyTime> last_progress_;
};

// Carries out an ENGINE_START on `session` as above. `reply` gets every IN_PROGRESS and then
// exactly one final reply.
void run_engine_start(DeviceSession& session, const CommandRequest& r, const DeviceFacts& device,
                      const Timeouts& timeouts, const EngineStartTiming& timing, ReplyFn reply);

}  // namespace pmu::service
