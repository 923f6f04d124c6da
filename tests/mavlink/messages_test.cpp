// Each message through FrameWriter and Parser and back, field by field; payloads shorter
// than the definition (truncated, or from a sender without the extensions) read as zero.

#include <gtest/gtest.h>

#include <cmath>
#include <functional>

#include "frame_builder.hpp"
#include "pmu/mavlink/messages.hpp"
#include "pmu/mavlink/parser.hpp"
#include "pmu/mavlink/writer.hpp"

namespace pmu::mavlink {
namespace {

using test::parse_all;
using test::raw_v2;

template <class M>
M round_trip(const M& message) {
  FrameWriter writer(7, 180);
  Parser parser;
  const auto results = parse_all(parser, writer.write(message));
  EXPECT_EQ(results.size(), 1U);
  const Frame* frame = results.empty() ? nullptr : std::get_if<Frame>(&results[0]);
  EXPECT_NE(frame, nullptr);
  if (frame == nullptr) return M{};
  EXPECT_EQ(frame->msgid, M::kId);
  auto back = decode<M>(*frame);
  EXPECT_TRUE(back.has_value());
  return back.value_or(M{});
}

bool same_float(float a, float b) { return (std::isnan(a) && std::isnan(b)) || a == b; }

TEST(MavlinkMessages, Heartbeat) {
  Heartbeat m;
  m.type = mav_type::kBattery;
  m.autopilot = mav_autopilot::kInvalid;
  m.base_mode = 0x81;
  m.custom_mode = 0xDEADBEEF;
  m.system_status = mav_state::kCritical;
  const auto b = round_trip(m);
  EXPECT_EQ(b.type, m.type);
  EXPECT_EQ(b.autopilot, m.autopilot);
  EXPECT_EQ(b.base_mode, m.base_mode);
  EXPECT_EQ(b.custom_mode, m.custom_mode);
  EXPECT_EQ(b.system_status, m.system_status);
  EXPECT_EQ(b.mavlink_version, kMavlinkVersion);
}

TEST(MavlinkMessages, ParamRequestReadAndList) {
  ParamRequestRead r;
  r.target_system = 1;
  r.target_component = 180;
  r.param_id = "PMU_OUT_28V_SET";
  r.param_index = -1;
  const auto br = round_trip(r);
  EXPECT_EQ(br.target_system, 1);
  EXPECT_EQ(br.target_component, 180);
  EXPECT_EQ(br.param_id, r.param_id);
  EXPECT_EQ(br.param_index, -1);

  ParamRequestList l;
  l.target_system = 1;
  l.target_component = mav_component::kAll;
  const auto bl = round_trip(l);
  EXPECT_EQ(bl.target_system, 1);
  EXPECT_EQ(bl.target_component, 0);
}

TEST(MavlinkMessages, ParamIdOfSixteenCharsHasNoTerminatorAndLongerIsCut) {
  for (const auto& [id, expected] : std::vector<std::pair<std::string, std::string>>{
           {"ABCDEFGHIJKLMNOP", "ABCDEFGHIJKLMNOP"}, {"ABCDEFGHIJKLMNOPQ", "ABCDEFGHIJKLMNOP"}, {"", ""}}) {
    ParamValue v;
    v.param_id = id;
    v.param_value = 1.5F;
    v.param_count = 3;
    v.param_index = 2;
    const auto b = round_trip(v);
    EXPECT_EQ(b.param_id, expected);
    EXPECT_EQ(b.param_type, mav_param_type::kReal32);  // the byte after the id is intact
    EXPECT_EQ(b.param_count, 3);
  }
}

TEST(MavlinkMessages, ParamValueAndSet) {
  ParamValue v;
  v.param_id = "PMU_BAT_A_CAP";
  v.param_value = -12.25F;
  v.param_count = 150;
  v.param_index = 149;
  const auto bv = round_trip(v);
  EXPECT_EQ(bv.param_id, v.param_id);
  EXPECT_EQ(bv.param_value, v.param_value);
  EXPECT_EQ(bv.param_type, mav_param_type::kReal32);
  EXPECT_EQ(bv.param_count, 150);
  EXPECT_EQ(bv.param_index, 149);

  ParamSet s;
  s.target_system = 1;
  s.target_component = 180;
  s.param_id = "PMU_OUT_28V_SET";
  s.param_value = 28.5F;
  const auto bs = round_trip(s);
  EXPECT_EQ(bs.target_system, 1);
  EXPECT_EQ(bs.target_component, 180);
  EXPECT_EQ(bs.param_id, s.param_id);
  EXPECT_EQ(bs.param_value, 28.5F);
  EXPECT_EQ(bs.param_type, mav_param_type::kReal32);
}

TEST(MavlinkMessages, CommandLongAndAck) {
  CommandLong c;
  c.target_system = 1;
  c.target_component = 180;
  c.command = mav_cmd::kDoEngineControl;
  c.confirmation = 2;
  c.param = {1.0F, 0.0F, 12.5F, 1.0F, NAN, -3.0F, 1e30F};
  const auto bc = round_trip(c);
  EXPECT_EQ(bc.target_system, 1);
  EXPECT_EQ(bc.target_component, 180);
  EXPECT_EQ(bc.command, mav_cmd::kDoEngineControl);
  EXPECT_EQ(bc.confirmation, 2);
  for (std::size_t i = 0; i < 7; ++i) EXPECT_TRUE(same_float(bc.param[i], c.param[i])) << i;

  CommandAck a;
  a.command = mav_cmd::kSetMessageInterval;
  a.result = mav_result::kInProgress;
  a.progress = not_provided::kProgress;
  a.result_param2 = -77;
  a.target_system = 255;
  a.target_component = 190;
  const auto ba = round_trip(a);
  EXPECT_EQ(ba.command, a.command);
  EXPECT_EQ(ba.result, a.result);
  EXPECT_EQ(ba.progress, 255);
  EXPECT_EQ(ba.result_param2, -77);
  EXPECT_EQ(ba.target_system, 255);
  EXPECT_EQ(ba.target_component, 190);
}

TEST(MavlinkMessages, BatteryStatusDefaultsAreNotProvided) {
  const auto b = round_trip(BatteryStatus{});
  EXPECT_EQ(b.temperature, INT16_MAX);
  for (auto v : b.voltages) EXPECT_EQ(v, UINT16_MAX);
  EXPECT_EQ(b.current_battery, -1);
  EXPECT_EQ(b.current_consumed, -1);
  EXPECT_EQ(b.energy_consumed, -1);
  EXPECT_EQ(b.battery_remaining, -1);
  EXPECT_EQ(b.time_remaining, 0);
  for (auto v : b.voltages_ext) EXPECT_EQ(v, 0);
}

TEST(MavlinkMessages, BatteryStatusEveryField) {
  BatteryStatus m;
  m.id = 10;
  m.battery_function = mav_battery_function::kPropulsion;
  m.type = mav_battery_type::kLion;
  m.temperature = -1234;
  for (std::size_t i = 0; i < 10; ++i) m.voltages[i] = static_cast<std::uint16_t>(3600 + i);
  m.current_battery = -2500;
  m.current_consumed = 123456;
  m.energy_consumed = 7890123;
  m.battery_remaining = 87;
  m.time_remaining = 3600;
  m.charge_state = mav_battery_charge_state::kCharging;
  m.voltages_ext = {3700, 3701, 1, 0};
  m.mode = mav_battery_mode::kHotSwap;
  m.fault_bitmask = mav_battery_fault::kOverTemperature | mav_battery_fault::kCellFail;
  const auto b = round_trip(m);
  EXPECT_EQ(b.id, 10);
  EXPECT_EQ(b.battery_function, m.battery_function);
  EXPECT_EQ(b.type, m.type);
  EXPECT_EQ(b.temperature, -1234);
  EXPECT_EQ(b.voltages, m.voltages);
  EXPECT_EQ(b.current_battery, -2500);
  EXPECT_EQ(b.current_consumed, 123456);
  EXPECT_EQ(b.energy_consumed, 7890123);
  EXPECT_EQ(b.battery_remaining, 87);
  EXPECT_EQ(b.time_remaining, 3600);
  EXPECT_EQ(b.charge_state, m.charge_state);
  EXPECT_EQ(b.voltages_ext, m.voltages_ext);
  EXPECT_EQ(b.mode, m.mode);
  EXPECT_EQ(b.fault_bitmask, m.fault_bitmask);
}

TEST(MavlinkMessages, StatustextFiftyCharsWithoutTerminator) {
  Statustext m;
  m.severity = mav_severity::kCritical;
  m.text = std::string(50, 'x');
  m.id = 513;
  m.chunk_seq = 2;
  const auto b = round_trip(m);
  EXPECT_EQ(b.severity, mav_severity::kCritical);
  EXPECT_EQ(b.text, m.text);
  EXPECT_EQ(b.id, 513);
  EXPECT_EQ(b.chunk_seq, 2);
}

TEST(MavlinkMessages, GeneratorStatusEveryFieldAndSentinels) {
  const auto d = round_trip(GeneratorStatus{});
  EXPECT_EQ(d.generator_speed, UINT16_MAX);
  EXPECT_TRUE(std::isnan(d.battery_current));
  EXPECT_TRUE(std::isnan(d.load_current));
  EXPECT_TRUE(std::isnan(d.power_generated));
  EXPECT_TRUE(std::isnan(d.bat_current_setpoint));
  EXPECT_EQ(d.rectifier_temperature, INT16_MAX);
  EXPECT_EQ(d.generator_temperature, INT16_MAX);
  EXPECT_EQ(d.runtime, UINT32_MAX);
  EXPECT_EQ(d.time_until_maintenance, INT32_MAX);

  GeneratorStatus m;
  m.status = mav_generator_status_flag::kGenerating | mav_generator_status_flag::kCharging | (std::uint64_t{1} << 63);
  m.generator_speed = 5200;
  m.battery_current = -12.5F;
  m.load_current = 8.25F;
  m.power_generated = 612.0F;
  m.bus_voltage = 28.1F;
  m.rectifier_temperature = 55;
  m.bat_current_setpoint = -10.0F;
  m.generator_temperature = -5;
  m.runtime = 3601;
  m.time_until_maintenance = -60;
  const auto b = round_trip(m);
  EXPECT_EQ(b.status, m.status);
  EXPECT_EQ(b.generator_speed, 5200);
  EXPECT_EQ(b.battery_current, -12.5F);
  EXPECT_EQ(b.load_current, 8.25F);
  EXPECT_EQ(b.power_generated, 612.0F);
  EXPECT_EQ(b.bus_voltage, 28.1F);
  EXPECT_EQ(b.rectifier_temperature, 55);
  EXPECT_EQ(b.bat_current_setpoint, -10.0F);
  EXPECT_EQ(b.generator_temperature, -5);
  EXPECT_EQ(b.runtime, 3601U);
  EXPECT_EQ(b.time_until_maintenance, -60);
}

TEST(MavlinkMessages, RelayStatus) {
  RelayStatus m;
  m.time_boot_ms = 123456789;
  m.on = 0x0005;
  m.present = 0x000F;
  const auto b = round_trip(m);
  EXPECT_EQ(b.time_boot_ms, m.time_boot_ms);
  EXPECT_EQ(b.on, m.on);
  EXPECT_EQ(b.present, m.present);
}

TEST(MavlinkMessages, SenderWithoutExtensionsReadsAsZero) {
  // COMMAND_ACK and BATTERY_STATUS as a sender with the definitions before <extensions/>
  // sends them: the base payload only.
  Parser parser;
  const auto results =
      parse_all(parser, test::concat({raw_v2(msgid::kCommandAck, {0xDF, 0x00, mav_result::kFailed}, 143),
                                      raw_v2(msgid::kBatteryStatus, std::vector<std::uint8_t>(36, 0x01), 154)}));
  ASSERT_EQ(results.size(), 2U);
  const auto ack = decode<CommandAck>(std::get<Frame>(results[0]));
  ASSERT_TRUE(ack.has_value());
  EXPECT_EQ(ack->command, mav_cmd::kDoEngineControl);
  EXPECT_EQ(ack->result, mav_result::kFailed);
  EXPECT_EQ(ack->progress, 0);
  EXPECT_EQ(ack->result_param2, 0);
  EXPECT_EQ(ack->target_system, 0);
  EXPECT_EQ(ack->target_component, 0);
  const auto bat = decode<BatteryStatus>(std::get<Frame>(results[1]));
  ASSERT_TRUE(bat.has_value());
  EXPECT_EQ(bat->battery_remaining, 1);
  EXPECT_EQ(bat->time_remaining, 0);
  EXPECT_EQ(bat->charge_state, 0);
  for (auto v : bat->voltages_ext) EXPECT_EQ(v, 0);
  EXPECT_EQ(bat->fault_bitmask, 0U);
}

TEST(MavlinkMessages, DecodeOfAnotherMessageIsEmpty) {
  Parser parser;
  FrameWriter writer(1, 1);
  const auto results = parse_all(parser, writer.write(Heartbeat{}));
  ASSERT_EQ(results.size(), 1U);
  EXPECT_FALSE(decode<CommandLong>(std::get<Frame>(results[0])).has_value());
  EXPECT_TRUE(decode<Heartbeat>(std::get<Frame>(results[0])).has_value());
}

}  // namespace
}  // namespace pmu::mavlink
