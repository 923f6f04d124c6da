// Firmware differences: v1.9 section 6 (version history) and v1.2 tables 6 and 15.
#include <gtest/gtest.h>

#include "pmu/codec/firmware.hpp"

namespace pmu::codec {
namespace {

TEST(Firmware, Parse) {
  EXPECT_EQ(parse_firmware("1.16"), (FirmwareVersion{1, 16}));
  EXPECT_EQ(parse_firmware("0.0"), (FirmwareVersion{0, 0}));
  EXPECT_EQ(parse_firmware("99.99"), (FirmwareVersion{99, 99}));
  for (const char* bad : {"", "1", "1.", ".1", "1.16a", "100.1", "1.100", "a.b", "1..2", "-1.2", "1.2.3"})
    EXPECT_FALSE(parse_firmware(bad).has_value()) << bad;
  EXPECT_EQ(to_string(FirmwareVersion{1, 7}), "1.7");
}

TEST(Firmware, Ordering) {
  EXPECT_LT((FirmwareVersion{1, 9}), (FirmwareVersion{1, 12}));  // numeric, not lexical
  EXPECT_LT((FirmwareVersion{1, 99}), (FirmwareVersion{2, 0}));
}

struct FeatureCase {
  Feature feature;
  FirmwareVersion last_without;
  FirmwareVersion first_with;
};

const FeatureCase kFeatures[] = {
    {Feature::ExternalTemperatures, {1, 11}, {1, 12}},     // 6.1
    {Feature::StarterReadyFlag, {1, 11}, {1, 12}},         // 6.1
    {Feature::MeasurementRequest, {1, 13}, {1, 14}},       // 6.5
    {Feature::BatteryDisconnectDetect, {1, 14}, {1, 15}},  // 6.7
    {Feature::SoaManagement, {1, 15}, {1, 16}},            // 6.8
    {Feature::SoaShutdownFlag, {1, 15}, {1, 16}},          // 6.8
    {Feature::MultipleBaudRates, {1, 16}, {1, 17}},        // 6.9
};

TEST(Firmware, FeatureTable) {
  for (const auto& c : kFeatures) {
    SCOPED_TRACE(std::string(feature_name(c.feature)));
    EXPECT_FALSE(supports(c.last_without, c.feature));
    EXPECT_TRUE(supports(c.first_with, c.feature));
    EXPECT_TRUE(supports(std::nullopt, c.feature));  // unknown = current document
    EXPECT_EQ(first_firmware_with(c.feature), c.first_with);
  }
}

TEST(Firmware, Bit6MeaningAndWhetherAssumed) {
  EXPECT_EQ(interpret_flags(FirmwareVersion{1, 15}).bit6, Bit6Meaning::StartButton);
  EXPECT_TRUE(interpret_flags(FirmwareVersion{1, 15}).firmware_known);
  EXPECT_EQ(interpret_flags(FirmwareVersion{1, 16}).bit6, Bit6Meaning::SoaShutdown);
  EXPECT_EQ(interpret_flags(std::nullopt).bit6, Bit6Meaning::SoaShutdown);
  EXPECT_FALSE(interpret_flags(std::nullopt).firmware_known);
}

TEST(Firmware, PowerUpStateBits) {
  // v1.2 table 15: bits 0-3 and 5; bit 4 from 1.15, bit 6 from 1.16; bit 7 never.
  EXPECT_EQ(power_up_state_mask(FirmwareVersion{1, 12}), 0x2F);
  EXPECT_EQ(power_up_state_mask(FirmwareVersion{1, 15}), 0x3F);
  EXPECT_EQ(power_up_state_mask(FirmwareVersion{1, 16}), 0x7F);
  EXPECT_EQ(power_up_state_mask(std::nullopt), 0x7F);
}

TEST(Firmware, BitRates) {
  // v1.2 section 2: 1 Mbit/s only; v1.9 section 2 / 6.9: 125, 250, 500, 1000 kb/s from 1.17.
  for (std::uint32_t rate : {125000u, 250000u, 500000u}) {
    EXPECT_FALSE(supports_bitrate(FirmwareVersion{1, 16}, rate));
    EXPECT_TRUE(supports_bitrate(FirmwareVersion{1, 17}, rate));
  }
  EXPECT_TRUE(supports_bitrate(FirmwareVersion{1, 12}, 1000000));
  EXPECT_FALSE(supports_bitrate(FirmwareVersion{1, 17}, 800000));
}

}  // namespace
}  // namespace pmu::codec
