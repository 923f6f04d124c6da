#include "pmuctl/view/mask_names.hpp"

#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "pmu/codec/encode.hpp"
#include "pmu/codec/parameters.hpp"

namespace pmu::tools {
namespace {

const MaskNames kMasks[] = {
    {"outputs", codec::kOutputNames.data(), codec::kOutputNames.size()},
    {codec::spec_of(codec::Parameter::PacketsStreamed).name, codec::kGroupNames.data(), codec::kGroupNames.size()},
    {codec::spec_of(codec::Parameter::PowerUpState).name, codec::kPowerUpNames.data(), codec::kPowerUpNames.size()},
};

// The range said is the mask the names cover (0x1F for packets_streamed), never the byte's
// 0..255. A number with other bits is refused by the spec's own check (parse_config_value),
// before anything is sent; a bit the names cover but the unit's firmware lacks only the
// service can judge.
std::string valid_names(const MaskNames& m) {
  std::string s;
  unsigned defined = 0;
  for (std::size_t i = 0; i < m.count; ++i) {
    s += std::string(m.bits[i].name) + ", ";
    defined |= m.bits[i].bit;
  }
  char hex[8];
  std::snprintf(hex, sizeof hex, "0x%02X", defined);
  return s + "none, or a number 0.." + hex;
}

// The whole of `text` as a number; nullopt when anything is left over.
std::optional<double> number(std::string_view text) {
  const std::string s(text);
  if (s.empty() || s.find_first_of(" \t") != std::string::npos) return std::nullopt;
  char* end = nullptr;
  const double v = std::strtod(s.c_str(), &end);
  if (*end != '\0') return std::nullopt;
  return v;
}

ConfigValue refused(std::string why) { return {std::nullopt, std::move(why)}; }

ConfigValue parse_mask(const MaskNames& m, std::string_view text) {
  const std::string field(m.field);
  if (const auto v = number(text)) {
    if (!(*v >= 0 && *v <= 255 && std::floor(*v) == *v))
      return refused(field + ": '" + std::string(text) + "' is not a mask (" + valid_names(m) + ")");
    return {*v, {}};
  }
  if (text == "none") return {0.0, {}};
  std::uint8_t mask = 0;
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = text.find(',', start);
    const std::string_view token = text.substr(start, comma == std::string_view::npos ? comma : comma - start);
    const std::string where = " in '" + std::string(text) + "'";
    if (token.empty()) return refused(field + ": empty name" + where + " (" + valid_names(m) + ")");
    if (token == "none") return refused(field + ": 'none' cannot be combined with names" + where);
    std::optional<std::uint8_t> bit;
    for (std::size_t i = 0; i < m.count && !bit; ++i)
      if (m.bits[i].name == token) bit = m.bits[i].bit;
    if (!bit)
      return refused(field + ": unknown name '" + std::string(token) + "'" + where + " (" + valid_names(m) + ")");
    mask = static_cast<std::uint8_t>(mask | *bit);
    if (comma == std::string_view::npos) break;
    start = comma + 1;
  }
  return {static_cast<double>(mask), {}};
}

}  // namespace

const MaskNames* mask_names(std::string_view field) noexcept {
  for (const auto& m : kMasks)
    if (m.field == field) return &m;
  return nullptr;
}

ConfigValue parse_config_value(std::string_view parameter, std::string_view text) {
  ConfigValue out;
  if (const auto* m = mask_names(parameter)) {
    out = parse_mask(*m, text);
  } else {
    const auto v = number(text);
    if (!v || !std::isfinite(*v))
      return refused(std::string(parameter) + ": '" + std::string(text) + "' is not a number");
    out = {*v, {}};
  }
  // The spec's range, step and mask, as the service would judge them, so a value out of
  // range is bad usage (exit 2, interface.md 3.2) and never sent. The firmware is the newest:
  // the power_up_state bits an older unit lacks are the service's to refuse, knowing the unit.
  if (const auto p = codec::parameter_from_name(parameter); p && out.value)
    if (const auto raw = codec::to_raw(*p, *out.value); !raw) return refused(raw.error().describe());
  return out;
}

}  // namespace pmu::tools
