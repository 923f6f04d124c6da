#include "pmu/service/device_session.hpp"

#include <spdlog/spdlog.h>

#include "pmu/codec/encode.hpp"

namespace pmu::service {
namespace {

using std::chrono::duration;
using std::chrono::milliseconds;

constexpr milliseconds kHealthInterval{1000};

bool is_telemetry(codec::PacketId p) noexcept { return static_cast<std::uint8_t>(p) <= 0x04; }

// The gets that read a device's identity and stored state, in the order they are sent.
std::vector<codec::PacketId> reading_packets() {
  std::vector<codec::PacketId> v{codec::PacketId::Serial, codec::PacketId::Firmware};
  for (const auto& s : codec::parameter_table()) v.push_back(s.packet);
  v.push_back(codec::PacketId::Outputs);
  v.push_back(codec::PacketId::Generation);
  return v;
}

}  // namespace

const char* to_string(HealthState s) noexcept {
  switch (s) {
    case HealthState::Unknown: return "UNKNOWN";
    case HealthState::Online: return "ONLINE";
    case HealthState::Stale: return "STALE";
    case HealthState::Offline: return "OFFLINE";
  }
  return "UNKNOWN";
}

DeviceSession::DeviceSession(DeviceKey key, DeviceConfig config, const Timeouts& timeouts, StateSink& sink,
                             SendFn send, SteadyTime now)
    : key_(std::move(key)), config_cfg_(config), timeouts_(timeouts), sink_(sink), send_(std::move(send)) {
  created_ = now;
  next_health_ = now;
  start_reading(now);
}

std::optional<codec::FirmwareVersion> DeviceSession::firmware() const noexcept {
  if (!info_ || !info_->firmware_known) return std::nullopt;
  return info_->firmware.version();
}

std::chrono::milliseconds DeviceSession::period() const noexcept {
  if (config_cfg_.mode == TelemetryMode::Streaming) {
    const auto& pp = config_.raw[static_cast<std::size_t>(codec::Parameter::PacketPeriod)];
    if (pp && *pp > 0) return milliseconds(*pp * 100);
  }
  return config_cfg_.period;
}

void DeviceSession::start_reading(SteadyTime now) {
  now_ = now;
  phase_ = Phase::Reading;
  reading_failed_ = false;
  for (auto it = queue_.begin(); it != queue_.end();)
    it = it->tag == kReadingTag ? queue_.erase(it) : std::next(it);
  const auto packets = reading_packets();
  reading_left_ = static_cast<unsigned>(packets.size());
  const std::uint64_t round = ++reading_round_;
  for (const auto p : packets) {
    Request r;
    r.frame = *codec::encode_get(p, key_.address);
    r.reply = p;
    r.retries = timeouts_.retries;
    r.tag = kReadingTag;
    r.done = [this, round](const RequestOutcome& o) { on_reading_done(o, round); };
    queue_.push_back(std::move(r));
  }
  send_next(now);
}

void DeviceSession::on_reading_done(const RequestOutcome& o, std::uint64_t round) {
  if (round != reading_round_ || phase_ != Phase::Reading || reading_failed_) return;
  if (o.status != RequestStatus::Answered) {
    // One silent get means a silent device: drop the rest of this round and try again
    // later instead of timing out every remaining get in turn.
    reading_failed_ = true;
    for (auto it = queue_.begin(); it != queue_.end();)
      it = it->tag == kReadingTag ? queue_.erase(it) : std::next(it);
    retry_reading_at_ = now_ + std::max(period() * 2, milliseconds(1000));
    return;
  }
  if (--reading_left_ > 0) return;
  phase_ = Phase::Running;
  if (info_)
    spdlog::info("{}/{}: serial {}, firmware {}.{}, configuration read", key_.bus, key_.address, info_->serial_number,
                 info_->firmware.firmware_major, info_->firmware.firmware_minor);
  next_poll_ = now_;
  if (info_) sink_.on_info(key_, *info_);
  sink_.on_config(key_, config_);
  if (config_cfg_.mode == TelemetryMode::Streaming && config_cfg_.configure_streaming) configure_streaming();
}

void DeviceSession::configure_streaming() {
  struct Want {
    codec::Parameter p;
    double value;
  };
  const Want wants[] = {
      {codec::Parameter::PacketPeriod, codec::duration_value(codec::Parameter::PacketPeriod, config_cfg_.period)},
      {codec::Parameter::PacketsStreamed, static_cast<double>(config_cfg_.groups)},
  };
  for (const auto& w : wants) {
    auto raw = codec::to_raw(w.p, w.value, firmware());
    if (!raw || config_.raw[static_cast<std::size_t>(w.p)] == *raw) continue;
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
  queue_.push_back(std::move(request));
  send_next(now);
}

void DeviceSession::submit_front(Request request, SteadyTime now) {
  now_ = now;
  queue_.push_front(std::move(request));
  send_next(now);
}

void DeviceSession::send_next(SteadyTime now) {
  now_ = now;
  if (pumping_) return;  // a done() callback submitted more: the loop below picks it up
  pumping_ = true;
  while (!in_flight_ && !queue_.empty()) {
    in_flight_ = std::move(queue_.front());
    queue_.pop_front();
    attempts_ = 1;
    if (in_flight_->expires && now > *in_flight_->expires) {
      RequestOutcome o;
      o.status = RequestStatus::Expired;
      Request done = std::move(*in_flight_);
      in_flight_.reset();
      if (done.done) done.done(o);
      continue;
    }
    const auto sent = send_(in_flight_->frame);
    if (sent.ok()) ++health_.frames_sent;
    if (sent.ok() && in_flight_->reply) {
      deadline_ = now + timeouts_.reply;
      break;
    }
    RequestOutcome o;
    o.status = sent.ok() ? RequestStatus::Sent : RequestStatus::SendFailed;
    o.send = sent;
    Request done = std::move(*in_flight_);
    in_flight_.reset();
    if (done.done) done.done(o);
  }
  pumping_ = false;
}

void DeviceSession::finish(RequestOutcome outcome, SteadyTime now) {
  Request done = std::move(*in_flight_);
  in_flight_.reset();
  if (done.done) done.done(outcome);
  send_next(now);
}

void DeviceSession::on_frame(const codec::CanFrame& frame, SteadyTime now, WallTime received) {
  now_ = now;
  const bool was_offline = health_.state == HealthState::Offline;
  last_rx_ = now;
  ++health_.frames_received;
  const auto m = codec::decode(frame, firmware());
  if (!m) {
    ++health_.decode_errors;
    return;
  }
  if (was_offline) {
    // Back after OFFLINE: the unit may have been reset or replaced; read everything again.
    ++health_.reconnects;
    if (phase_ == Phase::Running || reading_failed_) start_reading(now);
  } else if (phase_ == Phase::Reading && reading_failed_) {
    start_reading(now);
  }
  if (m->request) {
    update_health(now, false);
    return;  // a zero-length get: the question, not an answer
  }
  if (is_telemetry(m->packet)) sink_.on_telemetry(key_, *m, received);
  absorb(*m);
  if (in_flight_ && in_flight_->reply == m->packet) {
    RequestOutcome o;
    o.status = RequestStatus::Answered;
    o.reply = *m;
    finish(std::move(o), now);
  }
  update_health(now, false);
}

void DeviceSession::absorb(const codec::PmuMessage& m) {
  bool changed = false;
  auto set = [&changed](auto& slot, auto value) {
    if (slot != value) {
      slot = value;
      changed = true;
    }
  };
  if (const auto* p = std::get_if<codec::ParameterValue>(&m.payload)) {
    set(config_.raw[static_cast<std::size_t>(p->parameter)], std::optional<std::uint32_t>(p->raw));
  } else if (const auto* o = std::get_if<codec::OutputStates>(&m.payload)) {
    set(config_.outputs, std::optional<std::uint8_t>(o->mask));
  } else if (const auto* g = std::get_if<codec::GenerationState>(&m.payload)) {
    set(config_.generation_enabled, std::optional<bool>(g->enabled));
  } else if (const auto* s = std::get_if<codec::Status>(&m.payload)) {
    // The status packet streams the output and generation states too: keep config current.
    set(config_.outputs, std::optional<std::uint8_t>(s->outputs));
    set(config_.generation_enabled, std::optional<bool>(s->generation_enabled));
  } else if (const auto* sn = std::get_if<codec::SerialNumber>(&m.payload)) {
    if (!info_) info_ = InfoState{};
    if (info_->serial_number != sn->serial_number) {
      info_->serial_number = sn->serial_number;
      if (phase_ == Phase::Running) sink_.on_info(key_, *info_);
    }
    return;
  } else if (const auto* fw = std::get_if<codec::FirmwareInfo>(&m.payload)) {
    if (!info_) info_ = InfoState{};
    const auto& old = info_->firmware;
    info_->firmware_known = true;
    if (old.firmware_major != fw->firmware_major || old.firmware_minor != fw->firmware_minor ||
        old.build_year != fw->build_year || old.build_month != fw->build_month || old.build_day != fw->build_day) {
      info_->firmware = *fw;
      if (phase_ == Phase::Running) sink_.on_info(key_, *info_);
    }
    return;
  }
  if (changed && phase_ == Phase::Running) sink_.on_config(key_, config_);
}

void DeviceSession::on_bus_state(transport::BusState state, SteadyTime now) {
  if (health_.bus_state == state) return;
  health_.bus_state = state;
  update_health(now, true);
}

void DeviceSession::on_bus_counters(const transport::BusCounters& c) noexcept {
  health_.bus_errors = c.error_frames;
  health_.rx_dropped = c.rx_drops;
}

void DeviceSession::tick(SteadyTime now) {
  now_ = now;
  if (in_flight_ && now >= deadline_) {
    if (attempts_ <= in_flight_->retries) {
      ++attempts_;
      const auto sent = send_(in_flight_->frame);
      if (sent.ok()) ++health_.frames_sent;
      deadline_ = now + timeouts_.reply;
    } else {
      ++health_.timeouts;
      RequestOutcome o;
      o.status = RequestStatus::Timeout;
      finish(std::move(o), now);
    }
  }
  if (phase_ == Phase::Reading && reading_failed_ && now >= retry_reading_at_) start_reading(now);
  if (phase_ == Phase::Running && config_cfg_.mode == TelemetryMode::Polling && now >= next_poll_) poll(now);
  update_health(now, false);
}

void DeviceSession::poll(SteadyTime now) {
  next_poll_ = std::max(next_poll_ + config_cfg_.period, now);
  // A device slower than the poll period must not make polls pile up behind each other.
  for (const auto& r : queue_)
    if (r.tag == kPollTag) return;
  if (codec::supports(firmware(), codec::Feature::MeasurementRequest)) {
    Request r;
    r.frame = *codec::encode_measurement_request(config_cfg_.groups, key_.address, firmware());
    r.tag = kPollTag;
    submit(std::move(r), now);
    return;
  }
  // Before 1.14 there is no 0x0F: one zero-length get per packet.
  for (std::uint8_t bit = 0; bit < 5; ++bit) {
    if (!(config_cfg_.groups & (1u << bit))) continue;
    const auto packet = static_cast<codec::PacketId>(bit);
    Request r;
    r.frame = *codec::encode_get(packet, key_.address);
    r.reply = packet;
    r.tag = kPollTag;
    submit(std::move(r), now);
  }
}

void DeviceSession::update_health(SteadyTime now, bool force) {
  HealthState state = HealthState::Unknown;
  const double p = duration<double>(period()).count();
  if (last_rx_) {
    const double age = duration<double>(now - *last_rx_).count();
    health_.last_frame_age = age;
    state = age <= timeouts_.stale_periods * p     ? HealthState::Online
            : age <= timeouts_.offline_periods * p ? HealthState::Stale
                                                   : HealthState::Offline;
  } else {
    health_.last_frame_age = -1;
    const double since_start = duration<double>(now - created_).count();
    if (since_start > timeouts_.offline_periods * p) state = HealthState::Offline;
  }
  const bool changed = state != health_.state;
  if (changed && (state != HealthState::Unknown))
    spdlog::log(state == HealthState::Online ? spdlog::level::info : spdlog::level::warn, "{}/{}: {} (last frame {:.1f} s ago)",
                key_.bus, key_.address, to_string(state), health_.last_frame_age);
  health_.state = state;
  if (changed || force || now >= next_health_) {
    next_health_ = now + kHealthInterval;
    sink_.on_health(key_, health_);
  }
}

}  // namespace pmu::service
