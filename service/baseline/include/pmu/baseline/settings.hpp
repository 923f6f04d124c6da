#pragma once
// What a configuration file holds of a PMU: its eleven stored parameters (0x10..0x1B), its
// outputs (0x20) and its generation state (0x23), each as the raw value the wire carries, so
// two values compare equal exactly when the device would store the same thing (12.04 V and
// 12.0 V are one value with 0.1 V steps).

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "pmu/codec/parameters.hpp"

namespace pmu::baseline {

// The stored parameters in codec::Parameter's order, then the two switched states.
enum class Setting : std::uint8_t {
  AvionicsVoltage,
  PayloadVoltage,
  ServoVoltage,
  BatteryVoltage,
  PacketPeriod,
  PacketsStreamed,
  TemperatureOffset,
  UpperTemperatureLimit,
  PowerUpState,
  CrankingTime,
  CanAddress,
  Outputs,
  GenerationEnabled,
};
inline constexpr std::size_t kSettingCount = 13;

// The names of `pmuctl config get` and pmu::v5::Config.
std::string_view setting_name(Setting s) noexcept;
std::optional<Setting> setting_from_name(std::string_view name) noexcept;
// The stored parameter a setting is, if it is one.
std::optional<codec::Parameter> parameter_of(Setting s) noexcept;
Setting setting_of(codec::Parameter p) noexcept;

// A raw value in its unit, as `config get` shows it: "24.0 V", "1.5 s", "40 degC",
// "avionics_servo,payload (0x03)", "none (0x00)", "yes", "no".
std::string value_text(Setting s, std::uint32_t raw);

struct Settings {
  std::array<std::optional<std::uint32_t>, kSettingCount> raw{};
  std::optional<std::uint32_t>& operator[](Setting s) { return raw[static_cast<std::size_t>(s)]; }
  const std::optional<std::uint32_t>& operator[](Setting s) const { return raw[static_cast<std::size_t>(s)]; }
};

}  // namespace pmu::baseline
