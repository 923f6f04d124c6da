// Stored parameters and addressing: gets (v1.9 4.2 "zero data bytes returns the current
// values"), sets within tables 8..18, out-of-range sets ignored, broadcast (4.3), foreign
// addresses and wrong lengths ignored and counted.
#include <gtest/gtest.h>

#include "sim_harness.hpp"

namespace pmu::sim::test {
namespace {

// ---- gets: every packet with a zero-length get answers once, same id, own address -------
struct GetCase {
  PacketId packet;
};

const GetCase kGets[] = {
    {PacketId::Voltages},
    {PacketId::Currents},
    {PacketId::BatteryEnergy},
    {PacketId::Temperatures},
    {PacketId::Status},
    {PacketId::AvionicsVoltage},
    {PacketId::PayloadVoltage},
    {PacketId::ServoVoltage},
    {PacketId::BatteryVoltage},
    {PacketId::PacketPeriod},
    {PacketId::PacketsStreamed},
    {PacketId::TemperatureOffset},
    {PacketId::UpperTemperatureLimit},
    {PacketId::PowerUpState},
    {PacketId::CrankingTime},
    {PacketId::CanAddress},
    {PacketId::Outputs},
    {PacketId::Generation},
    {PacketId::Serial},
    {PacketId::Firmware},
};

TEST(SimGet, EachPacketAnsweredOnceFromOwnAddress) {
  for (const auto& c : kGets) {
    SCOPED_TRACE(std::string(codec::packet_name(c.packet)));
    Harness h(quiet_config(7));
    h.deliver(codec::encode_get(c.packet, 7));
    ASSERT_EQ(h.sent.size(), 1u);
    const auto reply = codec::decode(h.sent[0].frame, h.fw);
    ASSERT_TRUE(reply.ok()) << reply.error().describe();
    EXPECT_EQ(reply->packet, c.packet);
    EXPECT_EQ(reply->address, 7);
    EXPECT_FALSE(reply->request);  // carries data, the spec's length (table 1)
    EXPECT_EQ(h.sent[0].frame.length, codec::data_length(c.packet));
    EXPECT_EQ(h.pmu.counters().handled, 1u);
  }
}

// Factory values (config.hpp) as the unit reports them.
struct StoredCase {
  Parameter parameter;
  std::uint32_t raw;
};
const StoredCase kFactory[] = {
    {Parameter::AvionicsVoltage, 120},   {Parameter::PayloadVoltage, 120},
    {Parameter::ServoVoltage, 60},       {Parameter::BatteryVoltage, 252},
    {Parameter::PacketPeriod, 10},       {Parameter::PacketsStreamed, 0x1F},
    {Parameter::TemperatureOffset, 128}, {Parameter::UpperTemperatureLimit, 80},
    {Parameter::PowerUpState, 0x0F},     {Parameter::CrankingTime, 50},
    {Parameter::CanAddress, 1},
};

TEST(SimGet, FactoryValues) {
  Harness h(DeviceConfig{});
  for (const auto& c : kFactory) {
    SCOPED_TRACE(std::string(codec::spec_of(c.parameter).name));
    EXPECT_EQ(h.get_raw(c.parameter), c.raw);
  }
}

TEST(SimGet, IdentityPackets) {
  DeviceConfig cfg = quiet_config(1, kFw116);
  cfg.serial_number = 31337;
  cfg.build_date = {2021, 11, 30};
  Harness h(cfg);
  EXPECT_EQ(h.get<codec::SerialNumber>(PacketId::Serial)->serial_number, 31337);
  const auto fw = h.get<codec::FirmwareInfo>(PacketId::Firmware);
  ASSERT_TRUE(fw);
  EXPECT_EQ(fw->firmware_major, 1);
  EXPECT_EQ(fw->firmware_minor, 16);
  EXPECT_EQ(fw->build_year, 2021);
  EXPECT_EQ(fw->build_month, 11);
  EXPECT_EQ(fw->build_day, 30);
}

// ---- sets within range are stored, silently ---------------------------------------------
struct SetCase {
  Parameter parameter;
  double value;  // engineering units, as encode_set takes it
  std::uint32_t raw;
};

// Each range's ends (tables 8..18).
const SetCase kValidSets[] = {
    {Parameter::AvionicsVoltage, 12.0, 120},
    {Parameter::AvionicsVoltage, 24.0, 240},
    {Parameter::PayloadVoltage, 12.0, 120},
    {Parameter::PayloadVoltage, 24.0, 240},
    {Parameter::ServoVoltage, 5.0, 50},
    {Parameter::ServoVoltage, 12.0, 120},
    {Parameter::BatteryVoltage, 20.0, 200},
    {Parameter::BatteryVoltage, 25.2, 252},
    {Parameter::PacketPeriod, 0.1, 1},
    {Parameter::PacketPeriod, 25.5, 255},
    {Parameter::PacketsStreamed, 0, 0},
    {Parameter::PacketsStreamed, 0x1F, 0x1F},
    {Parameter::TemperatureOffset, 0, 0},
    {Parameter::TemperatureOffset, 255, 255},
    {Parameter::UpperTemperatureLimit, 0, 0},
    {Parameter::UpperTemperatureLimit, 255, 255},
    {Parameter::PowerUpState, 0, 0},
    {Parameter::PowerUpState, 0x7F, 0x7F},
    {Parameter::CrankingTime, 0, 0},
    {Parameter::CrankingTime, 25.5, 255},
    {Parameter::CanAddress, 1, 1},
    {Parameter::CanAddress, 2, 2},
};

TEST(SimSet, InRangeStoredWithoutReply) {
  for (const auto& c : kValidSets) {
    SCOPED_TRACE(std::string(codec::spec_of(c.parameter).name) + " = " + std::to_string(c.value));
    Harness h;
    h.deliver(codec::encode_set(c.parameter, c.value, 1, kFw117));
    EXPECT_TRUE(h.sent.empty()) << "a set is not answered";
    EXPECT_EQ(h.pmu.parameter(c.parameter), c.raw);
    const std::uint16_t now_at = c.parameter == Parameter::CanAddress ? static_cast<std::uint16_t>(c.raw) : 1;
    EXPECT_EQ(h.get_raw(c.parameter, now_at), c.raw);
    EXPECT_EQ(h.pmu.counters().rejected_sets, 0u);
  }
}

// ---- sets out of range are ignored: the stored value is kept -----------------------------
struct BadSetCase {
  const char* why;
  Parameter parameter;
  std::uint32_t raw;  // on the wire; encode_parameter_reply writes any raw the field holds
  codec::FirmwareVersion fw;
};

const BadSetCase kBadSets[] = {
    {"V_A below 12.0", Parameter::AvionicsVoltage, 119, kFw117},
    {"V_A above 24.0", Parameter::AvionicsVoltage, 241, kFw117},
    {"V_P above 24.0", Parameter::PayloadVoltage, 250, kFw117},
    {"V_S below 5.0", Parameter::ServoVoltage, 49, kFw117},
    {"V_S above 12.0", Parameter::ServoVoltage, 121, kFw117},
    {"V_B below 20.0", Parameter::BatteryVoltage, 199, kFw117},
    {"V_B above 25.2", Parameter::BatteryVoltage, 253, kFw117},
    {"PP zero", Parameter::PacketPeriod, 0, kFw117},
    {"PS undefined bit 5", Parameter::PacketsStreamed, 0x21, kFw117},
    {"S0 bit 7", Parameter::PowerUpState, 0x80, kFw117},
    {"S0 bit 4 before 1.15", Parameter::PowerUpState, 0x10, kFw114},
    {"S0 bit 6 before 1.16", Parameter::PowerUpState, 0x40, kFw115},
    {"CA broadcast", Parameter::CanAddress, 0xFFFF, kFw117},
};

TEST(SimSet, OutOfRangeIgnored) {
  for (const auto& c : kBadSets) {
    SCOPED_TRACE(c.why);
    Harness h(quiet_config(1, c.fw));
    const std::uint32_t before = h.pmu.parameter(c.parameter);
    h.deliver(codec::encode_parameter_reply(c.parameter, c.raw, 1));
    EXPECT_TRUE(h.sent.empty());
    EXPECT_EQ(h.pmu.counters().rejected_sets, 1u);
    EXPECT_EQ(h.pmu.counters().handled, 0u);
    EXPECT_EQ(h.get_raw(c.parameter), before) << "the service detects the refusal by reading back";
  }
}

// S0 bits 4 and 6 become valid with the firmware that defines them (v1.9 6.7, 6.8).
struct PowerUpBitCase {
  codec::FirmwareVersion fw;
  std::uint8_t bits;
  bool stored;
};
const PowerUpBitCase kPowerUpBits[] = {
    {kFw112, 0x2F, true},  {kFw114, 0x10, false}, {kFw115, 0x10, true},
    {kFw115, 0x40, false}, {kFw116, 0x40, true},  {kFw117, 0x7F, true},
};

TEST(SimSet, PowerUpStateBitsFollowFirmware) {
  for (const auto& c : kPowerUpBits) {
    SCOPED_TRACE(codec::to_string(c.fw) + " bits " + std::to_string(c.bits));
    Harness h(quiet_config(1, c.fw));
    h.deliver(codec::encode_parameter_reply(Parameter::PowerUpState, c.bits, 1));
    EXPECT_EQ(h.get_raw(Parameter::PowerUpState) == c.bits, c.stored);
  }
}

// ---- addressing (4.3) --------------------------------------------------------------------
TEST(SimAddress, BroadcastGetAnsweredFromOwnAddress) {
  Harness h(quiet_config(300));
  h.deliver(codec::encode_get(PacketId::CanAddress, codec::kBroadcastAddress));
  const auto replies = h.take();
  ASSERT_EQ(replies.size(), 1u);
  EXPECT_EQ(replies[0].address, 300);  // how a forgotten address is found (table 18)
  EXPECT_EQ(std::get<codec::ParameterValue>(replies[0].payload).raw, 300u);
}

TEST(SimAddress, BroadcastSetApplies) {
  Harness h(quiet_config(300));
  h.deliver(codec::encode_set(Parameter::AvionicsVoltage, 15.5, codec::kBroadcastAddress));
  EXPECT_EQ(h.get_raw(Parameter::AvionicsVoltage, 300), 155u);
}

TEST(SimAddress, ForeignAddressIgnored) {
  Harness h(quiet_config(300));
  h.deliver(codec::encode_get(PacketId::Serial, 301));
  h.deliver(codec::encode_set(Parameter::AvionicsVoltage, 15.5, 301));
  h.deliver(codec::encode_reset(1));
  EXPECT_TRUE(h.sent.empty());
  EXPECT_EQ(h.pmu.counters().other_address, 3u);
  EXPECT_EQ(h.pmu.parameter(Parameter::AvionicsVoltage), 120u);
}

TEST(SimAddress, NewAddressAppliesAtOnce) {
  Harness h(quiet_config(1));
  h.deliver(codec::encode_set(Parameter::CanAddress, 42, 1));
  EXPECT_EQ(h.pmu.address(), 42);
  h.deliver(codec::encode_get(PacketId::Serial, 1));
  EXPECT_TRUE(h.sent.empty()) << "the old address is no longer ours";
  h.deliver(codec::encode_get(PacketId::Serial, 42));
  const auto replies = h.take();
  ASSERT_EQ(replies.size(), 1u);
  EXPECT_EQ(replies[0].address, 42);
  EXPECT_EQ(std::get<codec::SerialNumber>(replies[0].payload).serial_number, 4242);
}

TEST(SimAddress, BroadcastAddressRefusedAtStartUp) {
  EXPECT_THROW(PmuModel(quiet_config(codec::kBroadcastAddress), nullptr, TimePoint{}), std::invalid_argument);
}

// ---- frames the unit cannot use are ignored and counted -----------------------------------
struct IgnoredCase {
  const char* why;
  codec::CanFrame frame;
  std::uint64_t Counters::*counter;
};

codec::CanFrame with(codec::CanFrame f, bool extended, bool remote) {
  f.extended = extended;
  f.remote = remote;
  return f;
}

const IgnoredCase kIgnored[] = {
    {"V_A set with 2 bytes", raw_frame(PacketId::AvionicsVoltage, 1, {150, 0}), &Counters::wrong_length},
    {"CA set with 1 byte", raw_frame(PacketId::CanAddress, 1, {5}), &Counters::wrong_length},
    {"voltages get with junk", raw_frame(PacketId::Voltages, 1, {1, 2, 3}), &Counters::wrong_length},
    {"enable outputs without data", raw_frame(PacketId::EnableOutputs, 1, {}), &Counters::wrong_length},
    {"disable outputs without data", raw_frame(PacketId::DisableOutputs, 1, {}), &Counters::wrong_length},
    {"reset with data", raw_frame(PacketId::Reset, 1, {0}), &Counters::wrong_length},
    {"start with data", raw_frame(PacketId::EngineStart, 1, {1}), &Counters::wrong_length},
    {"outputs set with 2 bytes", raw_frame(PacketId::Outputs, 1, {0, 0}), &Counters::wrong_length},
    {"11-bit id", with(raw_frame(PacketId::Reset, 1, {}), false, false), &Counters::not_pmu},
    {"group 0x1F",
     [] {
       auto f = raw_frame(PacketId::Reset, 1, {});
       f.id |= 1u << 24;
       return f;
     }(),
     &Counters::not_pmu},
    {"unknown packet 0x1A",
     [] {
       auto f = raw_frame(PacketId::Reset, 1, {});
       f.id = 0x1E1A0001;
       return f;
     }(),
     &Counters::unknown_packet},
    {"remote frame", with(raw_frame(PacketId::Reset, 1, {}), true, true), &Counters::malformed},
    {"another unit's voltages", raw_frame(PacketId::Voltages, 1, {1, 2, 3, 4, 5, 6, 7}), &Counters::not_commands},
    {"another unit's serial", raw_frame(PacketId::Serial, 1, {0, 9}), &Counters::not_commands},
};

TEST(SimIgnored, CountedAndWithoutEffect) {
  for (const auto& c : kIgnored) {
    SCOPED_TRACE(c.why);
    DeviceConfig cfg = quiet_config();
    cfg.parameters.set_raw(Parameter::PowerUpState, 0x0F);
    Harness h(cfg);
    h.deliver(codec::encode_disable_outputs(codec::output_bit::Payload, 1));  // a reset would undo it
    const Counters before = h.pmu.counters();
    h.deliver(c.frame);
    const Counters after = h.pmu.counters();
    EXPECT_TRUE(h.sent.empty());
    EXPECT_EQ(after.*(c.counter), before.*(c.counter) + 1);
    EXPECT_EQ(after.frames_in, before.frames_in + 1);
    EXPECT_EQ(after.handled, before.handled);
    EXPECT_EQ(h.pmu.outputs(), 0x0D);
    EXPECT_EQ(h.pmu.parameter(Parameter::AvionicsVoltage), 120u);
    EXPECT_EQ(h.pmu.address(), 1);
  }
}

}  // namespace
}  // namespace pmu::sim::test
