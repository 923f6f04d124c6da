#include "pmu/service/bus_worker.hpp"

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

}  // namespace

BusWorker::BusWorker(BusConfig config, std::unique_ptr<transport::CanBus> bus, const transport::Clock& clock,
                     const Timeouts& timeouts, StateSink& sink)
    : config_(std::move(config)),
      bus_(std::move(bus)),
      clock_(clock),
      timeouts_(timeouts),
      sink_(sink),
      loop_(clock, config_.name) {
  const int error = loop_.watch(bus_->fd(), transport::EventLoop::kReadable,
                                [this](std::uint32_t) { turn_frames_ += bus_->drain(*this).frames; });
  if (error != 0) throw std::system_error(error, std::generic_category(), "epoll_ctl");
  const auto now = clock_.steady_now();
  for (const auto& d : config_.devices) add_session(d);
  for (const auto& b : config_.batteries) add_canopen_session({config_.name, b.node, DeviceKind::Battery}, b.period);
  for (const auto& m : config_.mppts) add_canopen_session({config_.name, m.device, DeviceKind::Mppt}, m.period);
  // Both due at the first turn. Of two timers due together the one added first fires first:
  // discovery before maintenance, their order when they were checks at the end of a turn.
  if (config_.discover)
    loop_.add_timer(now, kDiscoveryInterval, [this](std::chrono::steady_clock::time_point) { discover(); });
  loop_.add_timer(now, kMaintainInterval, [this](std::chrono::steady_clock::time_point t) { bus_->maintain(t); });
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

CanOpenSession& BusWorker::add_canopen_session(DeviceKey key, milliseconds period) {
  const auto id = std::make_pair(key.kind, key.address);
  auto s = std::make_unique<CanOpenSession>(std::move(key), period, config_.canopen_publish_period, timeouts_, sink_,
                                            clock_.steady_now());
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
  return it == sessions_.end() ? nullptr : it->second.get();
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
  if (!s && config_.discover && id.id->packet == codec::PacketId::Firmware && rx.frame.length == codec::data_length(codec::PacketId::Firmware)) {
    DeviceConfig d = config_.discovered_defaults;
    d.address = address;
    s = &add_session(d);
    spdlog::info("{}: discovered a PMU at address {}", config_.name, address);
  }
  if (!s) return;  // a PMU the config does not serve
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
}

void BusWorker::discover() {
  (void)bus_->send(*codec::encode_get(codec::PacketId::Firmware, codec::kBroadcastAddress), timeouts_.send);
}

void BusWorker::post(std::function<void()> fn) { loop_.post(std::move(fn)); }

std::size_t BusWorker::run_once(milliseconds max_wait) {
  turn_frames_ = 0;
  loop_.run_once(std::min(max_wait, kTick));
  end_turn();
  return turn_frames_;
}

void BusWorker::end_turn() {
  const auto now = clock_.steady_now();
  const auto counters = bus_->counters();
  for (auto& [a, s] : sessions_) {
    s->on_bus_counters(counters);
    s->tick(now);
  }
  for (auto& [id, s] : canopen_) {
    s->on_bus_counters(counters);
    s->tick(now);
  }
  rekey_moved_sessions();
  progress_.fetch_add(1, std::memory_order_relaxed);
}

void BusWorker::rekey_moved_sessions() {
  // A verified CAN address change moved a session: file it under its new address.
  for (auto it = sessions_.begin(); it != sessions_.end();) {
    if (it->second->key().address == it->first) {
      ++it;
      continue;
    }
    auto moved = std::move(it->second);
    it = sessions_.erase(it);
    const auto address = moved->key().address;
    sessions_[address] = std::move(moved);
    // A move onto an address that had a session of its own leaves one session fewer.
    device_count_.store(sessions_.size(), std::memory_order_relaxed);
  }
}

void BusWorker::run() { loop_.run(kTick, [this] { end_turn(); }); }

void BusWorker::stop() { loop_.stop(); }

}  // namespace pmu::service
