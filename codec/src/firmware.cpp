#include "pmu/codec/firmware.hpp"

#include <charconv>

namespace pmu::codec {

std::optional<FirmwareVersion> parse_firmware(std::string_view text) noexcept {
  const auto dot = text.find('.');
  if (dot == std::string_view::npos || dot == 0 || dot + 1 >= text.size()) return std::nullopt;
  unsigned major = 0, minor = 0;
  const char* begin = text.data();
  const char* end = text.data() + text.size();
  auto r1 = std::from_chars(begin, begin + dot, major);
  if (r1.ec != std::errc{} || r1.ptr != begin + dot) return std::nullopt;
  auto r2 = std::from_chars(begin + dot + 1, end, minor);
  if (r2.ec != std::errc{} || r2.ptr != end) return std::nullopt;
  // Table 24: major and minor are each 0..99.
  if (major > 99 || minor > 99) return std::nullopt;
  return FirmwareVersion{static_cast<std::uint8_t>(major), static_cast<std::uint8_t>(minor)};
}

std::string to_string(FirmwareVersion v) { return std::to_string(v.major) + "." + std::to_string(v.minor); }

FirmwareVersion first_firmware_with(Feature f) noexcept {
  switch (f) {
    case Feature::ExternalTemperatures:
    case Feature::StarterReadyFlag: return {1, 12};
    case Feature::MeasurementRequest: return {1, 14};
    case Feature::BatteryDisconnectDetect: return {1, 15};
    case Feature::SoaManagement:
    case Feature::SoaShutdownFlag: return {1, 16};
    case Feature::MultipleBaudRates: return {1, 17};
  }
  return kCurrentFirmware;
}

std::string_view feature_name(Feature f) noexcept {
  switch (f) {
    case Feature::ExternalTemperatures: return "external_temperatures";
    case Feature::StarterReadyFlag: return "starter_ready_flag";
    case Feature::MeasurementRequest: return "measurement_request";
    case Feature::BatteryDisconnectDetect: return "battery_disconnect_detect";
    case Feature::SoaManagement: return "soa_management";
    case Feature::SoaShutdownFlag: return "soa_shutdown_flag";
    case Feature::MultipleBaudRates: return "multiple_baud_rates";
  }
  return "unknown";
}

bool supports(std::optional<FirmwareVersion> fw, Feature f) noexcept {
  return fw.value_or(kCurrentFirmware) >= first_firmware_with(f);
}

FlagInterpretation interpret_flags(std::optional<FirmwareVersion> fw) noexcept {
  return {supports(fw, Feature::SoaShutdownFlag) ? Bit6Meaning::SoaShutdown : Bit6Meaning::StartButton, fw.has_value()};
}

std::uint8_t power_up_state_mask(std::optional<FirmwareVersion> fw) noexcept {
  // v1.2 table 15: bits 0..3 and 5; bit 4 from 1.15, bit 6 from 1.16; bit 7 never.
  std::uint8_t mask = 0x2F;
  if (supports(fw, Feature::BatteryDisconnectDetect)) mask |= 0x10;
  if (supports(fw, Feature::SoaManagement)) mask |= 0x40;
  return mask;
}

bool supports_bitrate(std::optional<FirmwareVersion> fw, std::uint32_t bitrate) noexcept {
  if (bitrate == 1000000) return true;
  if (!supports(fw, Feature::MultipleBaudRates)) return false;
  return bitrate == 125000 || bitrate == 250000 || bitrate == 500000;
}

}  // namespace pmu::codec
