#include "fake_pmu.hpp"

#include <poll.h>
#include <sys/socket.h>

#include <algorithm>
#include <cerrno>
#include <memory>
#include <stdexcept>

#include "pacer.hpp"
#include "pmu/codec/encode.hpp"
#include "pmu/sim/pmu_model.hpp"
#include "pmu/transport/linux_frame.hpp"

namespace pmu::bench {

FakePmu::FakePmu(transport::UniqueFd fd, FakePmuLoad load) : fd_(std::move(fd)), load_(load) {
  thread_ = std::thread([this] { run(); });
}

FakePmu::~FakePmu() {
  stop_ = true;
  thread_.join();
}

void FakePmu::write_raw(const void* frame) {
  // Blocking: a full socket buffer slows the writer down instead of losing the frame.
  std::lock_guard lock(write_mutex_);
  while (::send(fd_.get(), frame, sizeof(struct can_frame), MSG_NOSIGNAL) < 0 && errno == EINTR) {
  }
}

void FakePmu::run() {
  const auto send = [this](const codec::CanFrame& f) {
    const struct can_frame raw = transport::to_linux(f);
    write_raw(&raw);
  };
  std::vector<std::unique_ptr<sim::PmuModel>> models;
  for (std::uint16_t a = 1; a <= load_.units; ++a) {
    sim::DeviceConfig config;
    config.address = a;
    config.serial_number = static_cast<std::uint16_t>(1000 + a);
    config.parameters.set_raw(codec::Parameter::PacketPeriod, load_.period_tenths);
    config.parameters.set_raw(codec::Parameter::PacketsStreamed, 0x1F);  // every packet
    models.push_back(std::make_unique<sim::PmuModel>(config, send, sim::Clock::now()));
    models.back()->set_engine_running(true, sim::Clock::now());
  }
  while (!stop_) {
    auto next = models.front()->next_deadline();
    for (const auto& m : models) next = std::min(next, m->next_deadline());
    const auto wait = std::chrono::duration_cast<std::chrono::milliseconds>(next - sim::Clock::now());
    pollfd p{fd_.get(), POLLIN, 0};
    ::poll(&p, 1, static_cast<int>(std::clamp<std::int64_t>(wait.count(), 0, 20)));
    struct can_frame raw {};
    while (::recv(fd_.get(), &raw, sizeof raw, MSG_DONTWAIT) == static_cast<ssize_t>(sizeof raw)) {
      ++from_service_;
      // Every unit sees every frame, as on a bus; each acts on its own address only.
      if (const auto f = transport::from_linux(raw))
        for (const auto& m : models) m->on_frame(*f, sim::Clock::now());
    }
    const auto now = sim::Clock::now();
    for (const auto& m : models) m->tick(now);
  }
}

std::int64_t FakePmu::write_status(bool thermal_shutdown) {
  codec::Status s;
  s.generator_rpm = 6000;
  s.generation_enabled = true;
  s.thermal_shutdown = thermal_shutdown;
  s.starter_ready = true;
  s.outputs = 0x0F;
  const auto frame = codec::encode_status(s, 1);
  const struct can_frame raw = transport::to_linux(*frame);
  const std::int64_t now = steady_ns();
  write_raw(&raw);
  return now;
}

Injection FakePmu::inject(double rate, std::chrono::nanoseconds duration, WriteTimes& times,
                          const std::atomic<bool>* stop) {
  codec::Voltages v;
  v.avionics = kMarkerRaw / 10.0;
  v.output_28v = 28.0;
  v.payload = 12.0;
  v.servo = 6.0;
  v.generator = 48.0;
  Injection result;
  std::int64_t first = 0, last = 0;
  const auto n = static_cast<std::uint64_t>(static_cast<double>(duration.count()) * rate / 1e9);
  result.frames = paced(rate, n, stop, [&](std::uint64_t i) {
    const std::uint16_t seq = seq_;
    seq_ = static_cast<std::uint16_t>((seq_ + 1) % kSeqSpace);
    v.battery_a = (seq / kSeqBase) / 10.0;
    v.battery_b = (seq % kSeqBase) / 10.0;
    const auto frame = codec::encode_voltages(v, 1);
    if (!frame) return;  // cannot happen: every field is within 0..25.0 V
    const struct can_frame raw = transport::to_linux(*frame);
    const std::int64_t now = steady_ns();
    times.record(seq, now);
    write_raw(&raw);
    if (i == 0) first = now;
    last = now;
  });
  result.seconds = static_cast<double>(last - first) / 1e9;
  return result;
}

}  // namespace pmu::bench
