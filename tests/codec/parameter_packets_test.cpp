// Stored parameters 0x10..0x1B, protocol v1.9 tables 8..18: every range boundary and one
// step past it, on encode (a set) and decode (the device's answer to a get).
#include <gtest/gtest.h>

#include <cmath>

#include "pmu/codec/decode.hpp"
#include "pmu/codec/encode.hpp"
#include "support/pmu_frames.hpp"

namespace pmu::codec {
namespace {

using test::pmu_frame;

struct RangeCase {
  const char* name;
  std::uint8_t packet;
  double min, max;  // engineering units, inclusive, as the spec states
  double step;      // resolution
  std::uint32_t raw_min, raw_max;
};

const RangeCase kRanges[] = {
    {"avionics_voltage", 0x10, 12.0, 24.0, 0.1, 120, 240},  // table 8
    {"payload_voltage", 0x11, 12.0, 24.0, 0.1, 120, 240},   // table 9
    {"servo_voltage", 0x12, 5.0, 12.0, 0.1, 50, 120},       // table 10
    {"battery_voltage", 0x13, 20.0, 25.2, 0.1, 200, 252},   // table 11
    {"packet_period", 0x14, 0.1, 25.5, 0.1, 1, 255},        // table 12
    {"temperature_offset", 0x16, 0, 255, 1, 0, 255},        // table 14
    {"upper_temperature_limit", 0x17, 0, 255, 1, 0, 255},   // table 15
    {"cranking_time", 0x19, 0.0, 25.5, 0.1, 0, 255},        // table 17 (0 = no timeout)
    {"can_address", 0x1B, 0, 65534, 1, 0, 65534},           // table 18
};

std::uint32_t frame_raw(const CanFrame& f) {
  return f.length == 2 ? (std::uint32_t{f.data[0]} << 8 | f.data[1]) : f.data[0];
}

TEST(Parameters, TableMatchesSpec) {
  for (const auto& c : kRanges) {
    SCOPED_TRACE(c.name);
    auto p = parameter_from_name(c.name);
    ASSERT_TRUE(p.has_value());
    const auto& s = spec_of(*p);
    EXPECT_EQ(static_cast<int>(s.packet), c.packet);
    EXPECT_EQ(s.raw_min, c.raw_min);
    EXPECT_EQ(s.raw_max, c.raw_max);
    EXPECT_EQ(parameter_from_packet(s.packet), p);
  }
  EXPECT_FALSE(parameter_from_name("avionics").has_value());
}

TEST(Parameters, SetAtBoundsEncodesSpecBytes) {
  for (const auto& c : kRanges) {
    SCOPED_TRACE(c.name);
    const Parameter p = *parameter_from_name(c.name);
    for (auto [value, raw] : {std::pair{c.min, c.raw_min}, std::pair{c.max, c.raw_max}}) {
      auto f = encode_set(p, value, 0x0102);
      ASSERT_TRUE(f.ok()) << f.error().describe();
      EXPECT_EQ(f->id, (0x1Eu << 24) | (std::uint32_t{c.packet} << 16) | 0x0102u);
      EXPECT_TRUE(f->extended);
      EXPECT_EQ(f->length, c.packet == 0x1B ? 2 : 1);
      EXPECT_EQ(frame_raw(*f), raw);
    }
  }
}

TEST(Parameters, OneStepPastEitherBoundIsRefusedWithTheRange) {
  for (const auto& c : kRanges) {
    SCOPED_TRACE(c.name);
    const Parameter p = *parameter_from_name(c.name);
    for (double v : {c.min - c.step, c.max + c.step}) {
      auto f = encode_set(p, v, 1);
      ASSERT_FALSE(f.ok()) << v;
      EXPECT_EQ(f.error().kind, EncodeErrorKind::OutOfRange);
      EXPECT_DOUBLE_EQ(f.error().min, c.min);
      EXPECT_DOUBLE_EQ(f.error().max, c.max);
      EXPECT_NE(f.error().describe().find(c.name), std::string::npos);
    }
  }
}

TEST(Parameters, NaNAndInfinityAreRefused) {
  for (const auto& s : parameter_table()) {
    for (double v : {std::nan(""), HUGE_VAL, -HUGE_VAL}) {
      auto f = encode_set(s.parameter, v, 1);
      ASSERT_FALSE(f.ok()) << s.name;
      EXPECT_EQ(f.error().kind, EncodeErrorKind::NotANumber);
    }
  }
}

TEST(Parameters, ValuesBetweenStepsAreRefusedNotRounded) {
  auto f = encode_set(Parameter::AvionicsVoltage, 12.05, 1);
  ASSERT_FALSE(f.ok());
  EXPECT_EQ(f.error().kind, EncodeErrorKind::NotOnStep);
  EXPECT_EQ(f.error().describe(), "value 12.05 V for avionics_voltage is not a multiple of 0.1 V");
  EXPECT_FALSE(encode_set(Parameter::CanAddress, 7.5, 1).ok());
  // float32 as DDS delivers it is still on the step.
  auto g = encode_set(Parameter::AvionicsVoltage, static_cast<double>(12.3f), 1);
  ASSERT_TRUE(g.ok());
  EXPECT_EQ(g->data[0], 123);
}

TEST(Parameters, ErrorMessageNamesValueRangeAndUnit) {
  auto f = encode_set(Parameter::AvionicsVoltage, 30.0, 1);
  ASSERT_FALSE(f.ok());
  EXPECT_EQ(f.error().describe(), "value 30.0 V out of range 12.0..24.0 V for avionics_voltage");
}

TEST(Parameters, BroadcastIsNotACanAddress) {
  auto f = encode_set(Parameter::CanAddress, 65535, 1);
  ASSERT_FALSE(f.ok());
  EXPECT_EQ(f.error().kind, EncodeErrorKind::OutOfRange);
  auto ok = encode_set(Parameter::CanAddress, 0x1234, 1);
  ASSERT_TRUE(ok.ok());
  EXPECT_EQ(ok->data[0], 0x12);  // big-endian (section 5)
  EXPECT_EQ(ok->data[1], 0x34);
}

TEST(Parameters, PacketsStreamedMaskBits0To4) {
  EXPECT_TRUE(encode_set(Parameter::PacketsStreamed, 0x1F, 1).ok());
  EXPECT_TRUE(encode_set(Parameter::PacketsStreamed, 0, 1).ok());
  auto f = encode_set(Parameter::PacketsStreamed, 0x20, 1);
  ASSERT_FALSE(f.ok());
  EXPECT_EQ(f.error().kind, EncodeErrorKind::InvalidBits);
  EXPECT_FALSE(encode_set(Parameter::PacketsStreamed, 256, 1).ok());
  EXPECT_FALSE(encode_set(Parameter::PacketsStreamed, -1, 1).ok());
}

// A value that is no mask at all is refused with the spec's mask, never the byte's 0..255.
TEST(Parameters, ANonMaskValueIsRefusedWithTheDefinedMask) {
  const struct {
    double value;
    const char* message;
  } cases[] = {
      {-1, "packets_streamed: value -1 is not a bit mask 0..0x1F"},
      {1.5, "packets_streamed: value 1.5 is not a bit mask 0..0x1F"},
      {256, "packets_streamed: value 256 is not a bit mask 0..0x1F"},
      {0x20, "packets_streamed 32 has bits outside the defined mask 0x1F"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.value);
    auto f = encode_set(Parameter::PacketsStreamed, c.value, 1);
    ASSERT_FALSE(f.ok());
    EXPECT_EQ(f.error().kind, EncodeErrorKind::InvalidBits);
    EXPECT_EQ(f.error().describe(), c.message);
  }
}

struct PowerUpCase {
  std::optional<FirmwareVersion> fw;
  std::uint8_t value;
  bool ok;
  EncodeErrorKind kind;
};

TEST(Parameters, PowerUpStateBitsDependOnFirmware) {
  // Bit 4 (battery disconnect detect) from 1.15, bit 6 (SOA management) from 1.16, bit 7 never.
  const PowerUpCase cases[] = {
      {FirmwareVersion{1, 12}, 0x2F, true, {}},
      {FirmwareVersion{1, 12}, 0x10, false, EncodeErrorKind::Unsupported},
      {FirmwareVersion{1, 14}, 0x40, false, EncodeErrorKind::Unsupported},
      {FirmwareVersion{1, 15}, 0x3F, true, {}},
      {FirmwareVersion{1, 15}, 0x40, false, EncodeErrorKind::Unsupported},
      {FirmwareVersion{1, 16}, 0x7F, true, {}},
      {FirmwareVersion{1, 17}, 0x80, false, EncodeErrorKind::InvalidBits},
      {std::nullopt, 0x7F, true, {}},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(testing::Message() << (c.fw ? to_string(*c.fw) : "unknown") << " value " << int(c.value));
    auto f = encode_set(Parameter::PowerUpState, c.value, 1, c.fw);
    ASSERT_EQ(f.ok(), c.ok);
    if (c.ok)
      EXPECT_EQ(f->data[0], c.value);
    else
      EXPECT_EQ(f.error().kind, c.kind);
  }
  auto f = encode_set(Parameter::PowerUpState, 0x40, 1, FirmwareVersion{1, 15});
  EXPECT_EQ(f.error().describe(), "power_up_state needs firmware 1.16 (device has 1.15)");
}

TEST(Parameters, ZeroLengthGetOfEveryParameter) {
  for (const auto& s : parameter_table()) {
    auto f = encode_get(s.packet, 3);
    ASSERT_TRUE(f.ok());
    EXPECT_EQ(f->length, 0);
    EXPECT_EQ(f->id, make_id(s.packet, 3));
    auto m = decode(*f);
    ASSERT_TRUE(m.ok());
    EXPECT_TRUE(m->request);
  }
}

TEST(Parameters, DecodeReplyInEngineeringUnits) {
  struct Case {
    std::uint8_t packet;
    std::initializer_list<std::uint8_t> bytes;
    double value;
  };
  const Case cases[] = {{0x10, {240}, 24.0}, {0x11, {120}, 12.0}, {0x12, {50}, 5.0},          {0x13, {252}, 25.2},
                        {0x14, {1}, 0.1},    {0x15, {0x1F}, 31},  {0x16, {255}, 255},         {0x17, {0}, 0},
                        {0x18, {0x21}, 33},  {0x19, {0}, 0},      {0x1B, {0xFF, 0xFE}, 65534}};
  for (const auto& c : cases) {
    SCOPED_TRACE(int(c.packet));
    auto m = decode(pmu_frame(c.packet, 1, c.bytes));
    ASSERT_TRUE(m.ok());
    const auto& pv = std::get<ParameterValue>(m->payload);
    EXPECT_EQ(pv.value, c.value);
    EXPECT_EQ(spec_of(pv.parameter).packet, static_cast<PacketId>(c.packet));
    // Wrong lengths: a parameter is 1 byte (2 for CA).
    CanFrame bad = pmu_frame(c.packet, 1, c.bytes);
    bad.length = static_cast<std::uint8_t>(bad.length + 1);
    EXPECT_FALSE(decode(bad).ok());
  }
}

TEST(Parameters, ToRawMatchesEncodeForEveryRawValue) {
  for (const auto& s : parameter_table()) {
    if (s.kind == ParameterKind::Mask) continue;
    for (std::uint32_t raw = s.raw_min; raw <= s.raw_max; raw += (s.width == 2 ? 257 : 1)) {
      const double v = parameter_value(s.parameter, raw);
      auto r = to_raw(s.parameter, v);
      ASSERT_TRUE(r.ok()) << s.name << " " << raw;
      EXPECT_EQ(*r, raw);
    }
  }
}

}  // namespace
}  // namespace pmu::codec
