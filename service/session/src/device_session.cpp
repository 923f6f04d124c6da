#include "pmu/session/device_session.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <variant>

#include "pmu/codec/encode.hpp"
#include "pmu/codec/ids.hpp"

namespace pmu::service {
namespace {

using std::chrono::milliseconds;

bool is_telemetry(codec::PacketId p) noexcept { return static_cast<std::uint8_t>(p) <= 0x04; }

constexpr double kNotMeasured = std::numeric_limits<double>::quiet_NaN();

// A battery input with nothing connected reads about 0 V: v1.9 table 2 has no "absent"
// value, and the simulator takes a battery below 1 V as absent. Below 5 V the battery is
// taken as absent and its voltage as not measured (NaN), so a PMU with one battery raises no
// voltage alarm for the other, and an alarm already raised holds rather than clears when the
// battery is pulled. 5 V leaves room for what an open input picks up, and no 6S pack in use
// is that low (0.8 V a cell). A battery that goes absent raises nothing: the table has no
// code for it.
constexpr double kBatteryPresentVolts = 5.0;

double battery_volts(double measured) noexcept { return measured < kBatteryPresentVolts ? kNotMeasured : measured; }

}  // namespace

DeviceSession::DeviceSession(DeviceKey key, DeviceConfig device, const Timeouts& timeouts, StateSink& sink, SendFn send,
                             SteadyTime now)
    : key_(std::move(key)),
      settings_(device),
      timeouts_(timeouts),
      sink_(sink),
      send_(std::move(send)),
      health_(now, timeouts),
      queue_([this](const codec::CanFrame& f) { return send_one(f); }, timeouts.reply),
      alarms_(key_.bus, alarms::DeviceKind::Pmu, key_.address, device.alarms, sink) {
  start_reading(now);
}

std::chrono::milliseconds DeviceSession::period() const noexcept {
  if (settings_.mode == TelemetryMode::Streaming) {
    const auto& pp = reading_.config().raw[static_cast<std::size_t>(codec::Parameter::PacketPeriod)];
    if (pp && *pp > 0) return codec::duration_of(codec::Parameter::PacketPeriod, *pp);
  }
  return settings_.period;
}

std::optional<double> DeviceSession::internal_temperature(SteadyTime now) const noexcept {
  if (!internal_temperature_ || std::isnan(internal_temperature_->value)) return std::nullopt;
  const auto max_age = std::chrono::duration<double, std::milli>(period()) * timeouts_.stale_periods;
  if (now - internal_temperature_->at > max_age) return std::nullopt;
  return internal_temperature_->value;
}

std::vector<Request> DeviceSession::reading_gets(int tag) const {
  std::vector<Request> gets;
  for (const auto p : ReadingMachine::packets()) {
    Request r;
    r.frame = *codec::encode_get(p, key_.address);
    r.reply = p;
    r.retries = timeouts_.retries;
    r.tag = tag;
    gets.push_back(std::move(r));
  }
  return gets;
}

void DeviceSession::start_reading(SteadyTime now) {
  now_ = now;
  const std::uint64_t round = reading_.start();
  queue_.drop(kReadingTag);
  auto gets = reading_gets(kReadingTag);
  for (auto& r : gets) r.done = [this, round](const RequestOutcome& o) { on_reading_done(o, round); };
  queue_.append(std::move(gets), now);
}

void DeviceSession::repeat_reading_gets(SteadyTime now) {
  now_ = now;
  queue_.drop(kRepeatTag);
  queue_.append(reading_gets(kRepeatTag), now);
}

void DeviceSession::on_reading_done(const RequestOutcome& o, std::uint64_t round) {
  const auto retry_delay = std::max(period() * 2, milliseconds(1000));
  bool heard = false;
  switch (reading_.on_result(round, o.status == RequestStatus::Answered, now_, retry_delay)) {
    case ReadingMachine::Progress::Ignored:
    case ReadingMachine::Progress::Pending: return;
    case ReadingMachine::Progress::Failed:
      queue_.drop(kReadingTag);
      // Not the bus owner: the round is what was heard of the owner's own reading, if whole.
      if (o.send.status != transport::SendStatus::Fenced || !reading_.heard_all()) return;
      reading_.complete_from_heard();
      heard = true;
      break;
    case ReadingMachine::Progress::Done: break;
  }
  const auto& info = reading_.info();
  if (info)
    spdlog::info("{}/{}: serial {}, firmware {}.{}, configuration read", key_.bus, key_.address, info->serial_number,
                 info->firmware.firmware_major, info->firmware.firmware_minor);
  next_poll_ = now_;
  if (info) sink_.on_info(key_, *info);
  sink_.on_config(key_, reading_.config());
  // Streaming is set up by the owner that read the unit, not by one that only listened.
  if (!heard && settings_.mode == TelemetryMode::Streaming && settings_.configure_streaming) configure_streaming();
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

transport::SendResult DeviceSession::send_one(const codec::CanFrame& frame) {
  const auto sent = send_(frame);
  if (sent.ok()) health_.on_sent();
  return sent;
}

DeviceSession::UrgentSent DeviceSession::send_urgent(const codec::CanFrame& frame, SteadyTime now) {
  now_ = now;
  UrgentSent out;
  const auto id = codec::parse_id(frame.id, frame.extended);
  if (!id.id) {  // not a PMU frame: nothing to address
    out.result = send_one(frame);
    return out;
  }
  out.addresses.push_back(key_.address);
  if (alias_ && *alias_ != key_.address) out.addresses.push_back(*alias_);
  for (const auto address : out.addresses) {
    codec::CanFrame to = frame;
    to.id = codec::make_id(id.id->packet, address);
    const auto sent = send_one(to);
    if (!sent.ok() && out.result.ok()) out.result = sent;
  }
  if (id.id->packet == codec::PacketId::EngineStop) last_stop_ = now;
  return out;
}

void DeviceSession::on_frame(const codec::PmuId& id, const codec::CanFrame& frame, SteadyTime now, WallTime received) {
  now_ = now;
  last_heard_ = now;
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
    reading_.forget_heard();
    if (reading_.running() || reading_.failed()) start_reading(now);
  } else if (reading_.failed()) {
    start_reading(now);  // a failed round need not wait for its retry: the device speaks
  }
  if (m->request) {
    update_health(now, false);
    return;  // a zero-length get: the question, not an answer
  }
  if (is_telemetry(m->packet)) {
    sink_.on_telemetry(key_, *m, received);
    feed_alarms(*m, now, received);
  }
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
  alarms_.move_to(address);
  alias_.reset();
  reading_.set_address(address);
  // Whatever waits for the unit follows it: an engine start's speed polls go on reading this
  // unit, and nothing meant for it goes to the address it left (docs/safety.md H4, H10).
  queue_.readdress(old.address, address);
  if (cause == MoveCause::ByItself) {
    // A stop sent since it was last heard at the old address went where it no longer was.
    const bool stop_missed =
        last_stop_ && (!last_heard_ || *last_stop_ >= *last_heard_) && now - *last_stop_ <= kStopFollowsFor;
    if (health_.offline()) health_.on_reconnect();
    health_.on_frame(now);  // its serial answer, which the bus worker took as the evidence
    last_heard_ = now;
    if (stop_missed) {
      const auto sent = send_urgent(*codec::encode_engine_stop(address), now);
      spdlog::warn(
          "{}/{}: an engine stop was sent to address {} after the unit was last heard there: sent again "
          "at its new address ({})",
          key_.bus, address, old.address, transport::to_string(sent.result.status));
    }
    start_reading(now);
  }
  if (reading_.info()) sink_.on_info(key_, *reading_.info());
  sink_.on_config(key_, reading_.config());
  update_health(now, true);
}

void DeviceSession::on_bus_state(transport::BusState state, SteadyTime now) {
  if (health_.on_bus_state(state)) update_health(now, true);
}

void DeviceSession::tick(SteadyTime now, WallTime wall) {
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
  feed_health_alarms(now, wall);
  alarms_.tick(now, wall);
}

void DeviceSession::at(SteadyTime when, std::function<void(SteadyTime)> fn) {
  timers_.push_back({when, std::move(fn)});
}

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
  // Whatever the engine does next is what was asked. An engine that stopped by itself before
  // is now stopped on purpose too: its alarm clears at the next 0x04, and, critical, waits
  // for an acknowledgement.
  engine_.stop_commanded = true;
  engine_.stopped_by_itself = false;
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
    spdlog::log(report.state == HealthState::Online ? spdlog::level::info : spdlog::level::warn, "{}/{}: {} ({})",
                key_.bus, key_.address, to_string(report.state), last_frame_text(report.last_frame_age));
  if (u.publish) sink_.on_health(key_, report);
}

