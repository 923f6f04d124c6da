#include "pmu/baseline/settings.hpp"

#include <cmath>
#include <cstdio>

#include "pmu/codec/messages.hpp"

namespace pmu::baseline {

static_assert(kSettingCount == codec::kParameterCount + 2,
              "Setting lists the stored parameters in codec::Parameter's order, then outputs and generation");

std::optional<codec::Parameter> parameter_of(Setting s) noexcept {
  const auto i = static_cast<std::size_t>(s);
  if (i >= codec::kParameterCount) return std::nullopt;
  return static_cast<codec::Parameter>(i);
}

Setting setting_of(codec::Parameter p) noexcept { return static_cast<Setting>(static_cast<std::uint8_t>(p)); }

std::string_view setting_name(Setting s) noexcept {
  if (const auto p = parameter_of(s)) return codec::spec_of(*p).name;
  return s == Setting::Outputs ? "outputs" : "generation_enabled";
}

std::optional<Setting> setting_from_name(std::string_view name) noexcept {
  for (std::size_t i = 0; i < kSettingCount; ++i)
    if (setting_name(static_cast<Setting>(i)) == name) return static_cast<Setting>(i);
  return std::nullopt;
}

namespace {

template <std::size_t N>
std::string mask_text(const std::array<codec::NamedBit, N>& names, std::uint32_t raw) {
  std::string s;
  for (unsigned bit = 0; bit < 8; ++bit) {
    const auto b = static_cast<std::uint8_t>(1u << bit);
    if (!(raw & b)) continue;
    std::string name = "bit" + std::to_string(bit);
    for (const auto& n : names)
      if (n.bit == b) name = std::string(n.name);
    s += (s.empty() ? "" : ",") + name;
  }
  char hex[8];
  std::snprintf(hex, sizeof hex, "0x%02X", static_cast<unsigned>(raw & 0xFF));
  return (s.empty() ? std::string("none") : s) + " (" + hex + ")";
}

}  // namespace

std::string value_text(Setting s, std::uint32_t raw) {
  if (s == Setting::Outputs) return mask_text(codec::kOutputNames, raw);
  if (s == Setting::GenerationEnabled) return raw ? "on" : "off";
  if (s == Setting::PacketsStreamed) return mask_text(codec::kGroupNames, raw);
  if (s == Setting::PowerUpState) return mask_text(codec::kPowerUpNames, raw);
  const auto& spec = codec::spec_of(*parameter_of(s));
  std::string text;
  if (spec.kind == codec::ParameterKind::Scaled) {
    // As many decimals as the step has: 0.1 V steps print 24.0 V.
    const int decimals = static_cast<int>(std::ceil(std::log10(spec.divisor)));
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.*f", decimals, codec::parameter_value(spec.parameter, raw));
    text = buf;
  } else {
    text = std::to_string(raw);
  }
  return spec.unit.empty() ? text : text + " " + std::string(spec.unit);
}

}  // namespace pmu::baseline
