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

std::string value_text(Setting s, std::uint32_t raw) {
  const auto byte = static_cast<std::uint8_t>(raw);
  if (s == Setting::Outputs) return codec::mask_text(codec::kOutputNames, byte);
  if (s == Setting::GenerationEnabled) return raw ? "yes" : "no";  // as `config get` says it
  if (s == Setting::PacketsStreamed) return codec::mask_text(codec::kGroupNames, byte);
  if (s == Setting::PowerUpState) return codec::mask_text(codec::kPowerUpNames, byte);
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
