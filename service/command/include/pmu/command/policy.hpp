#pragma once
// The safety policy: which commands need an explicit `confirm`, which are denied outright,
// how many commands a device accepts per second. Pure: decides from the request and what the
// service knows of the device, sends nothing.
//
// Confirm rules (names used in the config's `policy.confirm` list; all on by default):
//   disable_avionics       any command that would switch the avionics/servo output off
//   reset                  0x26: outputs go to S0, energies to zero
//   engine_start           0x24
//   set_can_address        0x1B: the unit leaves the address the service knows it by
//   thermal_shutdown       T_U = 0 forces thermal shutdown (charging stops)
//   power_up_avionics_off  S0 without the avionics/servo bit: no avionics after a reset
//   stop_streaming         PS = 0 for a device the service expects to stream: it goes silent
// ENGINE_STOP is never refused by policy: not by deny, confirm, nor the rate limit.

#include <array>
#include <chrono>
#include <optional>
#include <string>
#include <vector>

#include "pmu/command/command.hpp"

namespace pmu::service {

enum class ConfirmRule : std::uint8_t {
  DisableAvionics,
  Reset,
  EngineStart,
  SetCanAddress,
  ThermalShutdown,
  PowerUpAvionicsOff,
  StopStreaming,
};
inline constexpr std::size_t kConfirmRuleCount = 7;
std::string_view to_string(ConfirmRule r) noexcept;
std::optional<ConfirmRule> confirm_rule_from_name(std::string_view name) noexcept;
// "disable_avionics, reset, ...": every rule's name, for messages.
std::string confirm_rule_names();

struct PolicyConfig {
  std::array<bool, kConfirmRuleCount> confirm{true, true, true, true, true, true, true};
  std::array<bool, kCommandKindCount> deny{};  // by CommandKind
  double rate_per_second = 20;                 // per device; 0 = no limit
  double burst = 40;                           // commands allowed at once
  Lifetimes lifetimes;                         // command_lifetime, max_command_lifetime
};

struct PolicyVerdict {
  CommandResult result = CommandResult::Completed;  // Completed = allowed
  std::string reason;
  bool allowed() const noexcept { return result == CommandResult::Completed; }
};

// What the service relies on from the device a request is for (its config).
struct DeviceUse {
  // The service listens for the packets the PMU streams (mode streaming), rather than
  // asking for them: PS = 0 would leave it nothing to hear.
  bool streaming = true;
};

// The confirm rule `r` falls under, whether or not the policy has it on; nullopt for none.
// pmuctl checks a whole configuration file with it before it sends anything.
std::optional<ConfirmRule> confirm_rule_for(const CommandRequest& r, const DeviceUse& device = {});
// What the rule protects against: "switches the avionics/servo output off".
std::string_view rule_why(ConfirmRule r) noexcept;

// Deny list and confirm rules for `r`. `device` matters only to stop_streaming: PS = 0 needs
// confirm for a device the service expects to stream, not for a polled one. The rate limit is
// RateLimiter's, not this function's.
PolicyVerdict check_policy(const CommandRequest& r, const PolicyConfig& p, const DeviceUse& device = {});

// A token bucket per device. Not thread-safe: used under the command service's lock.
class RateLimiter {
 public:
  explicit RateLimiter(double per_second = 20, double burst = 40) : rate_(per_second), burst_(burst), tokens_(burst) {}
  // Takes one token if there is one.
  bool allow(std::chrono::steady_clock::time_point now);

 private:
  double rate_;
  double burst_;
  double tokens_;
  std::optional<std::chrono::steady_clock::time_point> last_;
};

}  // namespace pmu::service
