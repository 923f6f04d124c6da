// The verified engine start (engine_start.hpp): the decision, then its runner on a session.
#include "pmu/dispatch/engine_start.hpp"

#include <cstdio>
#include <memory>

#include "pmu/codec/encode.hpp"
#include "pmu/dispatch/command_reply.hpp"

namespace pmu::service {
namespace {

using namespace std::chrono;

// The longest CT a unit can hold (v1.9 5.16: 25.5 s); a unit with CT 0 never lets go by
// itself, so the service gives it no longer than any other.
constexpr double kLongestCrankingTime = 25.5;
// Table 6: the top of the 16 bits is no reading.
constexpr std::uint16_t kNoReading = 65535;

// Seconds with one decimal, as the replies quote them.
std::string tenths(double seconds) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.1f", seconds);
  return buf;
}

}  // namespace

std::optional<std::string> refuse_start(const codec::Status& s, std::optional<codec::FirmwareVersion> fw,
                                        const EngineSettings& engine) {
  if (s.generator_rpm != kNoReading && s.generator_rpm >= engine.running_rpm)
    return "engine already running: " + std::to_string(s.generator_rpm) + " rpm (running from " +
           std::to_string(engine.running_rpm) + " rpm)";
  if (s.thermal_shutdown) return std::string("the PMU is in thermal shutdown");
  if (s.interpretation.bit6 == codec::Bit6Meaning::SoaShutdown && s.soa_shutdown)
    return std::string("the PMU is in safe-operating-area shutdown");
  if (codec::supports(fw, codec::Feature::StarterReadyFlag) && !s.starter_ready)
    return std::string("the engine starter is not ready");
  return std::nullopt;
}

EngineStartWatch::EngineStartWatch(const EngineSettings& engine, const EngineStartTiming& timing, double cranking_time,
                                   SteadyTime sent)
    : engine_(engine),
      timing_(timing),
      cranking_time_(cranking_time > 0 ? cranking_time : kLongestCrankingTime),
      sent_(sent),
      deadline_(sent + duration_cast<SteadyTime::duration>(duration<double>(cranking_time_)) + engine.running_hold +
                timing.margin) {}

double EngineStartWatch::seconds_since_sent(SteadyTime now) const { return duration<double>(now - sent_).count(); }

std::optional<Verdict> EngineStartWatch::on_rpm(std::uint16_t rpm, SteadyTime now) {
  const std::uint16_t speed = rpm == kNoReading ? 0 : rpm;
  last_rpm_ = speed;
  read_any_ = true;
  if (speed < engine_.running_rpm) {
    running_since_.reset();
    return std::nullopt;
  }
  if (!running_since_) running_since_ = now;
  if (now - *running_since_ < engine_.running_hold) return std::nullopt;
  return Verdict{CommandResult::Completed,
                 "engine running: " + std::to_string(speed) + " rpm for " +
                     tenths(duration<double>(now - *running_since_).count()) + " s, " +
                     tenths(seconds_since_sent(now)) + " s after the start",
                 static_cast<double>(speed), std::to_string(speed)};
}

std::optional<Verdict> EngineStartWatch::on_time(SteadyTime now) const {
  if (now < deadline_) return std::nullopt;
  return Verdict{CommandResult::Failed,
                 "no start: rpm " + std::to_string(last_rpm_) + " after " + tenths(seconds_since_sent(now)) +
                     " s (cranking time " + tenths(cranking_time_) + " s)",
                 static_cast<double>(last_rpm_), ""};
}

std::optional<Verdict> EngineStartWatch::progress(SteadyTime now) {
  if (last_progress_ && now - *last_progress_ < timing_.progress_every) return std::nullopt;
  last_progress_ = now;
  const char* phase = running_since_ ? "running, holding" : "cranking";
  Verdict v{CommandResult::InProgress,
            std::string(phase) + ": " + tenths(seconds_since_sent(now)) + " s of up to " + tenths(cranking_time_) +
                " s",
            std::nullopt, ""};
  if (read_any_) {
    v.reason += ", " + std::to_string(last_rpm_) + " rpm";
    v.value = last_rpm_;
  }
  return v;
}