// What each decoded packet feeds (the codes: alarm_table.cpp; interface.md 1.6). A value the
// packet does not carry, or carries as "no sensor", is NaN: the alarm holds its state.
void DeviceSession::feed_alarms(const codec::PmuMessage& m, SteadyTime now, WallTime wall) {
  using alarms::Code;
  if (const auto* v = std::get_if<codec::Voltages>(&m.payload)) {
    const double a = battery_volts(v->battery_a);
    const double b = battery_volts(v->battery_b);
    alarms_.observe(Code::BatteryALowVoltage, a, now, wall);
    alarms_.observe(Code::BatteryACriticalVoltage, a, now, wall);
    alarms_.observe(Code::BatteryBLowVoltage, b, now, wall);
    alarms_.observe(Code::BatteryBCriticalVoltage, b, now, wall);
    engine_.generator_volts = v->generator;
    feed_engine_alarms(now, wall);
  } else if (const auto* t = std::get_if<codec::Temperatures>(&m.payload)) {
    internal_temperature_ = Latest{t->internal, now};
    alarms_.observe(Code::InternalOverTemperature, t->internal, now, wall);
    alarms_.observe(Code::StarterOverTemperature, t->starter, now, wall);
    alarms_.observe(Code::GeneratorOverTemperature, t->generator, now, wall);
    alarms_.observe(Code::BatteryAOverTemperature, t->battery_a, now, wall);
    alarms_.observe(Code::BatteryBOverTemperature, t->battery_b, now, wall);
  } else if (const auto* s = std::get_if<codec::Status>(&m.payload)) {
    alarms_.observe_flag(Code::ThermalShutdown, s->thermal_shutdown, now, wall);
    // Bit 6 is the start button before firmware 1.16: only a decode that knew the firmware
    // and read it as the SOA flag says anything about an SOA shutdown.
    if (s->interpretation.bit6 == codec::Bit6Meaning::SoaShutdown && s->interpretation.firmware_known)
      alarms_.observe_flag(Code::SoaShutdown, s->soa_shutdown, now, wall);
    alarms_.observe_flag(Code::PayloadShed, s->payload_shed, now, wall);
    // uncommanded_engine_stop: the engine "ran" while the generator speed (the engine's shaft,
    // table 6) was at or above the unit's engine.running_rpm, the speed that also verifies an
    // ENGINE_START. A fall below it with no engine stop sent since it came up to speed is the
    // engine stopping by itself; the condition holds until it is at speed again (restarted)
    // or a stop is sent. A start that fails never reaches the speed, so it never ran and
    // raises nothing.
    const bool at_speed = s->generator_rpm >= settings_.engine.running_rpm;
    if (at_speed) {
      if (!engine_.running) engine_.stop_commanded = false;  // a new run: an earlier stop is spent
      engine_.running = true;
      engine_.stopped_by_itself = false;
    } else if (engine_.running) {
      engine_.running = false;
      engine_.stopped_by_itself = !engine_.stop_commanded;
      engine_.stop_commanded = false;
    }
    alarms_.observe_flag(Code::UncommandedEngineStop, engine_.stopped_by_itself, now, wall);
    engine_.status = *s;
    feed_engine_alarms(now, wall);
  }
}

