// Telemetry packets 0x00..0x04, protocol v1.9 tables 2..6: every field's scale, sign and
// range, in both directions (decode for the service, encode for the simulator).
#include <gtest/gtest.h>

#include <cmath>

#include "pmu/codec/decode.hpp"
#include "pmu/codec/encode.hpp"
#include "support/pmu_frames.hpp"

namespace pmu::codec {
namespace {

using test::pmu_frame;

// ---- table 2: voltages -------------------------------------------------------------------
struct ByteScale {
  const char* field;
  std::size_t byte;
  double divisor;  // engineering value = raw / divisor
  bool is_signed;
  int raw_min, raw_max;  // the range the table states
};

double voltages_field(const Voltages& v, std::size_t i) {
  const double f[] = {v.avionics, v.output_28v, v.payload, v.servo, v.battery_a, v.battery_b, v.generator};
  return f[i];
}
double currents_field(const Currents& c, std::size_t i) {
  const double f[] = {c.avionics, c.output_28v, c.payload, c.servo, c.battery_a, c.battery_b};
  return f[i];
}

const ByteScale kVoltages[] = {
    {"avionics", 0, 10, false, 0, 250},   {"output_28v", 1, 5, false, 0, 250}, {"payload", 2, 10, false, 0, 250},
    {"servo", 3, 10, false, 0, 125},      {"battery_a", 4, 10, false, 0, 250}, {"battery_b", 5, 10, false, 0, 250},
    {"generator", 6, 2.5, false, 0, 250},
};

// Table 3: 28 V and battery currents signed, output currents unsigned; all 0.1 A.
const ByteScale kCurrents[] = {
    {"avionics", 0, 10, false, 0, 100}, {"output_28v", 1, 10, true, -125, 125}, {"payload", 2, 10, false, 0, 100},
    {"servo", 3, 10, false, 0, 100},    {"battery_a", 4, 10, true, -125, 125},  {"battery_b", 5, 10, true, -125, 125},
};

std::uint8_t wire(int raw) { return static_cast<std::uint8_t>(raw & 0xFF); }

TEST(Voltages, DecodeEachFieldAtItsRangeEnds) {
  for (const auto& f : kVoltages) {
    for (int raw : {f.raw_min, 1, f.raw_max, 255}) {
      SCOPED_TRACE(testing::Message() << f.field << " raw " << raw);
      CanFrame fr = pmu_frame(0x00, 1, {0, 0, 0, 0, 0, 0, 0});
      fr.data[f.byte] = wire(raw);
      auto m = decode(fr);
      ASSERT_TRUE(m.ok());
      const auto& v = std::get<Voltages>(m->payload);
      EXPECT_DOUBLE_EQ(voltages_field(v, f.byte), raw / f.divisor);
    }
  }
}

TEST(Voltages, SpecExamples) {
  // Table 2: 250 -> 25.0 V (x10), 250 -> 50.0 V (28 V, x5), 125 -> 12.5 V servo, 250 -> 100 V generator.
  auto m = decode(pmu_frame(0x00, 7, {250, 250, 123, 125, 168, 0, 250}));
  ASSERT_TRUE(m.ok());
  EXPECT_EQ(m->address, 7);
  EXPECT_FALSE(m->request);
  const auto& v = std::get<Voltages>(m->payload);
  EXPECT_EQ(v.avionics, 25.0);
  EXPECT_EQ(v.output_28v, 50.0);
  EXPECT_EQ(v.payload, 12.3);  // exactly the double nearest 12.3, so it prints as 12.3
  EXPECT_EQ(v.servo, 12.5);
  EXPECT_EQ(v.battery_a, 16.8);
  EXPECT_EQ(v.battery_b, 0.0);
  EXPECT_EQ(v.generator, 100.0);
}

TEST(Voltages, EncodeRangeEndsAndOnePast) {
  for (const auto& f : kVoltages) {
    SCOPED_TRACE(f.field);
    Voltages v;
    double* slot[] = {&v.avionics, &v.output_28v, &v.payload, &v.servo, &v.battery_a, &v.battery_b, &v.generator};
    *slot[f.byte] = f.raw_max / f.divisor;
    auto fr = encode_voltages(v, 1);
    ASSERT_TRUE(fr.ok());
    EXPECT_EQ(fr->data[f.byte], f.raw_max);
    EXPECT_EQ(fr->length, 7);
    *slot[f.byte] = (f.raw_max + 1) / f.divisor;
    auto bad = encode_voltages(v, 1);
    ASSERT_FALSE(bad.ok());
    EXPECT_EQ(bad.error().kind, EncodeErrorKind::OutOfRange);
    EXPECT_EQ(bad.error().field, f.field);
    *slot[f.byte] = -1 / f.divisor;
    EXPECT_FALSE(encode_voltages(v, 1).ok());
    *slot[f.byte] = std::nan("");
    auto nan = encode_voltages(v, 1);
    ASSERT_FALSE(nan.ok());
    EXPECT_EQ(nan.error().kind, EncodeErrorKind::NotANumber);
  }
}

TEST(Voltages, EncodeRoundsMeasuredValuesToResolution) {
  Voltages v;
  v.avionics = 12.34;   // -> 123
  v.generator = 50.19;  // / 0.4 V -> 125.475 -> 125
  auto fr = encode_voltages(v, 1);
  ASSERT_TRUE(fr.ok());
  EXPECT_EQ(fr->data[0], 123);
  EXPECT_EQ(fr->data[6], 125);
}

// ---- table 3: currents -------------------------------------------------------------------
TEST(Currents, DecodeSignsAndRangeEnds) {
  for (const auto& f : kCurrents) {
    for (int raw : {f.raw_min, f.raw_max, 0, 1}) {
      SCOPED_TRACE(testing::Message() << f.field << " raw " << raw);
      CanFrame fr = pmu_frame(0x01, 1, {0, 0, 0, 0, 0, 0});
      fr.data[f.byte] = wire(raw);
      auto m = decode(fr);
      ASSERT_TRUE(m.ok());
      EXPECT_DOUBLE_EQ(currents_field(std::get<Currents>(m->payload), f.byte), raw / f.divisor);
    }
  }
}

TEST(Currents, SignedBytesUseTwosComplementUnsignedDoNot) {
  // 0x83 is -125 for a signed field and 131 (13.1 A) for an unsigned one.
  auto m = decode(pmu_frame(0x01, 1, {0x83, 0x83, 0x83, 0x83, 0x83, 0x83}));
  ASSERT_TRUE(m.ok());
  const auto& c = std::get<Currents>(m->payload);
  EXPECT_DOUBLE_EQ(c.avionics, 13.1);
  EXPECT_DOUBLE_EQ(c.output_28v, -12.5);
  EXPECT_DOUBLE_EQ(c.payload, 13.1);
  EXPECT_DOUBLE_EQ(c.servo, 13.1);
  EXPECT_DOUBLE_EQ(c.battery_a, -12.5);
  EXPECT_DOUBLE_EQ(c.battery_b, -12.5);
  // The extreme byte values -128 and 127 decode even though the table stops at +-125.
  auto x = decode(pmu_frame(0x01, 1, {0, 0x80, 0, 0, 0x7F, 0xFF}));
  ASSERT_TRUE(x.ok());
  EXPECT_DOUBLE_EQ(std::get<Currents>(x->payload).output_28v, -12.8);
  EXPECT_DOUBLE_EQ(std::get<Currents>(x->payload).battery_a, 12.7);
  EXPECT_DOUBLE_EQ(std::get<Currents>(x->payload).battery_b, -0.1);
}

TEST(Currents, EncodeRangeEndsAndOnePast) {
  for (const auto& f : kCurrents) {
    SCOPED_TRACE(f.field);
    Currents c;
    double* slot[] = {&c.avionics, &c.output_28v, &c.payload, &c.servo, &c.battery_a, &c.battery_b};
    for (int raw : {f.raw_min, f.raw_max}) {
      *slot[f.byte] = raw / f.divisor;
      auto fr = encode_currents(c, 1);
      ASSERT_TRUE(fr.ok());
      EXPECT_EQ(fr->data[f.byte], wire(raw));
    }
    for (int raw : {f.raw_min - 1, f.raw_max + 1}) {
      *slot[f.byte] = raw / f.divisor;
      auto bad = encode_currents(c, 1);
      ASSERT_FALSE(bad.ok());
      EXPECT_EQ(bad.error().kind, EncodeErrorKind::OutOfRange);
    }
  }
}

// ---- table 4: battery energy (signed 16-bit, big-endian) -----------------------------------
TEST(BatteryEnergy, SignedBigEndianExtremes) {
  struct Case {
    std::uint8_t hi, lo;
    int mah;
  };
  const Case cases[] = {{0x80, 0x00, -32768}, {0x7F, 0xFF, 32767}, {0xFF, 0xFF, -1}, {0x01, 0x00, 256}, {0, 0, 0}};
  for (const auto& c : cases) {
    auto m = decode(pmu_frame(0x02, 1, {c.hi, c.lo, c.lo, c.hi}));
    ASSERT_TRUE(m.ok());
    const auto& e = std::get<BatteryEnergy>(m->payload);
    EXPECT_EQ(e.battery_a_mah, c.mah);
    BatteryEnergy back{static_cast<std::int16_t>(c.mah), 0};
    auto fr = encode_battery_energy(back, 1);
    ASSERT_TRUE(fr.ok());
    EXPECT_EQ(fr->data[0], c.hi);
    EXPECT_EQ(fr->data[1], c.lo);
  }
  auto m = decode(pmu_frame(0x02, 1, {0x00, 0x01, 0x80, 0x00}));
  EXPECT_EQ(std::get<BatteryEnergy>(m->payload).battery_b_mah, -32768);
}

// ---- table 5: temperatures ---------------------------------------------------------------
// Table 5, one row per temperature: its byte, and the firmware from which it is reported
// (the external sensors from 1.12, v1.9 6.1). -128 on any of them is "no sensor", NaN
// (interface.md 1.1); the spec says so of the external sensors, and the internal and starter
// sensors cannot read -128 degC either.
struct TemperatureRow {
  const char* field;
  std::size_t byte;
  double Temperatures::*member;
  FirmwareVersion reported_from;
};

const TemperatureRow kTemperatureRows[] = {
    {"internal", 0, &Temperatures::internal, {1, 0}},    {"battery_a", 1, &Temperatures::battery_a, {1, 12}},
    {"battery_b", 2, &Temperatures::battery_b, {1, 12}}, {"generator", 3, &Temperatures::generator, {1, 12}},
    {"starter", 4, &Temperatures::starter, {1, 0}},
};

TEST(Temperatures, MinusOneTwentyEightIsNoSensorOnEveryTemperature) {
  for (const auto& row : kTemperatureRows) {
    SCOPED_TRACE(row.field);
    CanFrame frame = pmu_frame(0x03, 1, {20, 21, 22, 23, 24});
    frame.data[row.byte] = 0x80;  // -128
    const auto m = decode(frame, FirmwareVersion{1, 14});
    ASSERT_TRUE(m.ok());
    const auto& t = std::get<Temperatures>(m->payload);
    EXPECT_TRUE(std::isnan(t.*row.member));
    for (const auto& other : kTemperatureRows) {
      if (other.member != row.member) {
        EXPECT_EQ(t.*other.member, 20 + static_cast<double>(other.byte)) << other.field;
      }
    }
    // The encoder sends "no sensor" for NaN, and refuses the -128 it could not tell from it.
    Temperatures in{20, 21, 22, 23, 24};
    in.*row.member = std::nan("");
    const auto sent = encode_temperatures(in, 1);
    ASSERT_TRUE(sent.ok());
    EXPECT_EQ(sent->data[row.byte], 0x80);
    in.*row.member = -128;
    EXPECT_FALSE(encode_temperatures(in, 1).ok());
  }
}

// One past "no sensor" is a reading, on every temperature that the firmware reports.
TEST(Temperatures, MinusOneTwentySevenIsAReading) {
  for (const auto& row : kTemperatureRows) {
    SCOPED_TRACE(row.field);
    CanFrame frame = pmu_frame(0x03, 1, {0, 0, 0, 0, 0});
    frame.data[row.byte] = 0x81;  // -127
    const auto m = decode(frame, row.reported_from);
    ASSERT_TRUE(m.ok());
    EXPECT_EQ(std::get<Temperatures>(m->payload).*row.member, -127);
  }
}

TEST(Temperatures, SignedExtremes) {
  auto m = decode(pmu_frame(0x03, 1, {0x7F, 0x81, 0x7F, 0x00, 0x7F}));
  ASSERT_TRUE(m.ok());
  const auto& t = std::get<Temperatures>(m->payload);
  EXPECT_EQ(t.internal, 127);
  EXPECT_EQ(t.battery_a, -127);
  EXPECT_EQ(t.battery_b, 127);
  EXPECT_EQ(t.generator, 0);
  EXPECT_EQ(t.starter, 127);
}

TEST(Temperatures, ExternalSensorsAbsentBeforeFirmware112) {
  auto old = decode(pmu_frame(0x03, 1, {20, 21, 22, 23, 24}), FirmwareVersion{1, 11});
  ASSERT_TRUE(old.ok());
  const auto& t = std::get<Temperatures>(old->payload);
  EXPECT_EQ(t.internal, 20);
  EXPECT_TRUE(std::isnan(t.battery_a));
  EXPECT_TRUE(std::isnan(t.generator));
  EXPECT_EQ(t.starter, 24);
  auto cur = decode(pmu_frame(0x03, 1, {20, 21, 22, 23, 24}), FirmwareVersion{1, 12});
  EXPECT_EQ(std::get<Temperatures>(cur->payload).battery_a, 21);
}

TEST(Temperatures, EncodeNoSensorAndRanges) {
  Temperatures t;
  t.internal = -127;
  t.starter = -49;
  auto fr = encode_temperatures(t, 1);
  ASSERT_TRUE(fr.ok());
  EXPECT_EQ(fr->data[0], 0x81);
  EXPECT_EQ(fr->data[1], 0x80);  // NaN -> "no sensor"
  EXPECT_EQ(fr->data[4], 0xCF);
  t.starter = -50;  // one past table 5's -49
  EXPECT_FALSE(encode_temperatures(t, 1).ok());
  t.starter = 0;
  t.battery_a = -128;  // -128 would read back as "no sensor": refused
  EXPECT_FALSE(encode_temperatures(t, 1).ok());
  t.battery_a = 128;
  EXPECT_FALSE(encode_temperatures(t, 1).ok());
  t.battery_a = 127;
  EXPECT_TRUE(encode_temperatures(t, 1).ok());
}

// ---- table 6: miscellaneous (status) -------------------------------------------------------
struct FlagCase {
  const char* name;
  std::size_t byte;
  std::uint8_t bit;
  bool Status::*field;
};

const FlagCase kFlags[] = {
    {"generation_enabled", 2, 0x10, &Status::generation_enabled},
    {"thermal_shutdown", 2, 0x20, &Status::thermal_shutdown},
    {"payload_shed", 2, 0x80, &Status::payload_shed},
    {"starter_ready", 3, 0x80, &Status::starter_ready},
};

TEST(Status, EachFlagBitAlone) {
  for (const auto& f : kFlags) {
    SCOPED_TRACE(f.name);
    CanFrame fr = pmu_frame(0x04, 1, {0, 0, 0, 0, 0});
    fr.data[f.byte] = f.bit;
    auto m = decode(fr);
    ASSERT_TRUE(m.ok());
    const auto& s = std::get<Status>(m->payload);
    EXPECT_TRUE(s.*f.field);
    for (const auto& other : kFlags) {
      if (other.field != f.field) {
        EXPECT_FALSE(s.*other.field) << other.name;
      }
    }
    // and back
    auto enc = encode_status(s, 1);
    ASSERT_TRUE(enc.ok());
    EXPECT_EQ(enc->data[f.byte], f.bit);
  }
}

TEST(Status, OutputsAndRpm) {
  auto m = decode(pmu_frame(0x04, 1, {0xFF, 0xFF, 0, 0, 0xF5}));
  ASSERT_TRUE(m.ok());
  const auto& s = std::get<Status>(m->payload);
  EXPECT_EQ(s.generator_rpm, 65535);
  EXPECT_EQ(s.outputs, 0x05);  // bits 4..7 are not outputs
  EXPECT_TRUE(s.avionics_servo_on());
  EXPECT_FALSE(s.payload_on());
  EXPECT_TRUE(s.charger_a_on());
  EXPECT_FALSE(s.charger_b_on());
  auto rpm = decode(pmu_frame(0x04, 1, {0x0F, 0xA0, 0, 0, 0}));
  EXPECT_EQ(std::get<Status>(rpm->payload).generator_rpm, 4000);
}

struct Bit6Case {
  std::optional<FirmwareVersion> fw;
  bool soa_shutdown, start_button, known;
};

TEST(Status, Bit6MeaningFollowsFirmware) {
  // v1.9 6.8: bit 6 was "start button pressed" before 1.16, "SOA shutdown" from 1.16.
  const Bit6Case cases[] = {{FirmwareVersion{1, 12}, false, true, true},
                            {FirmwareVersion{1, 15}, false, true, true},
                            {FirmwareVersion{1, 16}, true, false, true},
                            {FirmwareVersion{1, 17}, true, false, true},
                            {std::nullopt, true, false, false}};
  for (const auto& c : cases) {
    SCOPED_TRACE(c.fw ? to_string(*c.fw) : "unknown");
    auto m = decode(pmu_frame(0x04, 1, {0, 0, 0x40, 0, 0}), c.fw);
    ASSERT_TRUE(m.ok());
    const auto& s = std::get<Status>(m->payload);
    EXPECT_EQ(s.soa_shutdown, c.soa_shutdown);
    EXPECT_EQ(s.start_button, c.start_button);
    EXPECT_EQ(s.interpretation.firmware_known, c.known);
    EXPECT_EQ(s.interpretation.bit6, c.soa_shutdown ? Bit6Meaning::SoaShutdown : Bit6Meaning::StartButton);
    auto enc = encode_status(s, 1, c.fw);
    ASSERT_TRUE(enc.ok());
    EXPECT_EQ(enc->data[2], 0x40);
  }
}

TEST(Status, StarterReadyFlagFromFirmware112) {
  auto old = decode(pmu_frame(0x04, 1, {0, 0, 0, 0x80, 0}), FirmwareVersion{1, 11});
  EXPECT_FALSE(std::get<Status>(old->payload).starter_ready);
  auto cur = decode(pmu_frame(0x04, 1, {0, 0, 0, 0x80, 0}), FirmwareVersion{1, 12});
  EXPECT_TRUE(std::get<Status>(cur->payload).starter_ready);
}

// ---- lengths (table 1) --------------------------------------------------------------------
struct LengthCase {
  std::uint8_t packet;
  std::uint8_t length;
};

TEST(Telemetry, WrongLengthIsAnErrorWithReason) {
  const LengthCase cases[] = {{0x00, 7}, {0x01, 6}, {0x02, 4}, {0x03, 5}, {0x04, 5}};
  for (const auto& c : cases) {
    for (std::uint8_t len = 1; len <= 8; ++len) {
      CanFrame fr = pmu_frame(c.packet, 1, {});
      fr.length = len;
      auto m = decode(fr);
      if (len == c.length) {
        EXPECT_TRUE(m.ok());
        continue;
      }
      ASSERT_FALSE(m.ok()) << int(c.packet) << " len " << int(len);
      EXPECT_EQ(m.error().kind, DecodeErrorKind::WrongLength);
      EXPECT_EQ(m.error().expected, c.length);
      EXPECT_NE(m.error().describe().find("wrong length " + std::to_string(len)), std::string::npos)
          << m.error().describe();
    }
    // Zero length is the get (section 4.2).
    auto get = decode(pmu_frame(c.packet, 1, {}));
    ASSERT_TRUE(get.ok());
    EXPECT_TRUE(get->request);
    EXPECT_TRUE(std::holds_alternative<NoPayload>(get->payload));
  }
}

}  // namespace
}  // namespace pmu::codec
