// The executor's table (command_plan.hpp) without a bus: for every kind, the frame it sends,
// the packet that answers or reads it back, how it is queued, and what the check makes of a
// matching and of a differing answer. The runner is covered against the simulator in
// command_test.cpp.
#include <gtest/gtest.h>

#include <cstdio>
#include <string>

#include "frame_text.hpp"
#include "pmu/codec/decode.hpp"
#include "pmu/codec/encode.hpp"
#include "pmu/dispatch/command_executor.hpp"
#include "support/recording_sink.hpp"

namespace pmu::service {
namespace {

using codec::PacketId;

CommandRequest request(CommandAction action, std::uint16_t address = 1) {
  CommandRequest r;
  r.request_id = "p-1";
  r.bus = "can0";
  r.address = address;
  r.action = action;
  return r;
}

// A message as the device would answer: `packet` carrying `bytes` from `address`.
codec::PmuMessage answer(PacketId packet, std::initializer_list<std::uint8_t> bytes, std::uint16_t address = 1) {
  codec::CanFrame f;
  f.id = codec::make_id(packet, address);
  f.extended = true;
  f.length = static_cast<std::uint8_t>(bytes.size());
  std::size_t i = 0;
  for (auto b : bytes) f.data[i++] = b;
  auto m = codec::decode(f, codec::kCurrentFirmware);
  EXPECT_TRUE(static_cast<bool>(m)) << hex(f);
  return m ? *m : codec::PmuMessage{};
}

// The same from the codec's encoder, for packets whose layout is not the point.
codec::PmuMessage answer(const codec::Encoded& f) {
  auto m = codec::decode(*f, codec::kCurrentFirmware);
  EXPECT_TRUE(static_cast<bool>(m));
  return m ? *m : codec::PmuMessage{};
}

codec::FirmwareInfo firmware_1_14() {
  codec::FirmwareInfo f;
  f.firmware_major = 1;
  f.firmware_minor = 14;
  f.build_year = 2025;
  f.build_month = 3;
  f.build_day = 9;
  return f;
}

struct PlanCase {
  const char* name;
  CommandAction action;
  const char* frame;  // candump notation, the spec's bytes (v1.9 tables 1 and sections 5.x)
  std::string what;
  std::optional<PacketId> answer;
  std::optional<PacketId> read_back;
  bool idempotent;
  bool urgent;
};

TEST(CommandPlan, EveryKindHasItsFrameItsAnswerAndItsQueueing) {
  const PlanCase cases[] = {
      {"get avionics_voltage", action::Get{PacketId::AvionicsVoltage}, "1E100001#", "get", PacketId::AvionicsVoltage,
       std::nullopt, true, false},
      {"set avionics_voltage 24.0", action::SetParameter{codec::Parameter::AvionicsVoltage, 240}, "1E100001#F0",
       "command", std::nullopt, PacketId::AvionicsVoltage, false, false},
      {"set outputs 0x03", action::SetOutputs{0x03}, "1E200001#03", "command", std::nullopt, PacketId::Outputs, false,
       false},
      {"enable payload", action::EnableOutputs{0x02}, "1E210001#02", "command", std::nullopt, PacketId::Outputs, false,
       false},
      {"disable payload", action::DisableOutputs{0x02}, "1E220001#02", "command", std::nullopt, PacketId::Outputs,
       false, false},
      {"generation on", action::SetGeneration{true}, "1E230001#01", "command", std::nullopt, PacketId::Generation,
       false, false},
      {"measure currents+status", action::RequestMeasurements{0x12}, "1E0F0001#12", "measurement request",
       PacketId::Currents, std::nullopt, false, false},
      {"engine start", action::EngineStart{}, "1E240001#", "engine start", std::nullopt, std::nullopt, false, false},
      {"engine stop", action::EngineStop{}, "1E250001#", "engine stop", std::nullopt, std::nullopt, false, true},
      {"reset", action::Reset{}, "1E260001#", "reset", std::nullopt, std::nullopt, false, false},
      {"get serial", action::GetSerial{}, "1E300001#", "get", PacketId::Serial, std::nullopt, true, false},
      {"get firmware", action::GetFirmware{}, "1E310001#", "get", PacketId::Firmware, std::nullopt, true, false},
  };
  std::size_t kinds = 0;
  for (const auto& c : cases) {
    SCOPED_TRACE(c.name);
    const auto p = plan_command(request(c.action), DeviceFacts{codec::kCurrentFirmware, 2.5});
    EXPECT_EQ(hex(p.frame), c.frame);
    EXPECT_EQ(p.what, c.what);
    EXPECT_EQ(p.answer, c.answer);
    EXPECT_EQ(p.read_back.has_value(), c.read_back.has_value());
    if (p.read_back && c.read_back) {
      EXPECT_EQ(p.read_back->packet, *c.read_back);
      EXPECT_EQ(p.read_back->address, 1);
    }
    EXPECT_EQ(p.idempotent, c.idempotent);
    EXPECT_EQ(p.urgent, c.urgent);
    EXPECT_FALSE(p.alias);
    EXPECT_TRUE(p.check);
    ++kinds;
  }
  EXPECT_EQ(kinds, kCommandKindCount);
}

struct CheckCase {
  const char* name;
  CommandAction action;
  std::optional<codec::PmuMessage> reply;  // nullopt: a frame that is only sent
  CommandResult result;
  std::string reason;
  std::optional<double> value;
  std::string value_text;
};

TEST(CommandPlan, TheCheckTurnsTheAnswerIntoTheReply) {
  const CheckCase cases[] = {
      {"get a parameter", action::Get{PacketId::AvionicsVoltage}, answer(PacketId::AvionicsVoltage, {120}),
       CommandResult::Completed, "", 12.0, ""},
      {"get outputs", action::Get{PacketId::Outputs}, answer(PacketId::Outputs, {0x05}), CommandResult::Completed, "",
       5.0, "avionics_servo,charger_a"},
      {"get generation", action::Get{PacketId::Generation}, answer(PacketId::Generation, {1}), CommandResult::Completed,
       "", 1.0, "on"},
      {"get telemetry", action::Get{PacketId::Currents}, answer(codec::encode_currents(codec::Currents{}, 1)),
       CommandResult::Completed, "published on pmu/currents", std::nullopt, ""},
      {"set read back equal", action::SetParameter{codec::Parameter::AvionicsVoltage, 240},
       answer(PacketId::AvionicsVoltage, {240}), CommandResult::Completed, "", 24.0, ""},
      {"set read back different", action::SetParameter{codec::Parameter::AvionicsVoltage, 240},
       answer(PacketId::AvionicsVoltage, {120}), CommandResult::Failed, "device reports 12 after the set, not 24", 12.0,
       ""},
      {"set outputs equal", action::SetOutputs{0x03}, answer(PacketId::Outputs, {0x03}), CommandResult::Completed, "",
       3.0, "on: avionics_servo,payload"},
      {"set outputs more on", action::SetOutputs{0x03}, answer(PacketId::Outputs, {0x07}), CommandResult::Failed,
       "outputs on after the command: avionics_servo,payload,charger_a", 7.0, "on: avionics_servo,payload,charger_a"},
      {"enable: others may stay on", action::EnableOutputs{0x02}, answer(PacketId::Outputs, {0x03}),
       CommandResult::Completed, "", 3.0, "on: avionics_servo,payload"},
      {"enable: still off", action::EnableOutputs{0x02}, answer(PacketId::Outputs, {0x01}), CommandResult::Failed,
       "outputs on after the command: avionics_servo", 1.0, "on: avionics_servo"},
      {"disable: off", action::DisableOutputs{0x02}, answer(PacketId::Outputs, {0x01}), CommandResult::Completed, "",
       1.0, "on: avionics_servo"},
      {"disable: still on", action::DisableOutputs{0x02}, answer(PacketId::Outputs, {0x02}), CommandResult::Failed,
       "outputs on after the command: payload", 2.0, "on: payload"},
      {"generation on", action::SetGeneration{true}, answer(PacketId::Generation, {1}), CommandResult::Completed, "",
       1.0, "on"},
      {"generation still off", action::SetGeneration{true}, answer(PacketId::Generation, {0}), CommandResult::Failed,
       "generation still off", std::nullopt, ""},
      {"measure", action::RequestMeasurements{0x01}, answer(codec::encode_voltages(codec::Voltages{}, 1)),
       CommandResult::Completed, "measurements published on their topics", std::nullopt, ""},
      {"engine start", action::EngineStart{}, std::nullopt, CommandResult::Completed,
       "start sent; the starter cranks for up to 2.5 s", std::nullopt, ""},
      {"engine stop", action::EngineStop{}, std::nullopt, CommandResult::Completed, "stop sent", std::nullopt, ""},
      {"reset", action::Reset{}, std::nullopt, CommandResult::Completed, "reset sent; re-reading the device",
       std::nullopt, ""},
      {"serial", action::GetSerial{}, answer(codec::encode_serial(4001, 1)), CommandResult::Completed, "", 4001.0,
       "4001"},
      {"firmware", action::GetFirmware{}, answer(codec::encode_firmware(firmware_1_14(), 1)), CommandResult::Completed,
       "", 1.14, "1.14 built 2025-03-09"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.name);
    const auto p = plan_command(request(c.action), DeviceFacts{codec::kCurrentFirmware, 2.5});
    const Verdict v = p.check(c.reply ? &*c.reply : nullptr);
    EXPECT_EQ(v.result, c.result);
    EXPECT_EQ(v.reason, c.reason);
    EXPECT_EQ(v.value.has_value(), c.value.has_value());
    if (v.value && c.value) {
      EXPECT_NEAR(*v.value, *c.value, 1e-9);
    }
    EXPECT_EQ(v.value_text, c.value_text);
  }
}

TEST(CommandPlan, ACanAddressChangeReadsBackAtTheNewAddressUnderAnAlias) {
  const auto p = plan_command(request(action::SetParameter{codec::Parameter::CanAddress, 7}, 1), DeviceFacts{});
  EXPECT_EQ(hex(p.frame).substr(0, 9), "1E1B0001#");  // sent to the old address
  ASSERT_TRUE(p.read_back);
  EXPECT_EQ(p.read_back->address, 7);
  EXPECT_EQ(p.alias, std::optional<std::uint16_t>(7));
  EXPECT_TRUE(p.on_completed) << "the session moves to the new address once verified";
}

// Named defect (fixed): the alias under which a queued CAN address change expects its answer
// was dropped by any other read-back command that failed before it ran.
TEST(CommandRun, AnotherCommandsFailureLeavesAQueuedAddressChangesAliasAlone) {
  using namespace std::chrono_literals;
  test::RecordingSink sink;
  const auto start = SteadyTime{} + 1h;
  DeviceConfig dc;
  dc.address = 1;
  Timeouts timeouts;
  DeviceSession s(
      {"can0", 1}, dc, timeouts, sink, [](const codec::CanFrame&) { return transport::SendResult{}; }, start);
  auto t = start;
  for (int i = 0; i < 100 && s.queued() > 0; ++i) s.tick(t += 100ms, {});  // a silent device: the reading round fails
  ASSERT_EQ(s.queued(), 0u);

  std::vector<CommandReplyData> replies;
  const ReplyFn collect = [&replies](const CommandReplyData& d) { replies.push_back(d); };
  CommandRequest outputs = request(action::SetOutputs{0x01});
  outputs.expires = t + 10s;
  execute_command(s, outputs, t, timeouts, collect);  // sent; its read-back now waits for 0x20
  CommandRequest move = request(action::SetParameter{codec::Parameter::CanAddress, 7});
  move.expires = t + 10s;
  execute_command(s, move, t, timeouts, collect);
  EXPECT_EQ(s.alias(), std::optional<std::uint16_t>(7));
  for (int i = 0; i < 100 && replies.empty(); ++i) s.tick(t += 100ms, {});
  ASSERT_EQ(replies.size(), 1u);
  EXPECT_EQ(replies[0].kind, CommandKind::SetOutputs);
  EXPECT_EQ(replies[0].result, CommandResult::Timeout);
  EXPECT_EQ(s.alias(), std::optional<std::uint16_t>(7)) << "the address change still waits for its answer there";
}

}  // namespace
}  // namespace pmu::service
