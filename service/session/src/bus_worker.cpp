#include "pmu/session/bus_worker.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cstring>
#include <system_error>

#include "pmu/codec/encode.hpp"
#include "pmu/codec/ids.hpp"

namespace pmu::service {
namespace {

using std::chrono::milliseconds;

constexpr milliseconds kTick{20};  // session timers need no finer grain than this
constexpr milliseconds kMaintainInterval{250};
constexpr milliseconds kDiscoveryInterval{10000};
constexpr milliseconds kHeardCanOpenPeriod{1000};  // listen_canopen: a device not in the config
constexpr milliseconds kAskInterval{1000};         // serial gets to one unserved address
constexpr milliseconds kSearchInterval{10000};     // broadcast serial requests while a known PMU is OFFLINE
constexpr std::size_t kMaxAsked = 64;              // unserved addresses remembered

bool silent(HealthState s, HealthState at_least) noexcept {
  if (at_least == HealthState::Offline) return s == HealthState::Offline;
  return s == HealthState::Stale || s == HealthState::Offline;
}

// What the operator does about a move: the config line to change, if any.
void log_move(const BusWorker::Moved& m) {
  const std::string serial = m.serial ? " (serial " + std::to_string(*m.serial) + ")" : std::string();
  if (m.config_line.empty())
    spdlog::info(
        "{}: PMU{} moved from address {} to {}; it is not in a config file (discovered or built in): "
        "nothing to change",
        m.bus, serial, m.from, m.to);
  else if (m.to == m.first)
    spdlog::info("{}: PMU{} moved from address {} back to {}, its address in the config ({}): nothing to change", m.bus,
                 serial, m.from, m.to, m.config_line);
  else
    spdlog::warn(
        "{}: PMU{} moved from address {} to {}: the config is stale: {}: change `address: {}` to "
        "`address: {}`",
        m.bus, serial, m.from, m.to, m.config_line, m.first, m.to);
}

}  // namespace

BusWorker::BusWorker(BusConfig config, std::unique_ptr<transport::CanBus> bus, const transport::Clock& clock,
                     const Timeouts& timeouts, StateSink& sink)
    : config_(std::move(config)),
      bus_(std::move(bus)),
      clock_(clock),
      timeouts_(timeouts),
      sink_(sink),
      bus_alarms_(config_.name, alarms::DeviceKind::Bus, 0, config_.alarms, sink),
      loop_(clock, config_.name) {
  const int error = loop_.watch(bus_->fd(), transport::EventLoop::kReadable,
                                [this](std::uint32_t) { turn_frames_ += bus_->drain(*this).frames; });
  if (error != 0) throw std::system_error(error, std::generic_category(), "epoll_ctl");
  const auto now = clock_.steady_now();
  for (const auto& d : config_.devices) add_session(d);
  for (const auto& b : config_.batteries)
    add_canopen_session({config_.name, b.node, DeviceKind::Battery}, b.period, b.alarms);
  for (const auto& m : config_.mppts)
    add_canopen_session({config_.name, m.device, DeviceKind::Mppt}, m.period, m.alarms);
  feed_bus_alarms(bus_->state());
  // Both due at the first turn. Of two timers due together the one added first fires first:
  // discovery before maintenance, their order when they were checks at the end of a turn.
  if (config_.discover)
    loop_.add_timer(now, kDiscoveryInterval, [this](std::chrono::steady_clock::time_point) { discover(); });
  loop_.add_timer(now, kMaintainInterval, [this](std::chrono::steady_clock::time_point t) { bus_->maintain(t); });
  loop_.add_timer(now + kSearchInterval, kSearchInterval, [this](std::chrono::steady_clock::time_point) { search(); });
}

BusWorker::~BusWorker() = default;

DeviceSession& BusWorker::add_session(const DeviceConfig& device) {
  auto s = std::make_unique<DeviceSession>(
      DeviceKey{config_.name, device.address}, device, timeouts_, sink_,
      [this](const codec::CanFrame& f) { return bus_->send(f, timeouts_.send); }, clock_.steady_now());
  auto& ref = *s;
  sessions_[device.address] = std::move(s);
  device_count_.store(sessions_.size(), std::memory_order_relaxed);
  ref.on_bus_state(bus_->state(), clock_.steady_now());
  return ref;
}

CanOpenSession& BusWorker::add_canopen_session(DeviceKey key, milliseconds period,
                                               const alarms::DeviceSettings& alarms) {
  const auto id = std::make_pair(key.kind, key.address);
  auto s = std::make_unique<CanOpenSession>(std::move(key), period, config_.canopen_publish_period, timeouts_, sink_,
                                            clock_.steady_now(), alarms);
  auto& ref = *s;
  canopen_[id] = std::move(s);
  ref.on_bus_state(bus_->state(), clock_.steady_now());
  return ref;
}

CanOpenSession* BusWorker::canopen_session(DeviceKind kind, std::uint16_t id) {
  auto it = canopen_.find({kind, id});
  return it == canopen_.end() ? nullptr : it->second.get();
}

void BusWorker::on_canopen_frame(const transport::ReceivedFrame& rx) {
  auto key = canopen_device(config_.name, rx.frame);
  if (!key) return;  // neither a PMU's nor a battery's or MPPT's
  CanOpenSession* s = canopen_session(key->kind, key->address);
  if (!s && config_.listen_canopen) {
    spdlog::info("{}: heard a {} at {} {}", config_.name, to_string(key->kind),
                 key->kind == DeviceKind::Mppt ? "device" : "node", key->address);
    s = &add_canopen_session(*key, kHeardCanOpenPeriod);
  }
  if (!s) return;  // one the config does not serve
  s->on_frame(rx.frame, clock_.steady_now(), rx.timestamp);
}

DeviceSession* BusWorker::session(std::uint16_t address) {
  auto it = sessions_.find(address);
  if (it != sessions_.end() && it->second->key().address == address) return it->second.get();
  // Moved this turn and not yet filed under its new address (rekey_moved_sessions).
  for (auto& [a, s] : sessions_)
    if (s->key().address == address) return s.get();
  return nullptr;
}

DeviceSession* BusWorker::session_moved_from(std::uint16_t address) {
  if (session(address)) return nullptr;
  const auto it = left_.find(address);
  return it == left_.end() ? nullptr : session(it->second);
}

std::vector<std::uint16_t> BusWorker::addresses() const {
  std::vector<std::uint16_t> v;
  for (const auto& [a, s] : sessions_) v.push_back(a);
  return v;
}

void BusWorker::on_frame(const transport::ReceivedFrame& rx) {
  const auto id = codec::parse_id(rx.frame.id, rx.frame.extended);
  if (!id.id) {  // not a PMU conversation: perhaps a battery or MPPT
    on_canopen_frame(rx);
    return;
  }
  const auto now = clock_.steady_now();
  const std::uint16_t address = id.id->address;
  if (address == codec::kBroadcastAddress) return;  // a broadcast request, not an answer
  DeviceSession* s = session(address);
  if (!s) {
    for (auto& [a, candidate] : sessions_)
      if (candidate->alias() == address) s = candidate.get();
  }
  if (!s) s = on_stranger(*id.id, rx);
  if (!s) return;                                    // a PMU the config does not serve
  s->on_frame(*id.id, rx.frame, now, rx.timestamp);  // the id is parsed here only
}

void BusWorker::on_event(const transport::BusEvent& event) {
  switch (event.kind) {
    case transport::BusEventKind::StateChanged:
      spdlog::log(event.state == transport::BusState::Up ? spdlog::level::info : spdlog::level::warn,
                  "{}: bus {} (was {})", config_.name, transport::to_string(event.state),
                  transport::to_string(event.previous));
      break;
    case transport::BusEventKind::Reopened: spdlog::info("{}: interface present, socket bound", config_.name); break;
    case transport::BusEventKind::SocketError:
      // Identical lines collapse in the logger's duplicate filter during a flood.
      spdlog::warn("{}: socket error: {}", config_.name, std::strerror(event.error));
      return;
    case transport::BusEventKind::ErrorFrame:
      spdlog::debug("{}: error frame class 0x{:X}", config_.name, event.error_class);
      return;
  }
  const auto now = clock_.steady_now();
  for (auto& [a, s] : sessions_) s->on_bus_state(event.state, now);
  for (auto& [id, s] : canopen_) s->on_bus_state(event.state, now);
  feed_bus_alarms(event.state);
}

// Error passive holds at bus off too (both mean an error counter past 127), so it does not
// clear as the bus gets worse. DOWN (the interface) and ERROR_WARNING have no code.
void BusWorker::feed_bus_alarms(transport::BusState state) {
  const auto now = clock_.steady_now();
  const auto wall = clock_.system_now();
  const bool off = state == transport::BusState::BusOff;
  bus_alarms_.observe_flag(alarms::Code::BusErrorPassive, off || state == transport::BusState::ErrorPassive, now, wall);
  bus_alarms_.observe_flag(alarms::Code::BusOff, off, now, wall);
}

DeviceSession* BusWorker::session_with_serial(std::uint16_t serial) {
  for (auto& [a, s] : sessions_)
    if (s->serial() == serial && !s->alias()) return s.get();
  return nullptr;
}

bool BusWorker::any_silent_known(HealthState at_least) const {
  for (const auto& [a, s] : sessions_)
    if (s->serial() && silent(s->health().state, at_least)) return true;
  return false;
}

DeviceSession* BusWorker::on_stranger(const codec::PmuId& id, const transport::ReceivedFrame& rx) {
  const auto m = codec::decode(rx.frame, id, std::nullopt);
  // Only a PMU sends these with data; a set or a get from another tool looks like any other
  // address's traffic and proves nothing.
  if (!m || m->request) return nullptr;
  const auto p = static_cast<std::uint8_t>(m->packet);
  if (p > 0x04 && m->packet != codec::PacketId::Serial && m->packet != codec::PacketId::Firmware) return nullptr;
  const auto now = clock_.steady_now();
  const std::uint16_t address = id.address;
  if (const auto* sn = std::get_if<codec::SerialNumber>(&m->payload)) {
    // Unless it is a silent one's: asked again only at the search's pace, in case one moves
    // there later.
    if (auto it = asked_.find(address); it != asked_.end()) it->second = now + kSearchInterval;
    if (DeviceSession* known = session_with_serial(sn->serial_number)) {
      const auto was = known->key().address;
      if (!silent(known->health().state, HealthState::Stale)) {
        spdlog::warn(
            "{}: serial {} answers at address {} while address {} with that serial still speaks: two "
            "units report one serial; address {} is not served",
            config_.name, sn->serial_number, address, was, address);
        return nullptr;
      }
      spdlog::warn(
          "{}: the PMU of serial {} (address {}, {} for {:.1f} s) answers at address {}: the same unit, "
          "moved; served as {}/{} from now on",
          config_.name, sn->serial_number, was, to_string(known->health().state), known->health().last_frame_age,
          address, config_.name, address);
      asked_.erase(address);
      known->move_to(address, DeviceSession::MoveCause::ByItself, now);
      return nullptr;  // move_to took this answer as the frame heard
    }
    if (config_.discover) {
      DeviceConfig d = config_.discovered_defaults;
      d.address = address;
      spdlog::info("{}: discovered a PMU at address {} (serial {})", config_.name, address, sn->serial_number);
      return &add_session(d);
    }
    return nullptr;
  }
  if (any_silent_known(HealthState::Stale)) {
    // Perhaps a silent session's unit, moved: its serial says.
    auto it = asked_.find(address);
    if (it == asked_.end() || now >= it->second) {
      if (asked_.size() >= kMaxAsked) asked_.clear();
      asked_[address] = now + kAskInterval;
      (void)bus_->send(*codec::encode_get(codec::PacketId::Serial, address), timeouts_.send);
    }
    return nullptr;  // served once its serial is known (above)
  }
  if (config_.discover && m->packet == codec::PacketId::Firmware) {
    DeviceConfig d = config_.discovered_defaults;
    d.address = address;
    spdlog::info("{}: discovered a PMU at address {}", config_.name, address);
    return &add_session(d);
  }
  return nullptr;
}

void BusWorker::search() {
  if (!any_silent_known(HealthState::Offline)) return;
  (void)bus_->send(*codec::encode_get(codec::PacketId::Serial, codec::kBroadcastAddress), timeouts_.send);
}

void BusWorker::discover() {
  (void)bus_->send(*codec::encode_get(codec::PacketId::Firmware, codec::kBroadcastAddress), timeouts_.send);
}

void BusWorker::post(std::function<void()> fn) { loop_.post(std::move(fn)); }

void BusWorker::post_urgent(std::function<void()> fn) { loop_.post_urgent(std::move(fn)); }

void BusWorker::repeat_readings() {
  const auto now = clock_.steady_now();
  for (auto& entry : sessions_) entry.second->repeat_reading_gets(now);
}

void BusWorker::every(milliseconds period, std::function<void(std::chrono::steady_clock::time_point)> fn) {
  loop_.add_timer(clock_.steady_now(), period, std::move(fn));
}

std::size_t BusWorker::run_once(milliseconds max_wait) {
  turn_frames_ = 0;
  loop_.run_once(std::min(max_wait, kTick));
  end_turn();
  return turn_frames_;
}

void BusWorker::end_turn() {
  const auto now = clock_.steady_now();
  const auto wall = clock_.system_now();
  const auto counters = bus_->counters();
  for (auto& [a, s] : sessions_) {
    s->on_bus_counters(counters);
    s->tick(now, wall);
  }
  for (auto& [id, s] : canopen_) {
    s->on_bus_counters(counters);
    s->tick(now, wall);
  }
  bus_alarms_.tick(now, wall);
  rekey_moved_sessions();
  progress_.fetch_add(1, std::memory_order_relaxed);
}

void BusWorker::confirm_expected(DeviceSession& s) {
  // A unit recorded as moved answered at its configured address after all: the record is over.
  if (!s.expects_serial() || !s.info() || s.key().address != s.first_address()) return;
  s.expect_serial(std::nullopt);
  spdlog::info("{}/{}: the PMU answers at its configured address (serial {}): the record of a move is dropped",
               config_.name, s.key().address, s.info()->serial_number);
  if (!moved_) return;
  Moved m;
  m.bus = config_.name;
  m.from = m.to = m.first = s.first_address();
  m.serial = s.serial();
  m.config_line = s.settings().source_line;
  moved_(m);
}

void BusWorker::rekey_moved_sessions() {
  // A verified CAN address change moved a session: file it under its new address.
  for (auto it = sessions_.begin(); it != sessions_.end();) {
    if (it->second->key().address == it->first) {
      confirm_expected(*it->second);
      ++it;
      continue;
    }
    auto moved = std::move(it->second);
    const std::uint16_t from = it->first;
    it = sessions_.erase(it);
    const auto address = moved->key().address;
    Moved m;
    m.bus = config_.name;
    m.from = from;
    m.to = address;
    m.first = moved->first_address();
    m.serial = moved->serial();
    m.config_line = moved->settings().source_line;
    // A move onto an address that had a session of its own leaves one session fewer.
    sessions_[address] = std::move(moved);
    // Who left where: a unit that left an address another unit left before is where both
    // went; one that is back where it left is no longer away from it.
    for (auto& [left, now_at] : left_)
      if (now_at == from) now_at = address;
    left_[from] = address;
    left_.erase(address);
    device_count_.store(sessions_.size(), std::memory_order_relaxed);
    log_move(m);
    if (moved_) moved_(m);
  }
}

void BusWorker::run() {
  loop_.run(kTick, [this] { end_turn(); });
}

void BusWorker::stop() { loop_.stop(); }

}  // namespace pmu::service
