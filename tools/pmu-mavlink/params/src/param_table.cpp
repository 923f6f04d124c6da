#include "pmu/mavlink_params/param_table.hpp"

#include <cmath>

#include "pmu/codec/encode.hpp"
#include "pmu/codec/messages.hpp"
#include "pmu/codec/parameters.hpp"

namespace pmu::mavlink_params {
namespace {

using S = Setting;

// can_address is read-only here: a set moves the unit off the address the bridge and the
// service know it by (interface.md 2.6), which a ground station's "load parameter file" would
// do without a word; `pmuctl --confirm config set can_address` is the way.
constexpr ParamSpec kTable[kSettingCount] = {
    {S::AvionicsVoltage, "AVION_V", "V", true},      {S::PayloadVoltage, "PAYLD_V", "V", true},
    {S::ServoVoltage, "SERVO_V", "V", true},         {S::BatteryVoltage, "BATT_V", "V", true},
    {S::PacketPeriod, "PKT_PERIOD", "s", true},      {S::PacketsStreamed, "PKT_STREAM", "", true},
    {S::TemperatureOffset, "TEMP_OFFSET", "", true}, {S::UpperTemperatureLimit, "TEMP_UPPER", "degC", true},
    {S::PowerUpState, "POWERUP", "", true},          {S::CrankingTime, "CRANK_TIME", "s", true},
    {S::CanAddress, "CAN_ADDR", "", false},          {S::Outputs, "OUTPUTS", "", true},
    {S::GenerationEnabled, "GEN_ENABLE", "", true},
};

constexpr bool rows_in_order() {
  for (std::size_t i = 0; i < kSettingCount; ++i)
    if (static_cast<std::size_t>(kTable[i].setting) != i) return false;
  return true;
}
static_assert(rows_in_order(), "one row per Setting, in Setting's order");

constexpr std::string_view kPrefix = "PMU";

// A whole number within 0..max, or why not.
codec::Result<std::uint32_t, std::string> whole(std::string_view what, float value, std::uint32_t max) {
  const double v = value;
  if (!std::isfinite(v)) return codec::Unexpected{std::string(what) + ": value is not a number"};
  const double r = std::round(v);
  if (std::fabs(v - r) > 1e-3 || r < 0 || r > max)
    return codec::Unexpected{std::string(what) + ": value " + std::to_string(v) + " is not a whole number 0.." +
                             std::to_string(max)};
  return static_cast<std::uint32_t>(r);
}

}  // namespace

const ParamSpec (&param_table() noexcept)[kSettingCount] { return kTable; }

const ParamSpec& spec_of(Setting s) noexcept { return kTable[static_cast<std::size_t>(s)]; }

std::string param_name(ParamRef p) {
  return std::string(kPrefix) + static_cast<char>('1' + p.pmu) + "_" + std::string(spec_of(p.setting).suffix);
}

std::optional<ParamRef> param_from_name(std::string_view name, std::size_t pmu_count) noexcept {
  if (name.size() < kPrefix.size() + 2 || name.substr(0, kPrefix.size()) != kPrefix) return std::nullopt;
  const char digit = name[kPrefix.size()];
  if (digit < '1' || digit > '9' || name[kPrefix.size() + 1] != '_') return std::nullopt;
  const auto pmu = static_cast<std::size_t>(digit - '1');
  if (pmu >= pmu_count) return std::nullopt;
  const auto suffix = name.substr(kPrefix.size() + 2);
  for (const auto& row : kTable)
    if (row.suffix == suffix) return ParamRef{pmu, row.setting};
  return std::nullopt;
}

std::uint16_t param_index(ParamRef p) noexcept {
  return static_cast<std::uint16_t>(p.pmu * kSettingCount + static_cast<std::size_t>(p.setting));
}

std::optional<ParamRef> param_from_index(std::int64_t index, std::size_t pmu_count) noexcept {
  if (index < 0 || static_cast<std::size_t>(index) >= param_count(pmu_count)) return std::nullopt;
  const auto i = static_cast<std::size_t>(index);
  return ParamRef{i / kSettingCount, static_cast<Setting>(i % kSettingCount)};
}

float to_real32(Setting s, std::uint32_t raw) noexcept {
  if (const auto p = baseline::parameter_of(s)) return static_cast<float>(codec::parameter_value(*p, raw));
  return static_cast<float>(raw);
}

codec::Result<std::uint32_t, std::string> from_real32(Setting s, float value) {
  if (const auto p = baseline::parameter_of(s)) {
    auto raw = codec::to_raw(*p, static_cast<double>(value));
    if (!raw) return codec::Unexpected{raw.error().describe()};
    return *raw;
  }
  if (s == Setting::GenerationEnabled) return whole("generation_enabled", value, 1);
  auto mask = whole("outputs", value, 0xFF);
  if (mask && (*mask & ~std::uint32_t{codec::output_bit::All}))
    return codec::Unexpected{"outputs " + std::to_string(*mask) + " has bits outside the defined mask 0x0F"};
  return mask;
}

}  // namespace pmu::mavlink_params
