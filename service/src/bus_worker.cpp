#include "pmu/service/bus_worker.hpp"

#include <sys/epoll.h>
#include <sys/eventfd.h>
#include <unistd.h>

#include <spdlog/spdlog.h>

#include <cerrno>
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

[[noreturn]] void fail(const char* what) { throw std::system_error(errno, std::generic_category(), what); }

}  // namespace

BusWorker::BusWorker(BusConfig config, std::unique_ptr<transport::CanBus> bus, const transport::Clock& clock,
                     const Timeouts& timeouts, StateSink& sink)
    : config_(std::move(config)), bus_(std::move(bus)), clock_(clock), timeouts_(timeouts), sink_(sink) {
  epoll_.reset(::epoll_create1(EPOLL_CLOEXEC));
  if (!epoll_) fail("epoll_create1");
  wake_.reset(::eventfd(0, EFD_CLOEXEC | EFD_NONBLOCK));
  if (!wake_) fail("eventfd");
  for (int fd : {bus_->fd(), wake_.get()}) {
    epoll_event ev{};
    ev.events = EPOLLIN;
    ev.data.fd = fd;
    if (::epoll_ctl(epoll_.get(), EPOLL_CTL_ADD, fd, &ev) != 0) fail("epoll_ctl");
  }
  const auto now = clock_.steady_now();
  for (const auto& d : config_.devices) add_session(d);
  next_maintain_ = now;
  next_discovery_ = now;
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
  if (!id.id) return;  // CANopen or unknown packets: not a PMU conversation
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
    case transport::BusEventKind::Reopened: spdlog::info("{}: interface back, socket reopened", config_.name); break;
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
}

void BusWorker::discover(std::chrono::steady_clock::time_point now) {
  if (!config_.discover || now < next_discovery_) return;
  next_discovery_ = now + kDiscoveryInterval;
  (void)bus_->send(*codec::encode_get(codec::PacketId::Firmware, codec::kBroadcastAddress), timeouts_.send);
}

void BusWorker::post(std::function<void()> fn) {
  {
    std::lock_guard<std::mutex> lock(posted_mutex_);
    posted_.push_back(std::move(fn));
  }
  const std::uint64_t one = 1;
  (void)!::write(wake_.get(), &one, sizeof one);
}

void BusWorker::run_posted() {
  std::uint64_t count = 0;
  (void)!::read(wake_.get(), &count, sizeof count);
  std::vector<std::function<void()>> work;
  {
    std::lock_guard<std::mutex> lock(posted_mutex_);
    work.swap(posted_);
  }
  for (auto& fn : work) fn();
}

std::size_t BusWorker::run_once(milliseconds max_wait) {
  epoll_event events[2];
  const int n = ::epoll_wait(epoll_.get(), events, 2, static_cast<int>(std::min(max_wait, kTick).count()));
  std::size_t frames = 0;
  bool woken = false;  // post() ran: only then is there work (and an eventfd to read)
  for (int i = 0; i < n; ++i) {
    if (events[i].data.fd == bus_->fd()) frames += bus_->drain(*this).frames;
    if (events[i].data.fd == wake_.get()) woken = true;
  }
  if (woken) run_posted();
  const auto now = clock_.steady_now();
  const auto counters = bus_->counters();
  for (auto& [a, s] : sessions_) {
    s->on_bus_counters(counters);
    s->tick(now);
  }
  discover(now);
  rekey_moved_sessions();
  if (now >= next_maintain_) {
    next_maintain_ = now + kMaintainInterval;
    bus_->maintain(now);
  }
  progress_.fetch_add(1, std::memory_order_relaxed);
  return frames;
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

void BusWorker::run() {
  while (!stop_.load(std::memory_order_relaxed)) run_once(kTick);
}

void BusWorker::stop() {
  stop_.store(true);
  post([] {});
}

}  // namespace pmu::service
