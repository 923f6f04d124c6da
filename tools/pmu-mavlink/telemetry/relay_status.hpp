#pragma once
// RELAY_STATUS (376) from the PMUs' switched outputs and generation (interface.md
// "pmu-mavlink"). Pure: views in, a message out.
//
// Bit 5n + i is PMU n's (0-based, the bridge's order, as for BATTERY_STATUS ids)
// MAV_CMD_DO_SET_RELAY instance i: 0 avionics_servo, 1 payload, 2 charger_a, 3 charger_b,
// 4 generation. The message has no instance field and 16 bits, so it holds PMUs 0..2
// (bits 0..14); bit 15 and later PMUs are never present. An output is present only while
// its PMU is ONLINE and its pmu/status has been read: one whose state is not known is left
// out, never reported off (docs/safety.md H7).
#include <cstdint>
#include <utility>
#include <vector>

#include "pmu/mavlink/messages.hpp"
#include "telemetry/device_views.hpp"

namespace pmu::mavlink_bridge {

// DO_SET_RELAY's instances a PMU has (0..3 the outputs, 4 generation), and how many PMUs
// RELAY_STATUS's 16 bits hold.
inline constexpr unsigned kRelaysPerPmu = 5;
inline constexpr unsigned kRelayStatusPmus = 3;

// Bits 0..4 of one PMU: its outputs' and generation's state, all present or none.
struct PmuRelays {
  std::uint16_t on = 0;
  std::uint16_t present = 0;
};
PmuRelays pmu_relays(const PmuView& pmu) noexcept;

// The PMUs by their 0-based number: each PMU's bits at 5 x its number; a number of 3 or more
// adds nothing. `time_boot_ms`: the bridge's milliseconds since it started.
pmu::mavlink::RelayStatus relay_status(const std::vector<std::pair<unsigned, const PmuView*>>& pmus,
                                       std::uint32_t time_boot_ms);

}  // namespace pmu::mavlink_bridge