Verdict EngineStartWatch::cancelled(const std::string& stop_request_id, SteadyTime now) const {
  return {CommandResult::Failed,
          "cancelled by engine stop (request " + stop_request_id + ") " + "after " + tenths(seconds_since_sent(now)) +
              " s at rpm " + std::to_string(last_rpm_),
          static_cast<double>(last_rpm_), ""};
}

namespace {

// One start, owned by the callbacks of its pending step and timers and by the session's
// engine-start slot; every path ends in conclude(), once.
class StartRun : public std::enable_shared_from_this<StartRun> {
 public:
  StartRun(DeviceSession& session, const CommandRequest& request, const DeviceFacts& device, const Timeouts& timeouts,
           const EngineStartTiming& timing, ReplyFn reply)
      : session_(session),
        request_(request),
        device_(device),
        timing_(timing),
        retries_(timeouts.retries),
        reply_(std::move(reply)) {}

  void start(SteadyTime now) {
    std::weak_ptr<StartRun> weak = shared_from_this();
    session_.set_engine_start(
        DeviceSession::EngineStartInProgress{request_.request_id, [weak](const std::string& stop_id, SteadyTime at) {
                                               if (auto self = weak.lock()) self->on_stop(stop_id, at);
                                             }});
    // Step 0, the check: a fresh 0x04, behind the device's queue and bound by the expiry.
    // Every frame of the start goes to the unit's address when it is made (a move readdresses
    // those queued): the start verifies this unit wherever it answers (docs/safety.md H10).
    Request r;
    r.frame = *codec::encode_get(codec::PacketId::Status, session_.key().address);
    r.reply = codec::PacketId::Status;
    r.retries = retries_;
    r.expires = request_.expires;
    r.done = [self = shared_from_this()](const RequestOutcome& o) { self->on_check(o); };
    session_.submit(std::move(r), now);
  }

 private:
  void on_check(const RequestOutcome& o) {
    if (done_ || !succeeded(o, "status get")) return;
    const auto* status = std::get_if<codec::Status>(&o.reply->payload);
    if (!status) return conclude({CommandResult::Failed, "the status answer carries no status", {}, ""});
    if (auto why = refuse_start(*status, device_.firmware, session_.settings().engine))
      return conclude({CommandResult::Denied, *why, {}, ""});
    // Bound by the expiry too: the check's answer may come after it (a resent get), and a
    // start its caller gave up on must not crank (docs/safety.md H5, H9).
    Request r;
    r.frame = *codec::encode_engine_start(session_.key().address);
    r.expires = request_.expires;
    r.done = [self = shared_from_this()](const RequestOutcome& sent) { self->on_sent(sent); };
    session_.submit_front(std::move(r), session_.now());
  }

  void on_sent(const RequestOutcome& o) {
    if (done_ || !succeeded(o, "engine start")) return;
    const auto now = session_.now();
    watch_.emplace(session_.settings().engine, timing_, device_.cranking_time, now);
    report_progress(now);
    schedule_poll(now);
    session_.at(watch_->deadline(), [self = shared_from_this()](SteadyTime t) { self->on_deadline(t); });
  }

  void schedule_poll(SteadyTime now) {
    session_.at(now + timing_.poll, [self = shared_from_this()](SteadyTime t) { self->poll(t); });
  }

  void poll(SteadyTime now) {
    if (done_) return;
    // Ahead of the queue: the speed must be read on time whatever else waits for the unit.
    Request r;
    r.frame = *codec::encode_get(codec::PacketId::Status, session_.key().address);
    r.reply = codec::PacketId::Status;
    r.retries = retries_;
    r.done = [self = shared_from_this()](const RequestOutcome& o) { self->on_poll(o); };
    session_.submit_front(std::move(r), now);
  }