// generator_not_producing: generation enabled (0x04 flag register 0 bit 4) and the engine
// at running speed (0x04 speed >= engine.running_rpm: below it the engine is starting,
// stopping or idling down, and a low voltage is expected), while the generator voltage (the
// latest 0x00) is below V_B, the unit's stored battery charging voltage (0x13): below it the
// generator can charge nothing. Only the voltage decides: 0x01 carries no generator current,
// and the battery currents also depend on the chargers being enabled and the batteries being
// full. Until the unit's V_B is read, or while either packet has not come since the session
// started or the unit came back after OFFLINE, the input is not measured and the alarm holds
// (a unit polled without voltages or status never feeds it).
void DeviceSession::feed_engine_alarms(SteadyTime now, WallTime wall) {
  const auto& vb = reading_.config().raw[static_cast<std::size_t>(codec::Parameter::BatteryVoltage)];
  if (!engine_.status || !vb || std::isnan(engine_.generator_volts)) {
    alarms_.observe(alarms::Code::GeneratorNotProducing, kNotMeasured, now, wall);
    return;
  }
  const bool turning = engine_.status->generator_rpm >= settings_.engine.running_rpm;
  const double charging_volts = codec::parameter_value(codec::Parameter::BatteryVoltage, *vb);
  alarms_.observe_flag(alarms::Code::GeneratorNotProducing,
                       engine_.status->generation_enabled && turning && engine_.generator_volts < charging_volts, now,
                       wall);
}

// device_stale holds while the health is STALE or OFFLINE (no frame within stale_periods),
// so it does not clear as the device gets worse; device_offline while it is OFFLINE. What the
// engine alarms remembered is forgotten at OFFLINE: the unit may come back reset or replaced,
// and an engine found stopped then was not seen to stop.
void DeviceSession::feed_health_alarms(SteadyTime now, WallTime wall) {
  const HealthState state = health_.report().state;
  alarms_.observe_flag(alarms::Code::DeviceStale, state == HealthState::Stale || state == HealthState::Offline, now,
                       wall);
  alarms_.observe_flag(alarms::Code::DeviceOffline, state == HealthState::Offline, now, wall);
  if (state == HealthState::Offline) engine_ = EngineView{};
}

}  // namespace pmu::service
