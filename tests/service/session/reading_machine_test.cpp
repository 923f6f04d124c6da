// The reading state machine (reading_machine.hpp): rounds, failure and retry, restarts, and
// what absorbing a frame changes.
#include <gtest/gtest.h>

#include "pmu/codec/encode.hpp"
#include "pmu/session/reading_machine.hpp"

namespace pmu::service::reading_machine_test {
namespace {

using namespace std::chrono_literals;
using codec::PacketId;
using Time = std::chrono::steady_clock::time_point;
using Progress = ReadingMachine::Progress;

const Time t0 = Time{} + 1h;

codec::PmuMessage decoded(const codec::Encoded& f) {
  auto m = codec::decode(*f, codec::kCurrentFirmware);
  EXPECT_TRUE(static_cast<bool>(m));
  return m ? *m : codec::PmuMessage{};
}

TEST(ReadingMachine, ARoundGetsIdentityThenEveryStoredValue) {
  const auto& p = ReadingMachine::packets();
  ASSERT_EQ(p.size(), 15u);  // serial, firmware, 11 parameters, outputs, generation
  EXPECT_EQ(p.front(), PacketId::Serial);
  EXPECT_EQ(p[1], PacketId::Firmware);
  EXPECT_EQ(p[13], PacketId::Outputs);
  EXPECT_EQ(p.back(), PacketId::Generation);
}

TEST(ReadingMachine, EveryAnswerCompletesTheRound) {
  ReadingMachine r;
  const auto round = r.start();
  for (std::size_t i = 1; i < ReadingMachine::packets().size(); ++i)
    EXPECT_EQ(r.on_result(round, true, t0, 1s), Progress::Pending);
  EXPECT_FALSE(r.running());
  EXPECT_EQ(r.on_result(round, true, t0, 1s), Progress::Done);
  EXPECT_TRUE(r.running());
  EXPECT_EQ(r.on_result(round, true, t0, 1s), Progress::Ignored) << "nothing after Done";
}

TEST(ReadingMachine, OneSilentGetFailsTheRoundUntilTheRetryIsDue) {
  ReadingMachine r;
  const auto round = r.start();
  EXPECT_EQ(r.on_result(round, true, t0, 2s), Progress::Pending);
  EXPECT_EQ(r.on_result(round, false, t0, 2s), Progress::Failed);
  EXPECT_TRUE(r.failed());
  EXPECT_EQ(r.on_result(round, true, t0, 2s), Progress::Ignored) << "the failed round's stragglers";
  EXPECT_FALSE(r.retry_due(t0 + 1999ms));
  EXPECT_TRUE(r.retry_due(t0 + 2s));
  const auto again = r.start();
  EXPECT_FALSE(r.failed());
  EXPECT_FALSE(r.retry_due(t0 + 1h));
  EXPECT_EQ(r.on_result(again, true, t0, 2s), Progress::Pending);
}

TEST(ReadingMachine, ARereadRestartsTheRoundAndIgnoresTheOldOne) {
  ReadingMachine r;
  auto first = r.start();
  for (std::size_t i = 0; i < ReadingMachine::packets().size(); ++i) r.on_result(first, true, t0, 1s);
  ASSERT_TRUE(r.running());
  const auto second = r.start();  // after a reset or OFFLINE
  EXPECT_FALSE(r.running());
  EXPECT_EQ(r.on_result(first, true, t0, 1s), Progress::Ignored);
  for (std::size_t i = 1; i < ReadingMachine::packets().size(); ++i) r.on_result(second, true, t0, 1s);
  EXPECT_FALSE(r.running()) << "the old round's answer did not count";
  EXPECT_EQ(r.on_result(second, true, t0, 1s), Progress::Done);
}

TEST(ReadingMachine, AbsorbingAFrameSaysWhatChanged) {
  ReadingMachine r;
  EXPECT_FALSE(r.firmware());
  auto c = r.absorb(decoded(codec::encode_serial(4001, 1)));
  EXPECT_TRUE(c.info);
  EXPECT_FALSE(c.config);
  EXPECT_FALSE(r.firmware()) << "a serial alone says nothing of the firmware";
  c = r.absorb(decoded(codec::encode_serial(4001, 1)));
  EXPECT_FALSE(c.info) << "the same serial again";

  codec::FirmwareInfo fw;
  fw.firmware_major = 1;
  fw.firmware_minor = 14;
  EXPECT_TRUE(r.absorb(decoded(codec::encode_firmware(fw, 1))).info);
  EXPECT_EQ(r.firmware(), (codec::FirmwareVersion{1, 14}));

  c = r.absorb(decoded(codec::encode_parameter_reply(codec::Parameter::AvionicsVoltage, 240, 1)));
  EXPECT_TRUE(c.config);
  EXPECT_DOUBLE_EQ(r.config().value(codec::Parameter::AvionicsVoltage), 24.0);
  EXPECT_FALSE(r.absorb(decoded(codec::encode_parameter_reply(codec::Parameter::AvionicsVoltage, 240, 1))).config);

  EXPECT_TRUE(r.absorb(decoded(codec::encode_outputs_reply(0x05, 1))).config);
  EXPECT_EQ(r.config().outputs, 0x05);
  EXPECT_TRUE(r.absorb(decoded(codec::encode_generation_reply(true, 1))).config);
  EXPECT_FALSE(r.absorb(decoded(codec::encode_voltages(codec::Voltages{}, 1))).config) << "telemetry is not config";
}

}  // namespace
}  // namespace pmu::service::reading_machine_test
