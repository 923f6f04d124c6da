#pragma once
// A PmuModel driven by a fake clock: the test moves `now` by hand and reads back the frames
// the model put on the "bus", decoded with pmu::codec::decode as a service would.

#include <gtest/gtest.h>

#include <chrono>
#include <initializer_list>
#include <optional>
#include <vector>

#include "pmu/codec/decode.hpp"
#include "pmu/codec/encode.hpp"
#include "pmu/sim/pmu_model.hpp"

namespace pmu::sim::test {

using namespace std::chrono_literals;
using codec::PacketId;
using codec::Parameter;

constexpr codec::FirmwareVersion kFw112{1, 12}, kFw114{1, 14}, kFw115{1, 15}, kFw116{1, 16}, kFw117{1, 17};

// Streaming off, so a test sees only the frames it asks for.
inline DeviceConfig quiet_config(std::uint16_t address = 1, codec::FirmwareVersion fw = kFw117) {
  DeviceConfig c;
  c.address = address;
  c.firmware = fw;
  c.serial_number = 4242;
  c.parameters.set_raw(Parameter::PacketsStreamed, 0);
  return c;
}

struct Sent {
  TimePoint at;
  codec::CanFrame frame;
};

class Harness {
 public:
  explicit Harness(const DeviceConfig& config = quiet_config())
      : fw(config.firmware),
        pmu(
            config,
            [this](const codec::CanFrame& f) {
              sent.push_back({now, f});
            },
            start) {}
  Harness(const Harness&) = delete;
  Harness& operator=(const Harness&) = delete;

  // Arbitrary, far from the epoch: nothing may depend on the clock's origin.
  const TimePoint start = TimePoint{} + 1000h;
  TimePoint now = start;
  std::vector<Sent> sent;
  codec::FirmwareVersion fw;
  PmuModel pmu;  // last: its sink uses the members above

  // Moves the fake clock in `step`s (one tick each) until `total` has passed.
  void run(Duration total, Duration step = 10ms) {
    const TimePoint end = now + total;
    while (now < end) {
      now = std::min(now + step, end);
      pmu.tick(now);
    }
  }
  void tick_at(Duration since_start) {
    now = start + since_start;
    pmu.tick(now);
  }

  void deliver(const codec::CanFrame& f) { pmu.on_frame(f, now); }
  void deliver(const codec::Encoded& e) {
    ASSERT_TRUE(e.ok()) << e.error().describe();
    pmu.on_frame(*e, now);
  }

  // Frames sent so far, decoded with the unit's firmware; clears the list.
  std::vector<codec::PmuMessage> take() {
    std::vector<codec::PmuMessage> out;
    for (const auto& s : sent) {
      auto m = codec::decode(s.frame, fw);
      EXPECT_TRUE(m.ok()) << m.error().describe();
      if (m) out.push_back(*m);
    }
    sent.clear();
    return out;
  }

  // Sends a zero-length get and returns the single reply's payload.
  template <class T>
  std::optional<T> get(PacketId packet, std::uint16_t to = 1) {
    sent.clear();
    deliver(codec::encode_get(packet, to));
    const auto replies = take();
    EXPECT_EQ(replies.size(), 1u) << "replies to packet " << int(static_cast<std::uint8_t>(packet));
    if (replies.size() != 1) return std::nullopt;
    EXPECT_EQ(replies[0].packet, packet);
    EXPECT_FALSE(replies[0].request);
    const T* p = std::get_if<T>(&replies[0].payload);
    EXPECT_NE(p, nullptr);
    if (!p) return std::nullopt;
    return *p;
  }

  std::uint32_t get_raw(Parameter p, std::uint16_t to = 1) {
    const auto v = get<codec::ParameterValue>(codec::spec_of(p).packet, to);
    return v ? v->raw : 0xFFFFFFFFu;
  }

  Telemetry measured() const { return pmu.telemetry(); }
};

// A PMU frame with arbitrary bytes (for lengths the codec's encoders refuse to produce).
inline codec::CanFrame raw_frame(PacketId packet, std::uint16_t address, std::initializer_list<std::uint8_t> bytes) {
  codec::CanFrame f;
  f.id = codec::make_id(packet, address);
  f.extended = true;
  f.length = static_cast<std::uint8_t>(bytes.size());
  std::uint8_t i = 0;
  for (auto b : bytes) f.data[i++] = b;
  return f;
}

inline std::vector<PacketId> packets(const std::vector<codec::PmuMessage>& msgs) {
  std::vector<PacketId> out;
  for (const auto& m : msgs) out.push_back(m.packet);
  return out;
}

}  // namespace pmu::sim::test
