// Fault injection: silence, random loss (seeded), delay, wrong data length; and the sink's
// freedom to call back into the model.
#include <gtest/gtest.h>

#include <random>

#include "sim_harness.hpp"

namespace pmu::sim::test {
namespace {

TEST(SimFaults, SilenceAnswersNothingStreamsNothingDoesNothing) {
  Harness h(DeviceConfig{});  // streaming every 1 s
  Faults f;
  f.silent = true;
  h.pmu.set_faults(f);
  h.deliver(codec::encode_get(PacketId::Serial, 1));
  h.deliver(codec::encode_set(Parameter::AvionicsVoltage, 20.0, 1));
  h.deliver(codec::encode_disable_outputs(codec::output_bit::All, 1));
  codec::CanFrame unknown = raw_frame(PacketId::Reset, 1, {});
  unknown.id = 0x1E270001;  // packet 0x27: not in table 1
  h.deliver(unknown);
  h.run(5s);
  EXPECT_TRUE(h.sent.empty());
  EXPECT_EQ(h.pmu.counters().ignored_silent, 4u);
  EXPECT_EQ(h.pmu.counters().unknown_packet, 0u);
  EXPECT_EQ(h.pmu.counters().suppressed, 5u * 5u);
  EXPECT_EQ(h.pmu.parameter(Parameter::AvionicsVoltage), 120u) << "a unit off the bus hears nothing";
  EXPECT_EQ(h.pmu.outputs(), codec::output_bit::All);

  h.pmu.set_faults(Faults{});
  EXPECT_EQ(h.get<codec::SerialNumber>(PacketId::Serial)->serial_number, 1);
  h.run(1s);
  EXPECT_EQ(h.sent.size(), 5u) << "streaming resumes on its schedule, without a catch-up burst";
}

struct LossCase {
  double p;
  std::size_t min_out, max_out;  // of 1000 replies
};
const LossCase kLoss[] = {
    {0.0, 1000, 1000},
    {1.0, 0, 0},
    {0.5, 430, 570},
    {0.1, 860, 940},
};

TEST(SimFaults, LossDropsFramesWithTheGivenProbability) {
  for (const auto& c : kLoss) {
    SCOPED_TRACE(c.p);
    Harness h;
    Faults f;
    f.loss_probability = c.p;
    f.loss_seed = 12345;
    h.pmu.set_faults(f);
    for (int i = 0; i < 1000; ++i) h.deliver(codec::encode_get(PacketId::Serial, 1));
    EXPECT_GE(h.sent.size(), c.min_out);
    EXPECT_LE(h.sent.size(), c.max_out);
    EXPECT_EQ(h.pmu.counters().lost + h.sent.size(), 1000u);
    EXPECT_EQ(h.pmu.counters().handled, 1000u) << "loss is on the way out, not in";
  }
}

TEST(SimFaults, LossIsReproducibleForASeed) {
  const auto pattern = [](std::uint64_t seed) {
    Harness h;
    Faults f;
    f.loss_probability = 0.5;
    f.loss_seed = seed;
    h.pmu.set_faults(f);
    std::vector<bool> out;
    for (int i = 0; i < 64; ++i) {
      h.sent.clear();
      h.deliver(codec::encode_get(PacketId::Serial, 1));
      out.push_back(!h.sent.empty());
    }
    return out;
  };
  EXPECT_EQ(pattern(7), pattern(7));
  EXPECT_NE(pattern(7), pattern(8));
}

TEST(SimFaults, DelayHoldsFramesUntilTick) {
  Harness h;
  Faults f;
  f.delay = 250ms;
  h.pmu.set_faults(f);
  const TimePoint asked = h.now;
  h.deliver(codec::encode_get(PacketId::Serial, 1));
  h.now += 100ms;
  h.deliver(codec::encode_get(PacketId::Firmware, 1));
  EXPECT_TRUE(h.sent.empty());
  EXPECT_EQ(h.pmu.frames_held(), 2u);
  EXPECT_EQ(h.pmu.next_deadline(), asked + 250ms);

  h.now = asked + 249ms;
  h.pmu.tick(h.now);
  EXPECT_TRUE(h.sent.empty());
  h.now = asked + 250ms;
  h.pmu.tick(h.now);
  ASSERT_EQ(h.sent.size(), 1u);
  h.now = asked + 350ms;
  h.pmu.tick(h.now);
  ASSERT_EQ(h.sent.size(), 2u);
  EXPECT_EQ(h.sent[0].at, asked + 250ms);
  EXPECT_EQ(h.sent[1].at, asked + 350ms);
  EXPECT_EQ(packets(h.take()), (std::vector<PacketId>{PacketId::Serial, PacketId::Firmware}));
  EXPECT_EQ(h.pmu.frames_held(), 0u);
}

TEST(SimFaults, SilenceKeepsHeldFramesOffTheBus) {
  Harness h;
  Faults f;
  f.delay = 100ms;
  h.pmu.set_faults(f);
  h.deliver(codec::encode_get(PacketId::Serial, 1));
  f.silent = true;
  h.pmu.set_faults(f);
  h.run(200ms);
  EXPECT_TRUE(h.sent.empty());
  EXPECT_EQ(h.pmu.frames_held(), 0u);
  EXPECT_EQ(h.pmu.counters().suppressed, 1u);
}

TEST(SimFaults, DelayShortenedKeepsOrder) {
  Harness h;
  Faults f;
  f.delay = 1s;
  h.pmu.set_faults(f);
  h.deliver(codec::encode_get(PacketId::Serial, 1));
  f.delay = Duration::zero();
  h.pmu.set_faults(f);
  h.deliver(codec::encode_get(PacketId::Firmware, 1));
  EXPECT_TRUE(h.sent.empty()) << "a CAN transmit queue does not reorder";
  h.run(1s);
  EXPECT_EQ(packets(h.take()), (std::vector<PacketId>{PacketId::Serial, PacketId::Firmware}));
}

struct WrongLengthCase {
  std::uint8_t length;
};
const WrongLengthCase kWrongLengths[] = {{0}, {3}, {8}};

TEST(SimFaults, WrongLengthTelemetry) {
  for (const auto& c : kWrongLengths) {
    SCOPED_TRACE(int(c.length));
    Harness h(DeviceConfig{});
    Faults f;
    f.telemetry_length = c.length;
    h.pmu.set_faults(f);
    h.run(1s);  // one streamed burst
    h.deliver(codec::encode_get(PacketId::Voltages, 1));
    h.deliver(codec::encode_get(PacketId::AvionicsVoltage, 1));
    ASSERT_EQ(h.sent.size(), 7u);
    for (std::size_t i = 0; i < 6; ++i) {
      EXPECT_EQ(h.sent[i].frame.length, c.length);
      const auto d = codec::decode(h.sent[i].frame, h.fw);
      if (c.length == 0) {
        ASSERT_TRUE(d.ok());
        EXPECT_TRUE(d->request) << "a zero-length telemetry frame reads as a get";
      } else {
        ASSERT_FALSE(d.ok());
        EXPECT_EQ(d.error().kind, codec::DecodeErrorKind::WrongLength);
      }
    }
    const auto reply = codec::decode(h.sent[6].frame, h.fw);
    ASSERT_TRUE(reply.ok()) << "parameter replies are not telemetry";
    EXPECT_EQ(std::get<codec::ParameterValue>(reply->payload).raw, 120u);
  }
}

TEST(SimRobustness, EveryFrameLandsInExactlyOneCounter) {
  // Seeded random frames: group 0x1E or not, any packet byte, any length, remote or not, to
  // us, to another unit or broadcast. Nothing crashes and the "in" counters add up.
  std::mt19937 rng(2024);
  const auto byte = [&] { return static_cast<std::uint8_t>(rng() & 0xFF); };
  Harness h(quiet_config(5));
  Plant p;
  p.engine_starts_after.reset();
  h.pmu.set_plant(p, h.now);
  const std::uint16_t addresses[] = {5, 6, codec::kBroadcastAddress};
  for (int i = 0; i < 20000; ++i) {
    codec::CanFrame f;
    const std::uint32_t group = (rng() % 8 == 0) ? 0x1Fu : 0x1Eu;
    const auto packet = static_cast<std::uint32_t>((rng() % 2 == 0) ? (rng() % 0x27u) : byte());
    f.id = (group << 24) | (packet << 16) | addresses[rng() % 3];
    f.extended = rng() % 16 != 0;
    f.remote = rng() % 32 == 0;
    f.length = static_cast<std::uint8_t>(rng() % 10);  // 9: a bad length code
    for (auto& d : f.data) d = byte();
    h.now += 1ms;
    h.deliver(f);
    if (h.pmu.address() != 5) h.deliver(codec::encode_set(Parameter::CanAddress, 5, h.pmu.address()));
  }
  const Counters c = h.pmu.counters();
  EXPECT_EQ(c.frames_in, c.handled + c.not_pmu + c.other_address + c.unknown_packet + c.wrong_length + c.malformed +
                             c.rejected_sets + c.unsupported + c.not_commands + c.ignored_commands + c.ignored_silent);
  EXPECT_GT(c.handled, 0u);
  EXPECT_GT(c.wrong_length, 0u);
  EXPECT_GT(c.rejected_sets, 0u);
  EXPECT_EQ(c.encode_errors, 0u);
  EXPECT_EQ(c.frames_out, h.sent.size());
}

TEST(SimSink, MayCallBackIntoTheModel) {
  // An in-process bus may hand the model a reply while the model is still sending: frames
  // stay in order and none is lost.
  std::vector<codec::CanFrame> out;
  std::unique_ptr<PmuModel> pmu;
  const TimePoint t{};
  bool asked = false;
  pmu = std::make_unique<PmuModel>(
      quiet_config(),
      [&](const codec::CanFrame& f) {
        out.push_back(f);
        if (!asked) {
          asked = true;
          pmu->on_frame(*codec::encode_get(PacketId::Firmware, 1), t);
        }
      },
      t);
  pmu->on_frame(*codec::encode_measurement_request(codec::group_bit::Voltages | codec::group_bit::Currents, 1), t);
  std::vector<PacketId> ids;
  for (const auto& f : out) ids.push_back(codec::parse_id(f.id, f.extended).id->packet);
  EXPECT_EQ(ids, (std::vector<PacketId>{PacketId::Voltages, PacketId::Currents, PacketId::Firmware}));
}

}  // namespace
}  // namespace pmu::sim::test
