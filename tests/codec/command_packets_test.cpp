// Commands and small packets, protocol v1.9 tables 7 and 19..24 and sections 5.22..5.26:
// the exact frame each encoder puts on the bus, and the decoding of the device's replies.
#include <gtest/gtest.h>

#include "pmu/codec/decode.hpp"
#include "pmu/codec/encode.hpp"
#include "support/pmu_frames.hpp"

namespace pmu::codec {
namespace {

using test::pmu_frame;

struct FrameCase {
  const char* what;
  Encoded encoded;
  CanFrame expected;
};

TEST(Commands, FramesMatchTheSpecByteForByte) {
  const FrameCase cases[] = {
      {"enable avionics+payload", encode_enable_outputs(0x03, 1), pmu_frame(0x21, 1, {0x03})},
      {"disable payload", encode_disable_outputs(0x02, 1), pmu_frame(0x22, 1, {0x02})},
      {"set outputs all off", encode_set_outputs(0x00, 1), pmu_frame(0x20, 1, {0x00})},
      {"set outputs all on", encode_set_outputs(0x0F, 9), pmu_frame(0x20, 9, {0x0F})},
      {"generation on", encode_generation(true, 1), pmu_frame(0x23, 1, {0x01})},
      {"generation off", encode_generation(false, 1), pmu_frame(0x23, 1, {0x00})},
      {"engine start", encode_engine_start(2), pmu_frame(0x24, 2, {})},
      {"engine stop", encode_engine_stop(2), pmu_frame(0x25, 2, {})},
      {"reset", encode_reset(0xFFFF), pmu_frame(0x26, 0xFFFF, {})},
      {"measure all", encode_measurement_request(0x1F, 1), pmu_frame(0x0F, 1, {0x1F})},
      {"measure temps", encode_measurement_request(0x08, 1), pmu_frame(0x0F, 1, {0x08})},
      {"get serial", encode_get(PacketId::Serial, 1), pmu_frame(0x30, 1, {})},
      {"get firmware", encode_get(PacketId::Firmware, 0xFFFF), pmu_frame(0x31, 0xFFFF, {})},
      {"get generation", encode_get(PacketId::Generation, 1), pmu_frame(0x23, 1, {})},
      {"get outputs", encode_get(PacketId::Outputs, 1), pmu_frame(0x20, 1, {})},
      {"get voltages", encode_get(PacketId::Voltages, 1), pmu_frame(0x00, 1, {})},
      {"get status", encode_get(PacketId::Status, 1), pmu_frame(0x04, 1, {})},
      {"measurement request get", encode_get(PacketId::MeasurementRequest, 1), pmu_frame(0x0F, 1, {})},
      {"set VA 12.0", encode_set(Parameter::AvionicsVoltage, 12.0, 1), pmu_frame(0x10, 1, {120})},
      {"set CT 2.5", encode_set(Parameter::CrankingTime, 2.5, 1), pmu_frame(0x19, 1, {25})},
      {"set CA 0x0203", encode_set(Parameter::CanAddress, 0x0203, 1), pmu_frame(0x1B, 1, {0x02, 0x03})},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.what);
    ASSERT_TRUE(c.encoded.ok()) << c.encoded.error().describe();
    EXPECT_EQ(*c.encoded, c.expected);
  }
}

TEST(Commands, OutputMasksOutsideBits0To3AreRefused) {
  for (auto* enc : {&encode_set_outputs, &encode_enable_outputs, &encode_disable_outputs}) {
    auto f = (*enc)(0x10, 1);
    ASSERT_FALSE(f.ok());
    EXPECT_EQ(f.error().kind, EncodeErrorKind::InvalidBits);
  }
}

TEST(Commands, EnableOrDisableNothingIsRefused) {
  EXPECT_EQ(encode_enable_outputs(0, 1).error().kind, EncodeErrorKind::EmptyMask);
  EXPECT_EQ(encode_disable_outputs(0, 1).error().kind, EncodeErrorKind::EmptyMask);
}

TEST(Commands, MeasurementRequestNeedsFirmware114) {
  auto old = encode_measurement_request(0x1F, 1, FirmwareVersion{1, 13});
  ASSERT_FALSE(old.ok());
  EXPECT_EQ(old.error().kind, EncodeErrorKind::Unsupported);
  EXPECT_EQ(old.error().describe(), "measurement_request needs firmware 1.14 (device has 1.13)");
  EXPECT_TRUE(encode_measurement_request(0x1F, 1, FirmwareVersion{1, 14}).ok());
  EXPECT_EQ(encode_measurement_request(0x20, 1).error().kind, EncodeErrorKind::InvalidBits);
  EXPECT_EQ(encode_measurement_request(0, 1).error().kind, EncodeErrorKind::EmptyMask);
}

TEST(Commands, NoGetForPacketsThatHaveNone) {
  for (auto p : {PacketId::EnableOutputs, PacketId::DisableOutputs, PacketId::EngineStart, PacketId::EngineStop,
                 PacketId::Reset}) {
    auto f = encode_get(p, 1);
    ASSERT_FALSE(f.ok());
    EXPECT_EQ(f.error().kind, EncodeErrorKind::NotAGet);
  }
}

struct DecodeCase {
  const char* what;
  CanFrame frame;
  bool request;
};

TEST(Commands, DecodeCommandFrames) {
  auto m = decode(pmu_frame(0x21, 4, {0x0B}));
  ASSERT_TRUE(m.ok());
  EXPECT_EQ(std::get<EnableOutputs>(m->payload).mask, 0x0B);
  m = decode(pmu_frame(0x22, 4, {0xF2}));  // bits 4..7 "don't care"
  EXPECT_EQ(std::get<DisableOutputs>(m->payload).mask, 0x02);
  m = decode(pmu_frame(0x20, 4, {0x05}));
  EXPECT_EQ(std::get<OutputStates>(m->payload).mask, 0x05);
  m = decode(pmu_frame(0x23, 4, {0xFE}));  // only bit 0 counts (table 22)
  EXPECT_FALSE(std::get<GenerationState>(m->payload).enabled);
  m = decode(pmu_frame(0x23, 4, {0x01}));
  EXPECT_TRUE(std::get<GenerationState>(m->payload).enabled);
  m = decode(pmu_frame(0x0F, 4, {0xFF}));
  EXPECT_EQ(std::get<MeasurementRequest>(m->payload).groups, 0x1F);
}

TEST(Commands, DataLessCommandsAreRequestsAndTakeNoData) {
  for (std::uint8_t p : {std::uint8_t{0x24}, std::uint8_t{0x25}, std::uint8_t{0x26}}) {
    auto m = decode(pmu_frame(p, 1, {}));
    ASSERT_TRUE(m.ok());
    EXPECT_TRUE(m->request);
    auto bad = decode(pmu_frame(p, 1, {0x00}));
    ASSERT_FALSE(bad.ok());
    EXPECT_EQ(bad.error().kind, DecodeErrorKind::WrongLength);
  }
  // 0x21/0x22 have no zero-length get (only ids up to 0x20, section 4.2).
  EXPECT_FALSE(decode(pmu_frame(0x21, 1, {})).ok());
  EXPECT_FALSE(decode(pmu_frame(0x22, 1, {})).ok());
}

TEST(Commands, SerialAndFirmwareReplies) {
  auto s = decode(pmu_frame(0x30, 1, {0xFF, 0xFF}));
  ASSERT_TRUE(s.ok());
  EXPECT_EQ(std::get<SerialNumber>(s->payload).serial_number, 65535);
  auto f = decode(pmu_frame(0x31, 1, {1, 17, 31, 12, 0x07, 0xE9}));  // 1.17 built 31/12/2025
  ASSERT_TRUE(f.ok());
  const auto& fi = std::get<FirmwareInfo>(f->payload);
  EXPECT_EQ(fi.firmware_major, 1);
  EXPECT_EQ(fi.firmware_minor, 17);
  EXPECT_EQ(fi.build_day, 31);
  EXPECT_EQ(fi.build_month, 12);
  EXPECT_EQ(fi.build_year, 2025);
  EXPECT_EQ(fi.version(), (FirmwareVersion{1, 17}));
  auto enc = encode_firmware(fi, 1);
  ASSERT_TRUE(enc.ok());
  EXPECT_EQ(*enc, pmu_frame(0x31, 1, {1, 17, 31, 12, 0x07, 0xE9}));
  EXPECT_EQ(*encode_serial(0x1234, 1), pmu_frame(0x30, 1, {0x12, 0x34}));
  EXPECT_FALSE(decode(pmu_frame(0x30, 1, {0x12})).ok());
  EXPECT_FALSE(decode(pmu_frame(0x31, 1, {1, 17, 31, 12, 0x07})).ok());
}

TEST(Commands, MeasurementRequestToOldFirmwareIsFlagged) {
  auto m = decode(pmu_frame(0x0F, 1, {0x1F}), FirmwareVersion{1, 12});
  ASSERT_TRUE(m.ok());
  EXPECT_TRUE(m->unsupported_by_firmware);
  EXPECT_FALSE(decode(pmu_frame(0x0F, 1, {0x1F}), FirmwareVersion{1, 14})->unsupported_by_firmware);
}

TEST(Commands, ErrorsSayWhatAndWhere) {
  CanFrame unknown = pmu_frame(0x05, 1, {});
  EXPECT_EQ(decode(unknown).error().describe(), "unknown packet 0x05 in id 1E050001");
  CanFrame foreign = pmu_frame(0x00, 1, {});
  foreign.id = 0x18FEF100;
  EXPECT_EQ(decode(foreign).error().kind, DecodeErrorKind::NotOurs);
  EXPECT_EQ(decode(foreign).error().describe(), "id 18FEF100 is not a PMU frame (needs a 29-bit id in group 0x1E)");
  CanFrame remote = pmu_frame(0x00, 1, {});
  remote.remote = true;
  EXPECT_EQ(decode(remote).error().kind, DecodeErrorKind::RemoteFrame);
  EXPECT_EQ(decode(pmu_frame(0x26, 1, {1})).error().describe(), "wrong length 1 for packet 0x26 reset (expects 0)");
}

}  // namespace
}  // namespace pmu::codec
