#include "pmu/command/command.hpp"

#include <algorithm>
#include <array>
#include <cstdio>
#include <cstring>

#include "pmu/codec/decode.hpp"
#include "pmu/codec/encode.hpp"
#include "pmu/codec/messages.hpp"

namespace pmu::service {
namespace {

using Reject = codec::Unexpected<std::string>;

constexpr std::array<std::string_view, kCommandKindCount> kKindNames{"get",
                                                                     "set_parameter",
                                                                     "set_outputs",
                                                                     "enable_outputs",
                                                                     "disable_outputs",
                                                                     "set_generation",
                                                                     "request_measurements",
                                                                     "engine_start",
                                                                     "engine_stop",
                                                                     "reset",
                                                                     "get_serial",
                                                                     "get_firmware"};

std::string quoted(std::string_view text) { return "'" + printable(text) + "'"; }

// What a GET may name: a stored parameter, outputs, generation, or a measurement group.
std::optional<codec::PacketId> get_target(std::string_view name) {
  using codec::PacketId;
  if (name == "generation_enabled") return PacketId::Generation;  // the Config field's name
  const auto p = codec::packet_from_name(name);
  if (!p || !codec::has_zero_length_get(*p)) return std::nullopt;
  if (*p == PacketId::Serial || *p == PacketId::Firmware || *p == PacketId::MeasurementRequest) return std::nullopt;
  return p;
}

codec::Result<bool, std::string> boolean(std::uint8_t byte, const char* field) {
  if (byte <= 1) return byte == 1;
  char buf[96];
  std::snprintf(buf, sizeof buf, "%s is not a boolean (byte 0x%02X; 0 or 1 expected)", field, byte);
  return Reject{std::string(buf)};
}

codec::Result<std::uint8_t, std::string> output_mask(std::uint8_t mask, bool allow_empty) {
  if (mask & ~codec::output_bit::All) {
    char buf[96];
    std::snprintf(buf, sizeof buf, "unknown output bits 0x%02X (outputs are bits 0..3)",
                  mask & ~codec::output_bit::All);
    return Reject{std::string(buf)};
  }
  if (!allow_empty && mask == 0) return Reject{std::string("no output named")};
  return mask;
}

codec::Result<CommandAction, std::string> parse_action(CommandKind kind, const CommandSample& s, bool enable) {
  switch (kind) {
    case CommandKind::Get: {
      const auto target = get_target(s.parameter);
      if (!target) return Reject{"unknown parameter " + quoted(s.parameter)};
      return CommandAction{action::Get{*target}};
    }
    case CommandKind::SetParameter: {
      const auto p = codec::parameter_from_name(s.parameter);
      if (!p) return Reject{"unknown parameter " + quoted(s.parameter)};
      // Range and step here, in wire units: what policy judges is the value that is sent.
      const auto raw = codec::to_raw(*p, s.value);
      if (!raw) return Reject{raw.error().describe()};
      return CommandAction{action::SetParameter{*p, *raw}};
    }
    case CommandKind::SetOutputs:
    case CommandKind::EnableOutputs:
    case CommandKind::DisableOutputs: {
      const auto mask = output_mask(s.outputs, kind == CommandKind::SetOutputs);
      if (!mask) return Reject{mask.error()};
      if (kind == CommandKind::SetOutputs) return CommandAction{action::SetOutputs{*mask}};
      if (kind == CommandKind::EnableOutputs) return CommandAction{action::EnableOutputs{*mask}};
      return CommandAction{action::DisableOutputs{*mask}};
    }
    case CommandKind::SetGeneration: return CommandAction{action::SetGeneration{enable}};
    case CommandKind::RequestMeasurements: {
      if (s.groups & ~codec::group_bit::All) {
        char buf[96];
        std::snprintf(buf, sizeof buf, "unknown measurement group bits 0x%02X (groups are bits 0..4)",
                      s.groups & ~codec::group_bit::All);
        return Reject{std::string(buf)};
      }
      return CommandAction{action::RequestMeasurements{s.groups ? s.groups : codec::group_bit::All}};
    }
    case CommandKind::EngineStart: return CommandAction{action::EngineStart{}};
    case CommandKind::EngineStop: return CommandAction{action::EngineStop{}};
    case CommandKind::Reset: return CommandAction{action::Reset{}};
    case CommandKind::GetSerial: return CommandAction{action::GetSerial{}};
    case CommandKind::GetFirmware: return CommandAction{action::GetFirmware{}};
  }
  return Reject{std::string("unknown command kind")};
}

// The hold bits of `groups` for a kind that may hold (the header says why there).
codec::Result<std::optional<ConfigHold>, std::string> parse_hold(const CommandSample& s) {
  const bool hold = (s.groups & hold_bit::Hold) != 0;
  const bool release = (s.groups & hold_bit::Release) != 0;
  if (!hold) {
    if (release) return Reject{std::string("groups bit 0x40 (release a hold) needs bit 0x80 (hold)")};
    return std::optional<ConfigHold>{};
  }
  const auto mark = s.request_id.rfind('#');
  if (mark == std::string::npos || mark == 0 || mark + 1 == s.request_id.size())
    return Reject{"a command that holds the configuration (groups bit 0x80) has a request id APPLY#N, not " +
                  quoted(s.request_id)};
  return std::optional<ConfigHold>{ConfigHold{s.request_id.substr(0, mark), release}};
}

codec::Result<bool, std::string> within(const std::string& text, std::size_t max, const char* field) {
  if (text.size() <= max) return true;
  return Reject{std::string(field) + " is " + std::to_string(text.size()) + " bytes long; at most " +
                std::to_string(max) + " are allowed"};
}

}  // namespace

// In unsigned nanoseconds: every value from 0 to 2^64-1 has a meaning and none can overflow.
codec::Result<std::chrono::steady_clock::time_point, std::string> deadline(std::uint64_t expires_at, const Now& now,
                                                                           const Lifetimes& lt) {
  using std::chrono::nanoseconds;
  if (expires_at == 0) return now.steady + lt.default_lifetime;
  const auto since_epoch = std::chrono::duration_cast<nanoseconds>(now.wall.time_since_epoch()).count();
  const std::uint64_t now_ns = since_epoch < 0 ? 0 : static_cast<std::uint64_t>(since_epoch);
  if (expires_at <= now_ns) return Reject{"expired " + std::to_string((now_ns - expires_at) / 1000000) + " ms ago"};
  const auto cap = static_cast<std::uint64_t>(std::chrono::duration_cast<nanoseconds>(lt.max_lifetime).count());
  const auto ahead = nanoseconds(static_cast<std::int64_t>(std::min(expires_at - now_ns, cap)));
  return now.steady + std::chrono::duration_cast<std::chrono::steady_clock::duration>(ahead);
}


bool changes_configuration(CommandKind k) noexcept {
  return k == CommandKind::SetParameter || k == CommandKind::SetOutputs || k == CommandKind::EnableOutputs ||
         k == CommandKind::DisableOutputs || k == CommandKind::SetGeneration || k == CommandKind::Reset;
}

bool may_hold(CommandKind k) noexcept { return k == CommandKind::Get || changes_configuration(k); }

std::string_view to_string(CommandKind k) noexcept { return kKindNames[static_cast<std::size_t>(k)]; }

std::optional<CommandKind> command_kind_from_name(std::string_view name) noexcept {
  for (std::size_t i = 0; i < kKindNames.size(); ++i)
    if (kKindNames[i] == name) return static_cast<CommandKind>(i);
  return std::nullopt;
}

std::string device_not_seen_reason(std::uint16_t address, std::string_view bus) {
  return "device " + std::to_string(address) + " not seen on " + std::string(bus);
}

namespace {
std::string not_served_lead(std::string_view bus) { return "bus '" + printable(bus) + "' is not served here"; }
}  // namespace

std::string bus_not_served_reason(std::string_view bus, std::string_view served) {
  return not_served_lead(bus) + " (buses: " + std::string(served) + ")";
}

bool says_no_such_target(std::string_view reason, std::string_view bus, std::uint16_t address) {
  const std::string lead = not_served_lead(bus) + " (";
  return reason == device_not_seen_reason(address, bus) || reason.substr(0, lead.size()) == lead;
}

std::string_view to_string(CommandResult r) noexcept {
  switch (r) {
    case CommandResult::Completed: return "COMPLETED";
    case CommandResult::Rejected: return "REJECTED";
    case CommandResult::Denied: return "DENIED";
    case CommandResult::Unsupported: return "UNSUPPORTED";
    case CommandResult::Timeout: return "TIMEOUT";
    case CommandResult::Failed: return "FAILED";
    case CommandResult::InProgress: return "IN_PROGRESS";
  }
  return "FAILED";
}

std::uint64_t content_fingerprint(const CommandSample& s) noexcept {
  // FNV-1a over every field that says what to do. A collision could only make one sender's
  // own reused id look like a resend; ids of different senders never meet here.
  std::uint64_t h = 1469598103934665603ull;
  auto mix = [&h](const void* data, std::size_t n) {
    const auto* p = static_cast<const unsigned char*>(data);
    for (std::size_t i = 0; i < n; ++i) h = (h ^ p[i]) * 1099511628211ull;
  };
  auto mix_text = [&](const std::string& t) {
    const auto n = t.size();
    mix(&n, sizeof n);
    mix(t.data(), n);
  };
  mix_text(s.vehicle);
  mix_text(s.bus);
  mix(&s.address, sizeof s.address);
  mix(&s.kind, sizeof s.kind);
  mix_text(s.parameter);
  std::uint64_t value_bits;
  std::memcpy(&value_bits, &s.value, sizeof value_bits);
  mix(&value_bits, sizeof value_bits);
  for (std::uint8_t b : {s.outputs, s.enable, s.groups, s.confirm}) mix(&b, 1);
  return h;
}

codec::Result<CommandRequest, std::string> parse_command(const CommandSample& s, const Now& now,
                                                         const Lifetimes& lifetimes) {
  if (s.request_id.empty()) return Reject{std::string("request_id is empty")};
  for (const auto& check :
       {within(s.request_id, kMaxRequestIdLength, "request_id"), within(s.bus, kMaxBusNameLength, "bus"),
        within(s.parameter, kMaxParameterLength, "parameter")})
    if (!check) return Reject{check.error()};
  if (s.kind >= kCommandKindCount) return Reject{"unknown command kind " + std::to_string(s.kind)};
  const auto kind = static_cast<CommandKind>(s.kind);
  const auto confirm = boolean(s.confirm, "confirm");
  if (!confirm) return Reject{confirm.error()};
  const auto enable = boolean(s.enable, "enable");
  if (!enable) return Reject{enable.error()};
  if (s.address == codec::kBroadcastAddress && kind != CommandKind::EngineStop)
    return Reject{std::string("broadcast (65535) is only accepted for engine_stop")};
  const auto expires = deadline(s.expires_at, now, lifetimes);
  if (!expires) return Reject{expires.error()};
  auto act = parse_action(kind, s, *enable);
  if (!act) return Reject{act.error()};
  std::optional<ConfigHold> hold;
  if (may_hold(kind)) {
    auto h = parse_hold(s);
    if (!h) return Reject{h.error()};
    hold = std::move(*h);
  }

  CommandRequest r;
  r.request_id = s.request_id;
  r.sender = s.sender;
  r.vehicle = s.vehicle;
  r.bus = s.bus;
  r.address = s.address;
  r.action = *act;
  r.expires = *expires;
  r.confirm = *confirm;
  r.hold = std::move(hold);
  return r;
}

namespace {
// VEHICLE/BUS/ADDRESS as pmuctl shows devices; the unnamed vehicle's are BUS/ADDRESS.
std::string device_path(const std::string& vehicle, const std::string& bus, std::uint16_t address) {
  std::string p = vehicle.empty() ? std::string() : printable(vehicle) + "/";
  return p + printable(bus) + "/" + std::to_string(address);
}
}  // namespace

std::string describe(const CommandRequest& r) {
  std::string s(to_string(r.kind()));
  char buf[64];
  std::visit(
      [&](const auto& a) {
        using A = std::decay_t<decltype(a)>;
        if constexpr (std::is_same_v<A, action::Get>) {
          s += " " + std::string(codec::packet_name(a.packet));
        } else if constexpr (std::is_same_v<A, action::SetParameter>) {
          std::snprintf(buf, sizeof buf, "=%g", codec::parameter_value(a.parameter, a.raw));
          s += " " + std::string(codec::spec_of(a.parameter).name) + buf;
        } else if constexpr (std::is_same_v<A, action::SetOutputs> || std::is_same_v<A, action::EnableOutputs> ||
                             std::is_same_v<A, action::DisableOutputs>) {
          std::snprintf(buf, sizeof buf, " outputs=0x%02X", a.mask);
          s += buf;
        } else if constexpr (std::is_same_v<A, action::SetGeneration>) {
          s += a.enable ? " on" : " off";
        } else if constexpr (std::is_same_v<A, action::RequestMeasurements>) {
          std::snprintf(buf, sizeof buf, " groups=0x%02X", a.groups);
          s += buf;
        }
      },
      r.action);
  s += r.bus.empty() && r.address == codec::kBroadcastAddress
           ? " to every PMU on every bus" + (r.vehicle.empty() ? std::string() : " of " + printable(r.vehicle))
           : " to " + device_path(r.vehicle, r.bus, r.address);
  if (r.confirm) s += " (confirmed)";
  if (r.hold) s += r.hold->release ? " (apply's last: releases its hold)" : " (under an apply's hold)";
  return s;
}

std::string describe(const CommandSample& s) {
  std::string out = s.kind < kCommandKindCount ? std::string(to_string(static_cast<CommandKind>(s.kind)))
                                               : "kind " + std::to_string(s.kind);
  if (!s.parameter.empty()) out += " " + printable(s.parameter);
  char buf[96];
  std::snprintf(buf, sizeof buf, " value=%g outputs=0x%02X groups=0x%02X", s.value, s.outputs, s.groups);
  out += buf;
  return out + " to " + device_path(s.vehicle, s.bus, s.address);
}

std::string printable(std::string_view text, std::size_t max) {
  std::string out;
  const std::size_t n = std::min(text.size(), max);
  out.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    const auto c = static_cast<unsigned char>(text[i]);
    if (c == '\\') {
      out += "\\\\";
    } else if (c >= 0x20 && c < 0x7F) {
      out += static_cast<char>(c);
    } else {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\x%02X", c);
      out += buf;
    }
  }
  if (text.size() > max) out += "...";
  return out;
}

}  // namespace pmu::service
