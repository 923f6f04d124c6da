#include "pmu/sim/bus_runner.hpp"

#include <algorithm>
#include <cstdint>
#include <system_error>

namespace pmu::sim {

using std::chrono::milliseconds;

namespace {
// The longest wait of start()'s turns: how late a change made through with_model() may be
// noticed while the loop waits.
constexpr milliseconds kTurn{50};
}  // namespace

BusRunner::BusRunner(std::unique_ptr<transport::CanBus> bus, const transport::Clock& clock)
    : bus_(std::move(bus)), clock_(clock), loop_(clock, bus_->name()) {
  const int error = loop_.watch(bus_->fd(), transport::EventLoop::kReadable, [this](std::uint32_t) {
    std::lock_guard<std::recursive_mutex> lock(mutex_);
    bus_->drain(*this);
  });
  if (error != 0) throw std::system_error(error, std::generic_category(), "epoll_ctl");
  // Only ends waits: every turn ticks every model whether or not a deadline passed.
  deadline_timer_ = loop_.add_timer(clock_.steady_now(), milliseconds{0}, {});
  loop_.disarm(deadline_timer_);
}

BusRunner::~BusRunner() { stop(); }

FrameSink BusRunner::sink() {
  // A real bus does not echo a node's own frames back to it: send without expecting them.
  return [this](const codec::CanFrame& f) { (void)bus_->send(f, milliseconds(10)); };
}

void BusRunner::add(const DeviceConfig& config) {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  auto model = std::make_unique<PmuModel>(config, sink(), clock_.steady_now());
  models_[config.address] = std::move(model);
}

SolarPlant& BusRunner::plant() {
  if (!plant_) plant_ = std::make_shared<SolarPlant>(SolarWorld{}, clock_.steady_now());
  return *plant_;
}

void BusRunner::add_battery(const BatterySimConfig& config) {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  plant();
  // Built before the old one goes, so a refused config leaves the old device running.
  auto model = std::make_unique<BatteryModel>(config, plant_, sink(), clock_.steady_now());
  batteries_[config.node] = std::move(model);
}

void BusRunner::add_mppt(const MpptSimConfig& config) {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  plant();
  auto model = std::make_unique<MpptModel>(config, plant_, sink(), clock_.steady_now());
  mppts_[config.device] = std::move(model);
}

void BusRunner::on_frame(const transport::ReceivedFrame& frame) {
  const auto now = clock_.steady_now();
  for (auto& [address, model] : models_) model->on_frame(frame.frame, now);
}

void BusRunner::on_event(const transport::BusEvent&) {}

void BusRunner::wake_at_next_deadline() {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  if (models_.empty() && batteries_.empty() && mppts_.empty()) {
    loop_.disarm(deadline_timer_);
    return;
  }
  auto earliest = transport::EventLoop::TimePoint::max();
  for (const auto& [address, model] : models_) earliest = std::min(earliest, model->next_deadline());
  for (const auto& [node, model] : batteries_) earliest = std::min(earliest, model->next_deadline());
  for (const auto& [device, model] : mppts_) earliest = std::min(earliest, model->next_deadline());
  loop_.schedule(deadline_timer_, earliest);
}

void BusRunner::end_turn() {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  const auto now = clock_.steady_now();
  for (auto& [address, model] : models_) model->tick(now);
  for (auto& [node, model] : batteries_) model->tick(now);
  for (auto& [device, model] : mppts_) model->tick(now);
  bus_->maintain(now);
}

void BusRunner::run_once(milliseconds max_wait) {
  wake_at_next_deadline();
  loop_.run_once(max_wait);
  end_turn();
}

void BusRunner::start() {
  thread_ = std::thread([this] {
    wake_at_next_deadline();
    loop_.run(kTurn, [this] {
      end_turn();
      wake_at_next_deadline();
    });
  });
}

void BusRunner::stop() {
  if (!thread_.joinable()) return;
  loop_.stop();
  thread_.join();
}

bool BusRunner::with_model(std::uint16_t address, const std::function<void(PmuModel&)>& fn) {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  auto it = models_.find(address);
  if (it == models_.end()) return false;
  fn(*it->second);
  return true;
}

bool BusRunner::with_battery(std::uint8_t node, const std::function<void(BatteryModel&)>& fn) {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  auto it = batteries_.find(node);
  if (it == batteries_.end()) return false;
  fn(*it->second);
  return true;
}

bool BusRunner::with_mppt(std::uint8_t device, const std::function<void(MpptModel&)>& fn) {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  auto it = mppts_.find(device);
  if (it == mppts_.end()) return false;
  fn(*it->second);
  return true;
}

}  // namespace pmu::sim
