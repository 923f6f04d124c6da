#include "pmu/redundancy/settings.hpp"

#include <algorithm>

namespace pmu::redundancy {
namespace {

std::string ms_text(Duration d) { return std::to_string(d.count()) + " ms"; }

}  // namespace

Duration can_heartbeat_period(const Settings& s) noexcept { return s.can_silence / 3; }

Duration claim_window(const Settings& s) noexcept { return 2 * can_heartbeat_period(s); }

Duration freeze_gap(const Settings& s) noexcept { return s.lease - s.heartbeat_period; }

Duration poll_period(const Settings& s) noexcept {
  return std::max(Duration{1}, std::min(s.heartbeat_period, can_heartbeat_period(s)) / 4);
}

std::string settings_problem(const Settings& s) {
  if (s.priority < kMinPriority) return "priority 0 is out of range 1..255";
  if (s.peer.empty()) return "peer must name the other instance";
  if (s.heartbeat_period < kMinHeartbeatPeriod || s.heartbeat_period > kMaxHeartbeatPeriod)
    return "heartbeat_period " + ms_text(s.heartbeat_period) + " is out of range " + ms_text(kMinHeartbeatPeriod) +
           ".." + ms_text(kMaxHeartbeatPeriod);
  // One late heartbeat must not be a failover.
  if (s.lease < 2 * s.heartbeat_period)
    return "lease " + ms_text(s.lease) + " is under 2 x heartbeat_period (" + ms_text(2 * s.heartbeat_period) + ")";
  if (s.lease > kMaxLease) return "lease " + ms_text(s.lease) + " is over " + ms_text(kMaxLease);
  if (s.can_silence < kMinCanSilence || s.can_silence > kMaxCanSilence)
    return "can_silence " + ms_text(s.can_silence) + " is out of range " + ms_text(kMinCanSilence) + ".." +
           ms_text(kMaxCanSilence);
  return {};
}

}  // namespace pmu::redundancy
