#include "pmu/command/policy.hpp"

#include <algorithm>
#include <array>
#include <cstdio>

#include "pmu/codec/messages.hpp"

namespace pmu::service {
namespace {

constexpr std::array<std::string_view, kConfirmRuleCount> kRuleNames{
    "disable_avionics",      "reset",          "engine_start",    "set_can_address", "thermal_shutdown",
    "power_up_avionics_off", "stop_streaming", "blind_monitoring"};

// What each rule protects against, for the DENIED reason.
constexpr std::array<std::string_view, kConfirmRuleCount> kRuleWhy{
    "switches the avionics/servo output off",
    "resets the PMU (outputs to their power-up state)",
    "cranks the engine",
    "moves the PMU to another CAN address",
    "sets the upper temperature limit to 0, or at or below the unit's internal temperature (below 128 degC while "
    "it is unknown), which forces thermal shutdown",
    "leaves the avionics/servo output off at the next power-up or reset",
    "sets packets_streamed to 0: the PMU stops the telemetry this service listens for, and goes OFFLINE",
    "drops from packets_streamed a packet the readiness and alarm rules read: they go blind",
};

// T_U at or below the internal temperature shuts the unit down (v1.9 5.14: all battery
// charging ceases); 0 forces it whatever the temperature (table 15). docs/safety.md H2.
bool forces_thermal_shutdown(std::uint32_t t_u, const DeviceUse& device) {
  if (t_u == 0) return true;
  if (!device.internal_temperature) return t_u < kSafeUpperTemperatureLimit;
  return static_cast<double>(t_u) <= *device.internal_temperature;
}

std::string degrees(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.0f degC", v);
  return buf;
}

// What `r` would do, for the DENIED reason: the rule's text, or for a rule judged by effect,
// the values it was judged on.
std::string effect(ConfirmRule rule, const CommandRequest& r, const DeviceUse& device) {
  const auto* set = std::get_if<action::SetParameter>(&r.action);
  if (rule == ConfirmRule::ThermalShutdown && set && set->raw != 0) {
    const std::string limit = "sets the upper temperature limit to " + degrees(set->raw);
    if (!device.internal_temperature)
      return limit + " while the unit's internal temperature is unknown (safe from " +
             degrees(kSafeUpperTemperatureLimit) + "): it may force thermal shutdown, which stops charging";
    return limit + ", at or below the unit's internal temperature " + degrees(*device.internal_temperature) +
           ": it forces thermal shutdown, which stops charging";
  }
  if (rule == ConfirmRule::BlindMonitoring && set) {
    const auto dropped = static_cast<std::uint8_t>(device.packets_needed & ~set->raw);
    return "drops " + codec::names_of(codec::kGroupNames, dropped, ", ") +
           " from packets_streamed: the readiness and alarm rules that read them go blind";
  }
  return std::string(kRuleWhy[static_cast<std::size_t>(rule)]);
}

}  // namespace

// Judged on the typed request, whose values are already what the wire will carry: a
// requested 0.0004 that rounds to 0 is 0 here.
std::optional<ConfirmRule> confirm_rule_for(const CommandRequest& r, const DeviceUse& device) {
  using codec::output_bit::AvionicsServo;
  if (const auto* off = std::get_if<action::DisableOutputs>(&r.action))
    return off->mask & AvionicsServo ? std::optional(ConfirmRule::DisableAvionics) : std::nullopt;
  if (const auto* set = std::get_if<action::SetOutputs>(&r.action))
    return set->mask & AvionicsServo ? std::nullopt : std::optional(ConfirmRule::DisableAvionics);
  if (std::holds_alternative<action::Reset>(r.action)) return ConfirmRule::Reset;
  if (std::holds_alternative<action::EngineStart>(r.action)) return ConfirmRule::EngineStart;
  if (const auto* p = std::get_if<action::SetParameter>(&r.action)) {
    switch (p->parameter) {
      case codec::Parameter::CanAddress: return ConfirmRule::SetCanAddress;
      case codec::Parameter::UpperTemperatureLimit:
        return forces_thermal_shutdown(p->raw, device) ? std::optional(ConfirmRule::ThermalShutdown) : std::nullopt;
      case codec::Parameter::PowerUpState:
        return p->raw & AvionicsServo ? std::nullopt : std::optional(ConfirmRule::PowerUpAvionicsOff);
      // Set-points within their ranges (v1.9 tables 8 to 11): none switches an output off.
      case codec::Parameter::AvionicsVoltage:
      case codec::Parameter::PayloadVoltage:
      case codec::Parameter::ServoVoltage:
      case codec::Parameter::BatteryVoltage: return std::nullopt;
      case codec::Parameter::PacketsStreamed:
        // A polled device is asked for its packets: what it streams takes nothing from the
        // service (docs/safety.md H3).
        if (!device.streaming) return std::nullopt;
        if (p->raw == 0) return ConfirmRule::StopStreaming;
        return device.packets_needed & ~p->raw ? std::optional(ConfirmRule::BlindMonitoring) : std::nullopt;
      case codec::Parameter::PacketPeriod:
      case codec::Parameter::TemperatureOffset:
      case codec::Parameter::CrankingTime: return std::nullopt;
    }
  }
  return std::nullopt;
}


std::string_view rule_why(ConfirmRule r) noexcept { return kRuleWhy[static_cast<std::size_t>(r)]; }

std::string_view to_string(ConfirmRule r) noexcept { return kRuleNames[static_cast<std::size_t>(r)]; }

std::optional<ConfirmRule> confirm_rule_from_name(std::string_view name) noexcept {
  for (std::size_t i = 0; i < kRuleNames.size(); ++i)
    if (kRuleNames[i] == name) return static_cast<ConfirmRule>(i);
  return std::nullopt;
}

std::string confirm_rule_names() {
  std::string names;
  for (const auto n : kRuleNames) names += (names.empty() ? "" : ", ") + std::string(n);
  return names;
}

PolicyVerdict check_policy(const CommandRequest& r, const PolicyConfig& p, const DeviceUse& device) {
  if (r.kind() == CommandKind::EngineStop) return {};  // never refused by policy
  if (p.deny[static_cast<std::size_t>(r.kind())])
    return {CommandResult::Denied, std::string(to_string(r.kind())) + " is denied by the service's policy"};
  if (const auto rule = confirm_rule_for(r, device); rule && p.confirm[static_cast<std::size_t>(*rule)] && !r.confirm) {
    return {CommandResult::Denied, std::string(to_string(r.kind())) + " " + effect(*rule, r, device) +
                                       ": it needs confirm (pmuctl --confirm); rule " + std::string(to_string(*rule))};
  }
  return {};
}

bool RateLimiter::allow(std::chrono::steady_clock::time_point now) {
  if (rate_ <= 0) return true;
  if (last_) tokens_ = std::min(burst_, tokens_ + std::chrono::duration<double>(now - *last_).count() * rate_);
  last_ = now;
  if (tokens_ < 1) return false;
  tokens_ -= 1;
  return true;
}

}  // namespace pmu::service
