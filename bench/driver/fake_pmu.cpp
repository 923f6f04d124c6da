#include "fake_pmu.hpp"

#include <poll.h>
#include <sys/socket.h>

#include <cerrno>
#include <stdexcept>

#include "pacer.hpp"
#include "pmu/codec/encode.hpp"
#include "pmu/sim/pmu_model.hpp"
#include "pmu/transport/linux_frame.hpp"

namespace pmu::bench {

FakePmu::FakePmu(transport::UniqueFd fd) : fd_(std::move(fd)) { thread_ = std::thread([this] { run(); }); }

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
  sim::DeviceConfig config;
  config.address = 1;
  config.serial_number = 1001;
  config.parameters.set_raw(codec::Parameter::PacketPeriod, 10);     // 1.0 s
  config.parameters.set_raw(codec::Parameter::PacketsStreamed, 0x1F);  // every packet
  sim::PmuModel model(
      config,
      [this](const codec::CanFrame& f) {
        const struct can_frame raw = transport::to_linux(f);
        write_raw(&raw);
      },
      sim::Clock::now());
  model.set_engine_running(true, sim::Clock::now());
  while (!stop_) {
    const auto now = sim::Clock::now();
    const auto wait = std::chrono::duration_cast<std::chrono::milliseconds>(model.next_deadline() - now);
    pollfd p{fd_.get(), POLLIN, 0};
    ::poll(&p, 1, static_cast<int>(std::clamp<std::int64_t>(wait.count(), 0, 20)));
    struct can_frame raw{};
    while (::recv(fd_.get(), &raw, sizeof raw, MSG_DONTWAIT) == static_cast<ssize_t>(sizeof raw)) {
      ++from_service_;
      if (const auto f = transport::from_linux(raw)) model.on_frame(*f, sim::Clock::now());
    }
    model.tick(sim::Clock::now());
  }
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
