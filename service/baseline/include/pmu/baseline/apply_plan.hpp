#pragma once
// How a configuration file is applied to a device (interface.md 4.6): only what differs, one
// command per setting, in an order that is safe, each judged by the confirm rules before
// anything is sent. Undoing runs the applied changes backwards with their old values, each
// only where the device still holds what the apply set (undo_of).
//
// The order, by what a change does to a flying aircraft:
//   1. what acts only later or on faults: temperature_offset, upper_temperature_limit,
//      cranking_time, power_up_state
//   2. the set-points: battery_voltage, servo_voltage, avionics_voltage, payload_voltage,
//      so an output switched on in step 3 comes up at the file's voltage
//   3. generation_enabled, then outputs
//   4. what the service hears: packet_period, packets_streamed
//   5. can_address, last: the unit leaves the address it is known by, so everything else
//      is set and verified at the old one first.

#include <optional>
#include <vector>

#include "pmu/baseline/config_diff.hpp"
#include "pmu/command/command.hpp"
#include "pmu/command/policy.hpp"

namespace pmu::baseline {

struct Change {
  Setting setting;
  std::uint32_t from = 0;  // the device's value before: what an undo sets
  std::uint32_t to = 0;
  int line = 0;                                 // the file's line
  std::optional<service::ConfirmRule> confirm;  // the rule that makes it need --confirm
};

// The changes for `diffs`, in the order above. Every difference must have its device value
// (the caller refuses to apply to a device not fully read: it could not be undone).
// `device`: what the caller knows of the PMU for the rules judged by effect; by default
// nothing, so each such rule asks for confirm whenever the service might (pmuctl sends a
// change confirmed only where the plan says it needs it).
std::vector<Change> apply_plan(const std::vector<Difference>& diffs, const service::DeviceUse& device = {});

// The command that sets `setting` to `raw`.
service::CommandAction action_for(Setting setting, std::uint32_t raw);

// What undoing one applied change does, given the value the device holds when the undo
// comes (docs/safety.md H11): a restore puts back only what the apply itself changed. The
// device still holds `c.to`: set it back to `c.from`. It holds anything else: another writer
// (a tool on the bus, the unit's panel, a client of a service that knows no hold) changed it
// since, and that value is theirs: left as it is, and said. Not read: left as it is too,
// since an undo that cannot be checked could overwrite someone else's value.
enum class Undo { Restore, ChangedByAnother, NotRead };
Undo undo_of(const Change& c, std::optional<std::uint32_t> device_now) noexcept;

// Where `s` comes in the order above (0 first).
int apply_rank(Setting s) noexcept;

}  // namespace pmu::baseline
