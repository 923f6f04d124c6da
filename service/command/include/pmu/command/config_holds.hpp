#pragma once
// Who holds each device's configuration (interface.md 2.8, docs/safety.md H11). An apply
// (`pmuctl config apply`) takes the hold with its first command and gives it back with its
// last, so no other writer's change lands between the apply's reading of the device, its
// changes and their undoing: two applies at once would leave the device matching neither file.
//
// A hold lasts until the expiry of the latest command its apply sent (expires_at, held to
// policy.max_command_lifetime, interface.md 2.3): a caller that dies leaves no hold behind for
// longer than that. While it lasts the kinds that change the configuration (SET_PARAMETER,
// SET_OUTPUTS, ENABLE_OUTPUTS, DISABLE_OUTPUTS, SET_GENERATION, RESET) are DENIED unless they
// are the holder's, and so is another apply's attempt to take it. A plain GET and every
// other kind (ENGINE_STOP above all) are never refused by a hold.
//
// Pure: `now` is given on every call; no clock, no I/O. Not thread-safe: the command service
// calls it under its lock. A hold is kept per (bus, address) and stays on the address it was
// taken at: an apply that moves the unit (can_address, applied last) takes a hold at the new
// address with its next command.

#include <chrono>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <utility>

#include "pmu/command/command.hpp"

namespace pmu::service {

class ConfigHolds {
 public:
  using Time = std::chrono::steady_clock::time_point;

  // Whether `r` may run on its device at `now`: nullopt when it may (a command carrying a hold
  // then holds the device until its own expiry, or at least as long as before; one that
  // releases ends every hold of its apply), else why it is DENIED, naming the holder.
  std::optional<std::string> admit(const CommandRequest& r, Time now);

  // Devices held at `now`.
  std::size_t held(Time now) const;

 private:
  struct Holder {
    std::string sender;      // the DDS writer of the apply's commands
    std::string apply;       // APPLY of its request ids APPLY#N
    std::string request_id;  // the command that took the hold
    Time until;
  };
  bool same(const Holder& h, const CommandRequest& r) const { return h.sender == r.sender && h.apply == r.hold->apply; }
  static std::string held_by(const Holder& h, const CommandRequest& r, Time now);

  std::map<std::pair<std::string, std::uint16_t>, Holder> holds_;  // by (bus, address)
};

}  // namespace pmu::service
