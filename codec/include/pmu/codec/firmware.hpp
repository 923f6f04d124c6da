#pragma once
// Firmware-dependent behaviour of the PMU, from the version histories of protocol v1.2 and
// v1.9. Where the firmware is unknown the codec assumes the current document (v1.9, firmware
// 1.17) and says so, because a device that has not yet answered 0x31 is most likely current.
//
//   feature                              from firmware   source
//   external temperature sensors (0x03)  1.12            v1.9 6.1
//   starter ready flag (0x04 reg 1 b7)   1.12            v1.9 6.1
//   measurement request 0x0F             1.14            v1.9 6.5
//   S0 bit 4 battery disconnect detect   1.15            v1.9 6.7
//   S0 bit 6 SOA management              1.16            v1.9 6.8
//   0x04 flag reg 0 bit 6 = SOA shutdown 1.16            v1.9 6.8 (before: start button)
//   baud rates 125/250/500/1000 kb/s     1.17            v1.9 6.9 (before: 1 Mbit/s only)

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace pmu::codec {

struct FirmwareVersion {
  std::uint8_t major = 0;
  std::uint8_t minor = 0;

  constexpr int ordinal() const noexcept { return major * 100 + minor; }
  friend constexpr bool operator==(FirmwareVersion a, FirmwareVersion b) noexcept { return a.ordinal() == b.ordinal(); }
  friend constexpr bool operator!=(FirmwareVersion a, FirmwareVersion b) noexcept { return !(a == b); }
  friend constexpr bool operator<(FirmwareVersion a, FirmwareVersion b) noexcept { return a.ordinal() < b.ordinal(); }
  friend constexpr bool operator>=(FirmwareVersion a, FirmwareVersion b) noexcept { return !(a < b); }
};

// "1.16" -> {1,16}; anything else (missing dot, > 99, trailing text) -> nullopt.
std::optional<FirmwareVersion> parse_firmware(std::string_view text) noexcept;
std::string to_string(FirmwareVersion v);

// The newest firmware the v1.9 document describes; assumed when the version is unknown.
inline constexpr FirmwareVersion kCurrentFirmware{1, 17};
// The oldest firmware the documents name (v1.9 6.1: 1.12 added the external temperatures and
// the starter-ready flag). What a unit before it did beyond that, and after kCurrentFirmware,
// no document says: a simulated PMU is only ever one of 1.12..1.17.
inline constexpr FirmwareVersion kOldestDescribedFirmware{1, 12};
// Whether `fw` is one the documents describe, kOldestDescribedFirmware..kCurrentFirmware.
constexpr bool is_described(FirmwareVersion fw) noexcept {
  return fw >= kOldestDescribedFirmware && !(kCurrentFirmware < fw);
}

enum class Feature : std::uint8_t {
  ExternalTemperatures,
  StarterReadyFlag,
  MeasurementRequest,
  BatteryDisconnectDetect,
  SoaManagement,
  SoaShutdownFlag,
  MultipleBaudRates,
};

FirmwareVersion first_firmware_with(Feature f) noexcept;
std::string_view feature_name(Feature f) noexcept;
inline constexpr Feature kAllFeatures[] = {
    Feature::ExternalTemperatures,    Feature::StarterReadyFlag, Feature::MeasurementRequest,
    Feature::BatteryDisconnectDetect, Feature::SoaManagement,    Feature::SoaShutdownFlag,
    Feature::MultipleBaudRates,
};

// Unknown firmware (nullopt) is treated as kCurrentFirmware.
bool supports(std::optional<FirmwareVersion> fw, Feature f) noexcept;

// Bit 6 of flag register 0 (packet 0x04) means "start button pressed" before 1.16 and
// "safe operating area shutdown" from 1.16.
enum class Bit6Meaning : std::uint8_t { StartButton, SoaShutdown };

struct FlagInterpretation {
  Bit6Meaning bit6;
  bool firmware_known;  // false: the meaning was assumed from kCurrentFirmware
};
FlagInterpretation interpret_flags(std::optional<FirmwareVersion> fw) noexcept;

// Bits of S0 (packet 0x18) that the firmware defines; others are "don't care".
std::uint8_t power_up_state_mask(std::optional<FirmwareVersion> fw) noexcept;

// CAN bit rates (bit/s) the firmware can run at: 1 Mbit/s only before 1.17.
bool supports_bitrate(std::optional<FirmwareVersion> fw, std::uint32_t bitrate) noexcept;

}  // namespace pmu::codec
