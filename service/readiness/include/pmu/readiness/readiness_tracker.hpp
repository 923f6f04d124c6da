#pragma once
// ReadinessTracker: a StateSink in front of another (the DDS publisher) that passes every
// event on and keeps, from health, identity, configuration and alarm events, the vehicle's
// readiness (readiness_rules.hpp). It sends a ReadinessReport on to the next sink when the
// report changes and at least once a second while events come (each device's health comes
// once a second), so a reader that missed one sees the next.
// A PMU with a `baseline:` is compared with it after every reading of its configuration
// (start, a reconnect's re-read, a verified set) and identity; each change of what differs
// (which settings, the serial) is logged once, and so is the match that follows.
// Each PMU's telemetry is noted by packet, so a packet its alarms read that is not monitored,
// not received or stale is a reason (input_missing): what it streams follows its PS as read,
// so a verified set of packets_streamed changes the report at once.
//
// Lifetime: `next` and `clock` must outlive the tracker, which keeps references to both
// (main.cpp makes the publisher and the clock first and the bus workers, which write through
// the tracker, are destroyed before it).
// Threads: every StateSink member from any bus worker thread at once; `mutex_` serialises
// the view and the reports, which are handed on under it so they reach `next` in order.

#include <chrono>
#include <map>
#include <mutex>
#include <optional>
#include <tuple>

#include "pmu/config/config.hpp"
#include "pmu/readiness/readiness_rules.hpp"
#include "pmu/session/state_sink.hpp"
#include "pmu/transport/clock.hpp"

namespace pmu::service {

class ReadinessTracker final : public ForwardingSink {
 public:
  // `buses`: the config's, for each PMU's min_firmware, baseline, mode, packets, period and
  // alarms (a discovered PMU takes its bus's discover: settings, and has no baseline).
  // `stale_periods`: the config's; a packet older than this many of its periods is stale, as
  // a device is for its health.
  ReadinessTracker(const std::vector<BusConfig>& buses, double stale_periods, StateSink& next,
                   const transport::Clock& clock);

  void on_telemetry(const DeviceKey& key, const codec::PmuMessage& message,
                    std::chrono::system_clock::time_point received) override;
  void on_config(const DeviceKey& key, const ConfigState& config) override;
  void on_info(const DeviceKey& key, const InfoState& info) override;
  void on_health(const DeviceKey& key, const HealthReport& health) override;
  void on_gone(const DeviceKey& key) override;
  void on_alarm(const AlarmReport& alarm) override;
  // The rest pass on unchanged (ForwardingSink): reports come from this tracker, and one
  // handed to it goes on as it is.

  // The latest report (for tests and the start-up log).
  ReadinessReport current() const;

  static constexpr std::chrono::seconds kRepeat{1};

 private:
  using Key = std::tuple<std::string, DeviceKind, std::uint16_t>;
  DeviceView& view_of(const DeviceKey& key);
  void update(bool force);  // with mutex_ held
  // What of a PMU's baseline differs, as last logged; settings: none before the first
  // comparison. log_drift() logs a change of either (mutex_ held).
  struct Drift {
    std::optional<std::vector<baseline::Setting>> settings;
    bool serial = false;
  };
  void log_drift(const DeviceKey& key, const DeviceView& view);
  // What the service gets of a PMU's packets, and how old one may be, from its config and the
  // PS and PP last read (mutex_ held).
  void refresh_inputs(const Key& key, DeviceView& view);

  // A PMU's config: how the service gets its packets.
  struct Expected {
    bool streaming = true;
    std::uint8_t groups = 0;
    std::chrono::milliseconds period{1000};
  };

  std::map<std::string, BusConfig> buses_;  // by bus name
  double stale_periods_;
  std::map<Key, Expected> expected_;  // PMUs
  const transport::Clock& clock_;
  mutable std::mutex mutex_;
  ReadinessInput input_;
  std::map<std::tuple<std::string, alarms::DeviceKind, std::uint16_t, alarms::Code>, std::size_t> alarm_index_;
  ReadinessReport report_;
  std::optional<std::chrono::steady_clock::time_point> last_sent_;
  std::map<Key, Drift> drift_logged_;  // PMUs with a baseline
};

}  // namespace pmu::service
