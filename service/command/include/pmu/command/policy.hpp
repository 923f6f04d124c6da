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
//   thermal_shutdown       T_U at or below the unit's internal temperature forces thermal
//                          shutdown (charging stops); T_U = 0 always; with the internal
//                          temperature unknown, any T_U below kSafeUpperTemperatureLimit
//   power_up_avionics_off  S0 without the avionics/servo bit: no avionics after a reset
//   stop_streaming         PS = 0 for a device the service expects to stream: it goes silent
//   blind_monitoring       PS without a packet the readiness and alarm rules read, for a
//                          device the service expects to stream: those rules go blind
// Rules that depend on the unit are judged by effect, on what the unit reports now
// (DeviceUse); what is not known is taken at its worst: unknown is never OK (docs/safety.md
// H6). ENGINE_STOP is never refused by policy: not by deny, confirm, nor the rate limit.

#include <array>
#include <chrono>
#include <optional>
#include <string>
#include <vector>

#include "pmu/codec/messages.hpp"
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
  BlindMonitoring,
};
inline constexpr std::size_t kConfirmRuleCount = 8;
std::string_view to_string(ConfirmRule r) noexcept;
std::optional<ConfirmRule> confirm_rule_from_name(std::string_view name) noexcept;
// "disable_avionics, reset, ...": every rule's name, for messages.
std::string confirm_rule_names();

struct PolicyConfig {
  std::array<bool, kConfirmRuleCount> confirm{true, true, true, true, true, true, true, true};
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

// The packets (codec::group_bit) the alarm table's PMU rows read: voltages, temperatures,
// status (alarms::packets_read of the table's defaults; a test keeps the two equal).
inline constexpr std::uint8_t kRulePackets =
    codec::group_bit::Voltages | codec::group_bit::Temperatures | codec::group_bit::Status;

// T_U at or above this is judged safe when the unit's internal temperature is unknown: it is
// above the highest internal temperature the PMU can report (v1.9 table 5: +127 degC), so it
// cannot be at or below a temperature the unit has.
inline constexpr std::uint32_t kSafeUpperTemperatureLimit = 128;

// What the service relies on from the device a request is for, and what the device reports
// now. Every field's default is the worst case, for a caller that knows nothing of the
// device (pmuctl's apply plan): a rule judged by effect then asks for confirm.
struct DeviceUse {
  // The service listens for the packets the PMU streams (mode streaming), rather than
  // asking for them: PS = 0 would leave it nothing to hear.
  bool streaming = true;
  // The packets its readiness and alarm rules read (alarms::packets_read of its settings).
  std::uint8_t packets_needed = kRulePackets;
  // Its internal temperature (v1.9 table 5), degC, from a temperatures packet that is not
  // stale; nullopt when unknown.
  std::optional<double> internal_temperature{};
};

// The confirm rule `r` falls under, whether or not the policy has it on; nullopt for none.
// pmuctl checks a whole configuration file with it before it sends anything.
std::optional<ConfirmRule> confirm_rule_for(const CommandRequest& r, const DeviceUse& device = {});
// What the rule protects against: "switches the avionics/servo output off".
std::string_view rule_why(ConfirmRule r) noexcept;

// Deny list and confirm rules for `r`. `device` matters to the rules judged by effect:
// stop_streaming and blind_monitoring (a polled device is not affected), thermal_shutdown
// (T_U against the internal temperature). The DENIED reason says what the command would do
// with the values the unit has now. The rate limit is RateLimiter's, not this function's.
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
