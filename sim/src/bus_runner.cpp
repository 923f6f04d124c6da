#include "pmu/sim/bus_runner.hpp"

#include <sys/epoll.h>

#include <algorithm>
#include <cerrno>
#include <system_error>

namespace pmu::sim {

using std::chrono::milliseconds;

BusRunner::BusRunner(std::unique_ptr<transport::CanBus> bus, const transport::Clock& clock)
    : bus_(std::move(bus)), clock_(clock) {
  epoll_.reset(::epoll_create1(EPOLL_CLOEXEC));
  if (!epoll_) throw std::system_error(errno, std::generic_category(), "epoll_create1");
  epoll_event ev{};
  ev.events = EPOLLIN;
  ev.data.fd = bus_->fd();
  if (::epoll_ctl(epoll_.get(), EPOLL_CTL_ADD, bus_->fd(), &ev) != 0)
    throw std::system_error(errno, std::generic_category(), "epoll_ctl");
}

BusRunner::~BusRunner() { stop(); }

void BusRunner::add(const DeviceConfig& config) {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  // A real bus does not echo a node's own frames back to it: send without expecting them.
  auto model = std::make_unique<PmuModel>(
      config, [this](const codec::CanFrame& f) { (void)bus_->send(f, milliseconds(10)); }, clock_.steady_now());
  models_[config.address] = std::move(model);
}

void BusRunner::on_frame(const transport::ReceivedFrame& frame) {
  const auto now = clock_.steady_now();
  for (auto& [address, model] : models_) model->on_frame(frame.frame, now);
}

void BusRunner::on_event(const transport::BusEvent&) {}

void BusRunner::run_once(milliseconds max_wait) {
  milliseconds wait = max_wait;
  {
    std::lock_guard<std::recursive_mutex> lock(mutex_);
    const auto now = clock_.steady_now();
    for (const auto& [address, model] : models_) {
      const auto until = std::chrono::duration_cast<milliseconds>(model->next_deadline() - now);
      wait = std::clamp(until, milliseconds(0), wait);
    }
  }
  epoll_event ev{};
  const int n = ::epoll_wait(epoll_.get(), &ev, 1, static_cast<int>(wait.count()));
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  if (n > 0) bus_->drain(*this);
  const auto now = clock_.steady_now();
  for (auto& [address, model] : models_) model->tick(now);
  bus_->maintain(now);
}

void BusRunner::start() {
  stop_ = false;
  thread_ = std::thread([this] {
    while (!stop_.load()) run_once(milliseconds(50));
  });
}

void BusRunner::stop() {
  stop_ = true;
  if (thread_.joinable()) thread_.join();
}

bool BusRunner::with_model(std::uint16_t address, const std::function<void(PmuModel&)>& fn) {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  auto it = models_.find(address);
  if (it == models_.end()) return false;
  fn(*it->second);
  return true;
}

}  // namespace pmu::sim
