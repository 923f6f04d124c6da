#pragma once
// A hot-standby instance's settings (the config's `redundancy:` section, interface.md 4.7) as
// plain values, the periods derived from them, and the one check of what can run.

#include <chrono>
#include <cstdint>
#include <string>

namespace pmu::redundancy {

using Duration = std::chrono::milliseconds;

struct Settings {
  std::uint8_t priority = 1;  // 1..255; the higher wins when neither instance owns the bus
  std::string name;           // this instance's name, pmu/role's key; empty: the host's name
  std::string peer;           // the peer instance's name: whose pmu/role samples are the peer's
  Duration heartbeat_period{100};
  Duration lease{300};
  Duration can_silence{150};
};

inline constexpr std::uint8_t kMinPriority = 1;
inline constexpr Duration kMinHeartbeatPeriod{10};
inline constexpr Duration kMaxHeartbeatPeriod{1000};
inline constexpr Duration kMaxLease{10000};
inline constexpr Duration kMinCanSilence{30};
inline constexpr Duration kMaxCanSilence{10000};

// The bus owner's CAN heartbeat period: three within `can_silence`, so one lost frame is no
// failover.
Duration can_heartbeat_period(const Settings& s) noexcept;
// How long a claimant sends its claim before it sends a PMU frame: two CAN heartbeat periods, so
// a claim made at the same moment on the other host is heard first.
Duration claim_window(const Settings& s) noexcept;
// A pause of the holder's calls longer than this means the process was frozen or starved: the
// peer could have started to claim by then (lease less one heartbeat after the last beat sent).
Duration freeze_gap(const Settings& s) noexcept;
// The longest a holder may leave between two calls of RoleMachine::poll.
Duration poll_period(const Settings& s) noexcept;

// Empty when the settings can run; otherwise what is wrong, naming the setting
// ("lease 150 ms is under 2 x heartbeat_period (200 ms)").
std::string settings_problem(const Settings& s);

}  // namespace pmu::redundancy
