#include "pmu/session/device_session.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>

#include "pmu/codec/encode.hpp"

namespace pmu::service {
namespace {

using std::chrono::milliseconds;

bool is_telemetry(codec::PacketId p) noexcept { return static_cast<std::uint8_t>(p) <= 0x04; }

}  // namespace

DeviceSession::DeviceSession(DeviceKey key, DeviceConfig device, const Timeouts& timeouts, StateSink& sink,
                             SendFn send, SteadyTime now)
    : key_(std::move(key)), settings_(device), timeouts_(timeouts), sink_(sink), send_(std::move(send)),
      health_(now, timeouts),
      queue_(
          [this](const codec::CanFrame& f) {
            const auto sent = send_(f);
            if (sent.ok()) health_.on_sent();
            return sent;
          },
          timeouts.reply) {
  start_reading(now);
}

std::chrono::milliseconds DeviceSession::period() const noexcept {
  if (settings_.mode == TelemetryMode::Streaming) {
    const auto& pp = reading_.config().raw[static_cast<std::size_t>(codec::Parameter::PacketPeriod)];
    if (pp && *pp > 0) return codec::duration_of(codec::Parameter::PacketPeriod, *pp);
  }
  return settings_.period;
}

void DeviceSession::start_reading(SteadyTime now) {
  now_ = now;
  const std::uint64_t round = reading_.start();
  queue_.drop(kReadingTag);
  std::vector<Request> gets;
  for (const auto p : ReadingMachine::packets()) {
    Request r;
    r.frame = *codec::encode_get(p, key_.address);
    r.reply = p;
    r.retries = timeouts_.retries;
    r.tag = kReadingTag;
    r.done = [this, round](const RequestOutcome& o) { on_reading_done(o, round); };
    gets.push_back(std::move(r));
  }
  queue_.append(std::move(gets), now);
}

void DeviceSession::on_reading_done(const RequestOutcome& o, std::uint64_t round) {
  const auto retry_delay = std::max(period() * 2, milliseconds(1000));
  switch (reading_.on_result(round, o.status == RequestStatus::Answered, now_, retry_delay)) {
    case ReadingMachine::Progress::Ignored:
    case ReadingMachine::Progress::Pending: return;
    case ReadingMachine::Progress::Failed: queue_.drop(kReadingTag); return;
    case ReadingMachine::Progress::Done: break;
  }
  const auto& info = reading_.info();
  if (info)
    spdlog::info("{}/{}: serial {}, firmware {}.{}, configuration read", key_.bus, key_.address, info->serial_number,
                 info->firmware.firmware_major, info->firmware.firmware_minor);
  next_poll_ = now_;
  if (info) sink_.on_info(key_, *info);
  sink_.on_config(key_, reading_.config());
  if (settings_.mode == TelemetryMode::Streaming && settings_.configure_streaming) configure_streaming();
}

void DeviceSession::configure_streaming() {
  struct Want {
    codec::Parameter p;
    double value;
  };
  const Want wants[] = {
      {codec::Parameter::PacketPeriod, codec::duration_value(codec::Parameter::PacketPeriod, settings_.period)},
      {codec::Parameter::PacketsStreamed, static_cast<double>(settings_.groups)},
  };
  for (const auto& w : wants) {
    auto raw = codec::to_raw(w.p, w.value, firmware());
    if (!raw || reading_.config().raw[static_cast<std::size_t>(w.p)] == *raw) continue;
    Request set;
    set.frame = *codec::encode_parameter_reply(w.p, *raw, key_.address);
    submit(std::move(set), now_);
    Request get;
    get.frame = *codec::encode_get(codec::spec_of(w.p).packet, key_.address);
    get.reply = codec::spec_of(w.p).packet;
    get.retries = timeouts_.retries;
    submit(std::move(get), now_);
  }
}

void DeviceSession::submit(Request request, SteadyTime now) {
  now_ = now;
  queue_.push_back(std::move(request), now);
}

void DeviceSession::submit_front(Request request, SteadyTime now) {
  now_ = now;
  queue_.push_front(std::move(request), now);
}

void DeviceSession::on_frame(const codec::PmuId& id, const codec::CanFrame& frame, SteadyTime now,
                             WallTime received) {
  now_ = now;
  const bool was_offline = health_.offline();
  health_.on_frame(now);
  const auto m = codec::decode(frame, id, firmware());
  if (!m) {
    health_.on_decode_error();
    return;
  }
  if (was_offline) {
    // Back after OFFLINE: the unit may have been reset or replaced; read everything again.
    health_.on_reconnect();
    if (reading_.running() || reading_.failed()) start_reading(now);
  } else if (reading_.failed()) {
    start_reading(now);  // a failed round need not wait for its retry: the device speaks
  }
  if (m->request) {
    update_health(now, false);
    return;  // a zero-length get: the question, not an answer
  }
  if (is_telemetry(m->packet)) sink_.on_telemetry(key_, *m, received);
  absorb(*m);
  queue_.on_answer(*m, now);
  update_health(now, false);
}

void DeviceSession::absorb(const codec::PmuMessage& m) {
  const auto changes = reading_.absorb(m);
  if (!reading_.running()) return;  // published together once the reading round is done
  if (changes.info && reading_.info()) sink_.on_info(key_, *reading_.info());
  if (changes.config) sink_.on_config(key_, reading_.config());
}

void DeviceSession::move_to(std::uint16_t address, MoveCause cause, SteadyTime now) {
  now_ = now;
  const DeviceKey old = key_;
  HealthReport last = health_.report();
  last.state = HealthState::Offline;
  sink_.on_health(old, last);
  gone_.push_back({old, now + kGoneDelay});
  // Back at a key not yet disposed: it stays, with what follows published on it.
  gone_.erase(std::remove_if(gone_.begin(), gone_.end(), [address](const Gone& g) { return g.key.address == address; }),
              gone_.end());
  key_.address = address;
  alias_.reset();
  reading_.set_address(address);
  if (cause == MoveCause::ByItself) {
    if (health_.offline()) health_.on_reconnect();
    health_.on_frame(now);  // its serial answer, which the bus worker took as the evidence
    start_reading(now);
  }
  if (reading_.info()) sink_.on_info(key_, *reading_.info());
  sink_.on_config(key_, reading_.config());
  update_health(now, true);
}

void DeviceSession::on_bus_state(transport::BusState state, SteadyTime now) {
  if (health_.on_bus_state(state)) update_health(now, true);
}

void DeviceSession::tick(SteadyTime now) {
  now_ = now;
  while (!gone_.empty() && now >= gone_.front().at) {
    sink_.on_gone(gone_.front().key);
    gone_.erase(gone_.begin());
  }
  if (queue_.tick(now)) health_.on_timeout();
  run_timers(now);
  if (reading_.retry_due(now)) start_reading(now);
  if (reading_.running() && settings_.mode == TelemetryMode::Polling && now >= next_poll_) poll(now);
  update_health(now, false);
}

void DeviceSession::at(SteadyTime when, std::function<void(SteadyTime)> fn) { timers_.push_back({when, std::move(fn)}); }

void DeviceSession::run_timers(SteadyTime now) {
  // A timer's function may add timers: take the due ones out first, then call them.
  std::vector<Timer> due;
  for (auto it = timers_.begin(); it != timers_.end();) {
    if (it->at <= now) {
      due.push_back(std::move(*it));
      it = timers_.erase(it);
    } else {
      ++it;
    }
  }
  for (auto& t : due) t.fn(now);
}

void DeviceSession::on_engine_stop(const std::string& request_id, SteadyTime now) {
  now_ = now;
  if (!engine_start_) return;
  auto stop = std::move(engine_start_->on_stop);
  engine_start_.reset();
  if (stop) stop(request_id, now);
}

void DeviceSession::poll(SteadyTime now) {
  next_poll_ = std::max(next_poll_ + settings_.period, now);
  // A device slower than the poll period must not make polls pile up behind each other.
  if (queue_.waiting(kPollTag)) return;
  if (codec::supports(firmware(), codec::Feature::MeasurementRequest)) {
    Request r;
    r.frame = *codec::encode_measurement_request(settings_.groups, key_.address, firmware());
    r.tag = kPollTag;
    submit(std::move(r), now);
    return;
  }
  // Before 1.14 there is no 0x0F: one zero-length get per packet.
  for (std::uint8_t bit = 0; bit < 5; ++bit) {
    if (!(settings_.groups & (1u << bit))) continue;
    const auto packet = static_cast<codec::PacketId>(bit);
    Request r;
    r.frame = *codec::encode_get(packet, key_.address);
    r.reply = packet;
    r.tag = kPollTag;
    submit(std::move(r), now);
  }
}

void DeviceSession::update_health(SteadyTime now, bool force) {
  const auto u = health_.update(now, period(), force);
  const auto& report = health_.report();
  if (u.changed && report.state != HealthState::Unknown)
    spdlog::log(report.state == HealthState::Online ? spdlog::level::info : spdlog::level::warn,
                "{}/{}: {} (last frame {:.1f} s ago)", key_.bus, key_.address, to_string(report.state),
                report.last_frame_age);
  if (u.publish) sink_.on_health(key_, report);
}

}  // namespace pmu::service
