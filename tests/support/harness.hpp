#pragma once
// One bus in one process with a fake clock: a BusWorker (the service's side) and simulated
// PMUs on a BusRunner, over the in-process bus. The service's endpoint is wrapped so the
// test sees every frame the service sent. Time moves only when the test says so; each step
// lets frames cross the bus both ways.

#include <chrono>
#include <memory>
#include <vector>

#include "pmu/codec/decode.hpp"
#include "pmu/session/bus_worker.hpp"
#include "pmu/sim/bus_runner.hpp"
#include "pmu/transport/sim_bus.hpp"
#include "recording_sink.hpp"  // beside this header: a fuzz target includes it without pmu::test_support

namespace pmu::service::test {

using namespace std::chrono_literals;

// A CanBus that forwards to another and keeps a copy of every frame sent through it.
class RecordingBus final : public transport::CanBus {
 public:
  explicit RecordingBus(std::unique_ptr<transport::CanBus> inner) : inner_(std::move(inner)) {}
  const std::string& name() const noexcept override { return inner_->name(); }
  int fd() const noexcept override { return inner_->fd(); }
  transport::DrainResult drain(transport::BusHandler& h) override { return inner_->drain(h); }
  transport::SendResult send(const codec::CanFrame& f, std::chrono::milliseconds w) override {
    // A lost set: the bus accepts it but the device never sees it (to test read-back).
    if (drop_data_of && f.length > 0 && ((f.id >> 16) & 0xFF) == *drop_data_of) {
      sent.push_back(f);
      return {};
    }
    auto r = inner_->send(f, w);
    if (r.ok()) sent.push_back(f);
    return r;
  }
  std::optional<std::uint8_t> drop_data_of;  // packet id whose data frames are lost
  transport::BusState state() const noexcept override { return inner_->state(); }
  transport::BusCounters counters() const noexcept override { return inner_->counters(); }
  void maintain(std::chrono::steady_clock::time_point now) override { inner_->maintain(now); }

  std::vector<codec::CanFrame> sent;

 private:
  std::unique_ptr<transport::CanBus> inner_;
};

// A system-clock time as a request's expires_at carries it (ns since the Unix epoch).
inline std::uint64_t epoch_ns(std::chrono::system_clock::time_point t) {
  return static_cast<std::uint64_t>(std::chrono::duration_cast<std::chrono::nanoseconds>(t.time_since_epoch()).count());
}

inline BusConfig sim_bus(std::vector<DeviceConfig> devices, bool discover = false) {
  BusConfig b;
  b.name = "sim0";
  b.interface = "sim";
  b.devices = std::move(devices);
  b.discover = discover;
  return b;
}

inline DeviceConfig device(std::uint16_t address, TelemetryMode mode = TelemetryMode::Streaming,
                           std::chrono::milliseconds period = 1000ms) {
  DeviceConfig d;
  d.address = address;
  d.mode = mode;
  d.period = period;
  return d;
}

inline sim::DeviceConfig pmu(std::uint16_t address, codec::FirmwareVersion fw = codec::kCurrentFirmware,
                             std::uint32_t packet_period_raw = 10) {
  sim::DeviceConfig d;
  d.address = address;
  d.serial_number = static_cast<std::uint16_t>(4000 + address);
  d.firmware = fw;
  d.parameters.set_raw(codec::Parameter::PacketPeriod, packet_period_raw);
  return d;
}

class Harness {
 public:
  // `publish_to` replaces the recording sink (e.g. the DDS publisher); `sink` then stays empty.
  Harness(BusConfig bus, std::vector<sim::DeviceConfig> pmus, Timeouts timeouts = {}, StateSink* publish_to = nullptr)
      : network_(clock_) {
    runner_ = std::make_unique<sim::BusRunner>(network_.attach("pmu-sim"), clock_);
    for (const auto& p : pmus) runner_->add(p);
    auto recording = std::make_unique<RecordingBus>(network_.attach(bus.name));
    bus_ = recording.get();
    worker_ = std::make_unique<BusWorker>(bus, std::move(recording), clock_, timeouts,
                                          publish_to ? *publish_to : static_cast<StateSink&>(sink));
    settle();
  }

  // Advances the fake clock by `total` in `step`s, letting every party act after each step.
  void run_for(std::chrono::milliseconds total, std::chrono::milliseconds step = 10ms) {
    for (auto t = 0ms; t < total; t += step) {
      clock_.advance(step);
      settle();
    }
  }
  // Lets frames in flight be delivered and answered without moving time.
  void settle() {
    for (int i = 0; i < 4; ++i) {
      worker_->run_once(0ms);
      runner_->run_once(0ms);
    }
  }

  // Frames the service put on the bus, decoded.
  std::vector<codec::PmuMessage> sent() const {
    std::vector<codec::PmuMessage> out;
    for (const auto& f : bus_->sent)
      if (auto m = codec::decode(f)) out.push_back(*m);
    return out;
  }
  void clear_sent() { bus_->sent.clear(); }
  const std::vector<codec::CanFrame>& sent_frames() const { return bus_->sent; }
  RecordingBus& recording_bus() { return *bus_; }

  BusWorker& worker() { return *worker_; }
  sim::BusRunner& pmus() { return *runner_; }
  transport::SimulatedNetwork& network() { return network_; }
  transport::ManualClock& clock() { return clock_; }

  RecordingSink sink;

 private:
  transport::ManualClock clock_;
  transport::SimulatedNetwork network_;
  std::unique_ptr<sim::BusRunner> runner_;
  RecordingBus* bus_ = nullptr;
  std::unique_ptr<BusWorker> worker_;
};

}  // namespace pmu::service::test
