#include "pmu/session/health_tracker.hpp"

#include <cstdio>

namespace pmu::service {
namespace {

constexpr std::chrono::milliseconds kPublishInterval{1000};

}  // namespace

const char* to_string(HealthState s) noexcept {
  switch (s) {
    case HealthState::Unknown: return "UNKNOWN";
    case HealthState::Online: return "ONLINE";
    case HealthState::Stale: return "STALE";
    case HealthState::Offline: return "OFFLINE";
  }
  return "UNKNOWN";
}

std::string last_frame_text(double age_s) {
  if (!(age_s >= 0)) return "no frame yet";
  char buf[48];
  std::snprintf(buf, sizeof buf, "last frame %.1f s ago", age_s);
  return buf;
}

const char* to_string(DeviceKind k) noexcept {
  switch (k) {
    case DeviceKind::Pmu: return "pmu";
    case DeviceKind::Battery: return "battery";
    case DeviceKind::Mppt: return "mppt";
  }
  return "pmu";
}

HealthTracker::HealthTracker(std::chrono::steady_clock::time_point created, const Timeouts& timeouts) noexcept
    : stale_periods_(timeouts.stale_periods),
      offline_periods_(timeouts.offline_periods),
      created_(created),
      next_publish_(created) {}

void HealthTracker::on_frame(std::chrono::steady_clock::time_point now) noexcept {
  last_rx_ = now;
  ++report_.frames_received;
}

bool HealthTracker::on_bus_state(transport::BusState state) noexcept {
  if (report_.bus_state == state) return false;
  report_.bus_state = state;
  return true;
}

void HealthTracker::on_bus_counters(const transport::BusCounters& c) noexcept {
  report_.bus_errors = c.error_frames;
  report_.rx_dropped = c.rx_drops;
}

HealthTracker::Update HealthTracker::update(std::chrono::steady_clock::time_point now, std::chrono::milliseconds period,
                                            bool force) noexcept {
  using Seconds = std::chrono::duration<double>;
  HealthState state = HealthState::Unknown;
  const double p = Seconds(period).count();
  if (last_rx_) {
    const double age = Seconds(now - *last_rx_).count();
    report_.last_frame_age = age;
    state = age <= stale_periods_ * p     ? HealthState::Online
            : age <= offline_periods_ * p ? HealthState::Stale
                                          : HealthState::Offline;
  } else {
    report_.last_frame_age = -1;
    if (Seconds(now - created_).count() > offline_periods_ * p) state = HealthState::Offline;
  }
  Update u;
  u.changed = state != report_.state;
  report_.state = state;
  u.publish = u.changed || force || now >= next_publish_;
  if (u.publish) next_publish_ = now + kPublishInterval;
  return u;
}

}  // namespace pmu::service