  void on_poll(const RequestOutcome& o) {
    if (done_) return;
    const auto now = session_.now();
    if (o.status != RequestStatus::Answered) {
      stop_cranking();
      return conclude({CommandResult::Timeout,
                       "device " + std::to_string(session_.key().address) +
                           " stopped answering while its engine was starting; stop sent in case it still cranks",
                       {},
                       ""});
    }
    if (const auto* status = std::get_if<codec::Status>(&o.reply->payload)) {
      if (auto v = watch_->on_rpm(status->generator_rpm, now)) return conclude(std::move(*v));
    }
    if (auto v = watch_->on_time(now)) return fail_in_time(std::move(*v));
    report_progress(now);
    schedule_poll(now);
  }

  void on_deadline(SteadyTime now) {
    if (done_) return;
    if (auto v = watch_->on_time(now)) fail_in_time(std::move(*v));
  }

  void fail_in_time(Verdict v) {
    stop_cranking();
    conclude(std::move(v));
  }

  void on_stop(const std::string& stop_id, SteadyTime now) {
    if (done_) return;
    if (watch_)
      conclude(watch_->cancelled(stop_id, now));
    else
      conclude({CommandResult::Failed,
                "cancelled by engine stop (request " + stop_id + ") before the start was sent",
                {},
                ""});
  }

  // The unit's CT should have ended the cranking; a CT of 0 never does, and a starter left
  // turning an engine that will not fire is what the stop exists for (v1.9 5.23). Sent at
  // once to where the unit is now, as an ENGINE_STOP is (docs/safety.md H4, H5).
  void stop_cranking() {
    (void)session_.send_urgent(*codec::encode_engine_stop(session_.key().address), session_.now());
  }

  void report_progress(SteadyTime now) {
    if (auto v = watch_->progress(now)) send(*v);
  }

  bool succeeded(const RequestOutcome& o, const char* what) {
    switch (o.status) {
      case RequestStatus::Answered:
      case RequestStatus::Sent: return true;
      case RequestStatus::Expired:
        conclude({CommandResult::Rejected, "expired before it could be sent", {}, ""});
        break;
      case RequestStatus::SendFailed:
        conclude({CommandResult::Failed,
                  std::string("bus refused the ") + what + ": " + std::string(transport::to_string(o.send.status)),
                  {},
                  ""});
        break;
      case RequestStatus::Timeout:
        conclude({CommandResult::Timeout,
                  "device " + std::to_string(session_.key().address) + " did not answer the " + what + " after " +
                      std::to_string(retries_ + 1) + " tries",
                  {},
                  ""});
        break;
    }
    return false;
  }

  void conclude(Verdict v) {
    if (done_) return;
    done_ = true;
    if (session_.engine_start() && session_.engine_start()->request_id == request_.request_id)
      session_.set_engine_start(std::nullopt);
    send(v);
  }

  void send(const Verdict& v) {
    CommandReplyData d = make_reply(request_, v.result, v.reason);
    if (v.value) {
      d.has_value = true;
      d.value = *v.value;
    }
    d.value_text = v.value_text;
    reply_(d);
  }

  DeviceSession& session_;
  CommandRequest request_;
  DeviceFacts device_;
  EngineStartTiming timing_;
  unsigned retries_;
  ReplyFn reply_;
  std::optional<EngineStartWatch> watch_;
  bool done_ = false;
};

}  // namespace

void run_engine_start(DeviceSession& session, const CommandRequest& r, const DeviceFacts& device,
                      const Timeouts& timeouts, const EngineStartTiming& timing, ReplyFn reply) {
  std::make_shared<StartRun>(session, r, device, timeouts, timing, std::move(reply))->start(session.now());
}

}  // namespace pmu::service
