#include "pmu/baseline/config_file.hpp"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <initializer_list>
#include <set>

#include "pmu/codec/decimal_text.hpp"
#include "pmu/codec/encode.hpp"
#include "pmu/codec/messages.hpp"
#include "pmu/command/command.hpp"

namespace pmu::baseline {
namespace {

// Thrown inside this file only, and caught in read_config_file(): yaml-cpp reports by
// throwing, and a check deep in a value is simplest to leave the same way.
struct Bad {
  int line;
  std::string message;
};

int line_at(const YAML::Node& n) { return n.IsDefined() && n.Mark().line >= 0 ? n.Mark().line + 1 : 1; }
[[noreturn]] void bad(const YAML::Node& at, std::string message) { throw Bad{line_at(at), std::move(message)}; }

std::string shown(const YAML::Node& n) { return "'" + service::printable(n.Scalar()) + "'"; }

// The mapping's keys, each known and once; `known` in the order the messages list them.
void check_keys(const YAML::Node& map, std::string_view where, std::initializer_list<std::string_view> known) {
  if (!map.IsMap()) bad(map, std::string(where) + " must be a mapping of key: value");
  std::set<std::string> seen;
  for (const auto& kv : map) {
    if (!kv.first.IsScalar()) bad(kv.first, std::string(where) + ": a key must be a name");
    const std::string key = kv.first.Scalar();
    bool ok = false;
    for (const auto k : known) ok = ok || k == key;
    if (!ok) {
      std::string list;
      for (const auto k : known) list += (list.empty() ? "" : ", ") + std::string(k);
      bad(kv.first, "unknown key " + shown(kv.first) + " in " + std::string(where) + " (known: " + list + ")");
    }
    if (!seen.insert(key).second) bad(kv.first, std::string(where) + ": " + key + " appears twice");
  }
}

// The whole scalar as a finite number in plain decimal (codec/decimal_text.hpp), as the
// service's config takes numbers: a unit or anything else after it is refused, so "24 V" never
// reads as 24, and "0x18" never as 24 V.
double number(const YAML::Node& n, std::string_view name, bool integer = false) {
  if (!n.IsScalar()) bad(n, std::string(name) + " must be a number");
  const std::string& s = n.Scalar();
  char* end = nullptr;
  const double v = s.empty() ? std::nan("") : std::strtod(s.c_str(), &end);
  if (s.empty() || *end != '\0' || !std::isfinite(v) || s.find_first_of(" \t") != std::string::npos)
    bad(n, std::string(name) + ": " + shown(n) + " is not a number");
  if (integer && !codec::is_plain_decimal(s))
    bad(n, std::string(name) + ": " + shown(n) +
               " is not a whole number (digits, optionally after '-'; no fraction, leading 0, '+', 0x or exponent)");
  if (!codec::is_plain_decimal_number(s))
    bad(n, std::string(name) + ": " + shown(n) +
               " is not a decimal number (digits, optionally after '-' and with a fraction after '.'; no leading 0, "
               "'+', 0x, exponent, or '.' without digits on both sides)");
  return v;
}

// A whole number 0..max in plain decimal; or, where `hex` (a mask: interface.md 4.6), 0x hex.
std::uint32_t whole(const YAML::Node& n, std::string_view name, std::uint32_t max, bool hex_too = false) {
  if (!n.IsScalar()) bad(n, std::string(name) + " must be a whole number");
  const std::string& s = n.Scalar();
  const bool hex = hex_too && s.size() > 2 && s[0] == '0' && (s[1] == 'x' || s[1] == 'X');
  const bool spelled = hex ? s.find_first_not_of("0123456789abcdefABCDEF", 2) == std::string::npos
                           : codec::is_plain_decimal(s) && s[0] != '-';
  char* end = nullptr;
  const unsigned long long v = spelled ? std::strtoull(s.c_str(), &end, hex ? 16 : 10) : 0;
  if (!spelled || *end != '\0' || v > max)
    bad(n, std::string(name) + ": " + shown(n) + " is not a whole number 0.." + std::to_string(max) +
               (hex_too ? " (decimal, or hex after 0x)" : " (decimal: no fraction, exponent, 0x, '+' or leading 0)"));
  return static_cast<std::uint32_t>(v);
}

std::string text(const YAML::Node& n, std::string_view name, std::size_t max) {
  if (!n.IsScalar()) bad(n, std::string(name) + " must be a text");
  if (n.Scalar().size() > max) bad(n, std::string(name) + " is longer than " + std::to_string(max) + " characters");
  return n.Scalar();
}

codec::FirmwareVersion firmware(const YAML::Node& n, std::string_view name) {
  if (!n.IsScalar()) bad(n, std::string(name) + " must be a version such as \"1.17\"");
  const auto v = codec::parse_firmware(n.Scalar());
  if (!v) bad(n, std::string(name) + ": " + shown(n) + " is not a firmware version such as \"1.17\"");
  return *v;
}

// A list of bit names, `none` or [], or a whole number (decimal or 0x hex).
template <std::size_t N>
std::uint32_t mask(const YAML::Node& n, std::string_view name, const std::array<codec::NamedBit, N>& names) {
  std::string valid;
  for (const auto& b : names) valid += std::string(b.name) + ", ";
  valid = "a list of " + valid.substr(0, valid.size() - 2) + "; [] or none; or a number";
  if (n.IsScalar()) {
    if (n.Scalar() == "none") return 0;
    if (!n.Scalar().empty() && std::isdigit(static_cast<unsigned char>(n.Scalar()[0])))
      return whole(n, name, 0xFF, true);
    bad(n, std::string(name) + ": " + shown(n) + " is not a mask (" + valid + ")");
  }
  if (!n.IsSequence()) bad(n, std::string(name) + " must be " + valid);
  std::uint32_t m = 0;
  for (const auto& item : n) {
    if (!item.IsScalar()) bad(item, std::string(name) + ": each item must be a name (" + valid + ")");
    const auto bit = codec::bit_named(names, item.Scalar());
    if (!bit) bad(item, std::string(name) + ": unknown name " + shown(item) + " (" + valid + ")");
    if (m & *bit) bad(item, std::string(name) + ": " + item.Scalar() + " is named twice");
    m |= *bit;
  }
  return m;
}

std::uint32_t parameter(const YAML::Node& n, codec::Parameter p, std::optional<codec::FirmwareVersion> fw) {
  const auto& spec = codec::spec_of(p);
  double v = 0;
  if (p == codec::Parameter::PacketsStreamed)
    v = mask(n, spec.name, codec::kGroupNames);
  else if (p == codec::Parameter::PowerUpState)
    v = mask(n, spec.name, codec::kPowerUpNames);
  else if (spec.kind == codec::ParameterKind::Integer)  // can_address 1.5 is no address
    v = number(n, spec.name, true);
  else  // Compared as the wire carries it: a value between two steps is the step the device
        // would store (12.04 V is 12.0 V with 0.1 V steps).
    v = std::round(number(n, spec.name) * spec.divisor) / spec.divisor;
  // The spec's own check, on the value the wire would carry (interface.md 2.3).
  const auto raw = codec::to_raw(p, v, fw);
  if (!raw) bad(n, raw.error().describe());
  return *raw;
}

ConfigFile read(const YAML::Node& root) {
  ConfigFile f;
  if (!root.IsMap()) bad(root, "the file must be a mapping with device, parameters, outputs and generation_enabled");
  check_keys(root, "the file", {"device", "parameters", "outputs", "generation_enabled"});
  if (const auto d = root["device"]) {
    check_keys(d, "device", {"vehicle", "bus", "address", "serial", "firmware", "min_firmware", "date"});
    Header& h = f.header;
    if (d["vehicle"]) h.vehicle = text(d["vehicle"], "vehicle", service::kMaxBusNameLength);
    if (d["bus"]) h.bus = text(d["bus"], "bus", service::kMaxBusNameLength);
    if (d["address"]) h.address = static_cast<std::uint16_t>(whole(d["address"], "address", 65534));
    if (d["serial"]) {
      h.serial = static_cast<std::uint16_t>(whole(d["serial"], "serial", 65535));
      f.serial_line = line_at(d["serial"]);
    }
    if (d["firmware"]) h.firmware = firmware(d["firmware"], "firmware");
    if (d["min_firmware"]) {
      h.min_firmware = firmware(d["min_firmware"], "min_firmware");
      f.min_firmware_line = line_at(d["min_firmware"]);
    }
    if (d["date"]) h.date = text(d["date"], "date", 64);
  }
  const auto fw = f.header.firmware;
  if (const auto params = root["parameters"]) {
    std::vector<std::string_view> names;
    if (!params.IsMap()) bad(params, "parameters must be a mapping of name: value");
    for (const auto& kv : params) {
      const auto p = kv.first.IsScalar() ? codec::parameter_from_name(kv.first.Scalar()) : std::nullopt;
      if (!p) {
        std::string known;
        for (const auto& s : codec::parameter_table()) known += (known.empty() ? "" : ", ") + std::string(s.name);
        bad(kv.first, "unknown parameter " + shown(kv.first) + " (parameters: " + known + ")");
      }
      const Setting s = setting_of(*p);
      if (f.line_of(s)) bad(kv.first, std::string(setting_name(s)) + " appears twice");
      f.settings[s] = parameter(kv.second, *p, fw);
      f.line[static_cast<std::size_t>(s)] = line_at(kv.first);
    }
  }
  if (const auto o = root["outputs"]) {
    const std::uint32_t m = mask(o, "outputs", codec::kOutputNames);
    if (m & ~std::uint32_t{codec::output_bit::All}) {
      char hex[96];
      std::snprintf(hex, sizeof hex, "outputs 0x%02X has bits outside the defined mask 0x%02X", m,
                    unsigned{codec::output_bit::All});
      bad(o, hex);
    }
    f.settings[Setting::Outputs] = m;
    f.line[static_cast<std::size_t>(Setting::Outputs)] = line_at(o);
  }
  if (const auto g = root["generation_enabled"]) {
    if (!g.IsScalar() || (g.Scalar() != "true" && g.Scalar() != "false"))
      bad(g, "generation_enabled must be true or false");
    f.settings[Setting::GenerationEnabled] = g.Scalar() == "true" ? 1u : 0u;
    f.line[static_cast<std::size_t>(Setting::GenerationEnabled)] = line_at(g);
  }
  bool any = f.serial_line || f.min_firmware_line;
  for (const auto& v : f.settings.raw) any = any || v.has_value();
  if (!any) bad(root, "nothing to compare: no parameters, outputs, generation_enabled, serial or min_firmware");
  return f;
}

// A YAML double-quoted scalar: safe for any text a vehicle or bus name may hold.
std::string quote(std::string_view s) {
  std::string out = "\"";
  for (const char ch : s) {
    const auto c = static_cast<unsigned char>(ch);
    if (c == '"' || c == '\\') {
      out += '\\';
      out += static_cast<char>(c);
    } else if (c < 0x20 || c >= 0x7F) {
      char hex[8];
      std::snprintf(hex, sizeof hex, "\\x%02X", c);
      out += hex;
    } else {
      out += static_cast<char>(c);
    }
  }
  return out + "\"";
}

// A mask as a flow list of names, or as a number when a bit has no name.
template <std::size_t N>
std::string mask_yaml(const std::array<codec::NamedBit, N>& names, std::uint32_t raw) {
  std::uint32_t named = 0;
  for (const auto& b : names) named |= b.bit;
  if (raw & ~named) {
    char hex[16];
    std::snprintf(hex, sizeof hex, "0x%02X", static_cast<unsigned>(raw));
    return hex;
  }
  return "[" + codec::names_of(names, static_cast<std::uint8_t>(raw), ", ") + "]";
}

}  // namespace

std::string describe(const FileError& e, std::string_view source) {
  return std::string(source) + ":" + std::to_string(e.line) + ": " + e.message;
}

codec::Result<ConfigFile, FileError> read_config_file(std::string_view text) {
  try {
    const auto docs = YAML::LoadAll(std::string(text));
    if (docs.empty() || docs[0].IsNull()) return codec::Unexpected{FileError{1, "the file is empty"}};
    if (docs.size() > 1)
      return codec::Unexpected{FileError{line_at(docs[1]), "a second YAML document: the file holds one PMU's"}};
    return read(docs[0]);
  } catch (const Bad& b) {
    return codec::Unexpected{FileError{b.line, b.message}};
  } catch (const YAML::Exception& e) {
    return codec::Unexpected{FileError{e.mark.line >= 0 ? e.mark.line + 1 : 1, "YAML syntax error: " + e.msg}};
  }
}

std::optional<FileError> check_firmware(const ConfigFile& file, std::optional<codec::FirmwareVersion> firmware) {
  for (std::size_t i = 0; i < codec::kParameterCount; ++i) {
    const auto p = static_cast<codec::Parameter>(i);
    const auto& raw = file.settings[setting_of(p)];
    if (!raw) continue;
    const auto again = codec::to_raw(p, codec::parameter_value(p, *raw), firmware);
    if (!again) return FileError{file.line_of(setting_of(p)), again.error().describe()};
  }
  return std::nullopt;
}

std::string write_config_file(const Header& h, const Settings& settings) {
  std::string out =
      "# One PMU's stored configuration (pmu-dds, interface.md section 4.6): `pmuctl config diff`\n"
      "# compares it with a device, `pmuctl config apply` writes what differs, and a device's\n"
      "# `baseline:` in pmu-service.yaml watches for drift from it.\n"
      "device:\n";
  out += "  vehicle: " + quote(h.vehicle) + "\n";
  out += "  bus: " + quote(h.bus) + "\n";
  if (h.address) out += "  address: " + std::to_string(*h.address) + "\n";
  if (h.serial) out += "  serial: " + std::to_string(*h.serial) + "\n";
  if (h.firmware) out += "  firmware: " + quote(codec::to_string(*h.firmware)) + "\n";
  if (h.min_firmware) out += "  min_firmware: " + quote(codec::to_string(*h.min_firmware)) + "\n";
  if (!h.date.empty()) out += "  date: " + quote(h.date) + "\n";
  bool header_written = false;
  for (std::size_t i = 0; i < codec::kParameterCount; ++i) {
    const auto p = static_cast<codec::Parameter>(i);
    const auto& raw = settings[setting_of(p)];
    if (!raw) continue;
    if (!header_written) out += "parameters:\n", header_written = true;
    const auto& spec = codec::spec_of(p);
    std::string value;
    if (p == codec::Parameter::PacketsStreamed)
      value = mask_yaml(codec::kGroupNames, *raw);
    else if (p == codec::Parameter::PowerUpState)
      value = mask_yaml(codec::kPowerUpNames, *raw);
    else
      value = value_text(setting_of(p), *raw).substr(0, value_text(setting_of(p), *raw).find(' '));
    std::string line = "  " + std::string(spec.name) + ": " + value;
    if (!spec.unit.empty())
      line += std::string(line.size() < 34 ? 34 - line.size() : 1, ' ') + "# " + std::string(spec.unit);
    out += line + "\n";
  }
  if (const auto& o = settings[Setting::Outputs]) out += "outputs: " + mask_yaml(codec::kOutputNames, *o) + "\n";
  if (const auto& g = settings[Setting::GenerationEnabled])
    out += std::string("generation_enabled: ") + (*g ? "true" : "false") + "\n";
  return out;
}

}  // namespace pmu::baseline
