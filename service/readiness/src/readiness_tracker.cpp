#include "pmu/readiness/readiness_tracker.hpp"

#include <spdlog/spdlog.h>

#include "pmu/alarms/settings.hpp"

namespace pmu::service {
namespace {

bool same(const std::vector<ReadinessReason>& a, const std::vector<ReadinessReason>& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i)
    if (a[i].code != b[i].code || a[i].severity != b[i].severity || a[i].bus != b[i].bus ||
        a[i].source != b[i].source || a[i].device != b[i].device || a[i].message != b[i].message ||
        a[i].description != b[i].description)
      return false;
  return true;
}

}  // namespace

ReadinessTracker::ReadinessTracker(const std::vector<BusConfig>& buses, double stale_periods, StateSink& next,
                                   const transport::Clock& clock)
    : ForwardingSink(next), stale_periods_(stale_periods), clock_(clock) {
  for (const auto& b : buses) buses_[b.name] = b;
  report_.since = clock_.system_now();
}

DeviceView& ReadinessTracker::view_of(const DeviceKey& key) {
  auto [it, added] = input_.devices.try_emplace(Key{key.bus, key.kind, key.address});
  if (added && key.kind == DeviceKind::Pmu) {
    const DeviceConfig* config = nullptr;
    if (auto b = buses_.find(key.bus); b != buses_.end()) {
      config = &b->second.discovered_defaults;
      it->second.min_firmware = b->second.discovered_defaults.min_firmware;
      for (const auto& d : b->second.devices)
        if (d.address == key.address) {
          config = &d;
          it->second.min_firmware = d.min_firmware;
          it->second.baseline = d.baseline;
          it->second.baseline_file = d.baseline_path;
        }
    }
    // A PMU the config does not name (no such bus): the table's alarms, and every packet
    // taken as not monitored until its PS is read; the side on which readiness says less.
    Expected e{true, 0, std::chrono::milliseconds(1000)};
    alarms::DeviceSettings alarm_settings;
    if (config) {
      e = {config->mode == TelemetryMode::Streaming, config->groups, config->period};
      alarm_settings = config->alarms;
    }
    it->second.packets_needed = alarms::packets_read(alarm_settings);
    expected_[Key{key.bus, key.kind, key.address}] = e;
    refresh_inputs(Key{key.bus, key.kind, key.address}, it->second);
  }
  return it->second;
}

void ReadinessTracker::refresh_inputs(const Key& key, DeviceView& v) {
  const auto e = expected_.find(key);
  if (e == expected_.end()) return;
  v.streaming = e->second.streaming;
  const auto& ps = v.settings.raw[static_cast<std::size_t>(codec::Parameter::PacketsStreamed)];
  const auto& pp = v.settings.raw[static_cast<std::size_t>(codec::Parameter::PacketPeriod)];
  // Streaming: what the PMU's PS selects (v1.9 table 13; bits 5-7 mean nothing), every PP.
  v.packets_monitored = v.streaming && ps ? static_cast<std::uint8_t>(*ps & codec::group_bit::All) : e->second.groups;
  auto period = e->second.period;
  if (v.streaming && pp && *pp > 0) period = codec::duration_of(codec::Parameter::PacketPeriod, *pp);
  v.max_age = std::chrono::duration_cast<std::chrono::steady_clock::duration>(
      std::chrono::duration<double, std::milli>(period) * stale_periods_);
}

void ReadinessTracker::on_telemetry(const DeviceKey& key, const codec::PmuMessage& message,
                                    std::chrono::system_clock::time_point received) {
  next().on_telemetry(key, message, received);
  const auto index = static_cast<std::size_t>(message.packet);
  if (key.kind != DeviceKind::Pmu || index >= DeviceView{}.received.size()) return;
  std::lock_guard<std::mutex> lock(mutex_);
  auto& v = view_of(key);
  const auto now = clock_.steady_now();
  auto& at = v.received[index];
  // A packet that was missing or stale comes back: the report changes now, not at the next
  // health report. Otherwise nothing changes: the frame rate need not drive the rules.
  const bool was_missing = !at || now - *at > v.max_age;
  at = now;
  if (was_missing) update(false);
}

void ReadinessTracker::on_config(const DeviceKey& key, const ConfigState& config) {
  next().on_config(key, config);
  std::lock_guard<std::mutex> lock(mutex_);
  auto& v = view_of(key);
  v.settings = settings_of(config);
  refresh_inputs(Key{key.bus, key.kind, key.address}, v);
  log_drift(key, v);
  update(false);
}

void ReadinessTracker::log_drift(const DeviceKey& key, const DeviceView& v) {
  if (!v.baseline) return;
  Drift& logged = drift_logged_[Key{key.bus, key.kind, key.address}];
  const bool serial = serial_differs(v);
  if (serial != logged.serial) {
    if (serial)
      spdlog::warn("{}/{}: PMU serial {} is not the serial {} of baseline {}: another unit answers at this address",
                   key.bus, key.address, *v.serial, *v.baseline->header.serial, v.baseline_file);
    else
      spdlog::info("{}/{}: PMU serial {} matches baseline {} again", key.bus, key.address,
                   v.serial ? std::to_string(*v.serial) : std::string("?"), v.baseline_file);
    logged.serial = serial;
  }
  bool compared = false;  // a setting of the baseline has been read: until then, no verdict
  for (std::size_t i = 0; i < baseline::kSettingCount; ++i)
    compared = compared || (v.settings.raw[i] && v.baseline->settings.raw[i]);
  if (!compared) return;
  const auto diffs = drift(v);
  std::vector<baseline::Setting> differing;
  for (const auto& d : diffs) differing.push_back(d.setting);
  if (logged.settings == differing) return;
  if (!differing.empty()) {
    std::string items;
    for (const auto& d : diffs)
      items += (items.empty() ? "" : "; ") + std::string(baseline::setting_name(d.setting)) + " device " +
               baseline::value_text(d.setting, *d.device) + ", baseline " + baseline::value_text(d.setting, d.file);
    spdlog::warn("{}/{}: configuration differs from baseline {}: {}", key.bus, key.address, v.baseline_file, items);
  } else {
    spdlog::info("{}/{}: configuration matches baseline {}{}", key.bus, key.address, v.baseline_file,
                 logged.settings ? " again" : "");
  }
  logged.settings = std::move(differing);
}

void ReadinessTracker::on_info(const DeviceKey& key, const InfoState& info) {
  next().on_info(key, info);
  std::lock_guard<std::mutex> lock(mutex_);
  auto& v = view_of(key);
  if (info.firmware_known) v.firmware = info.firmware.version();
  v.serial = info.serial_number;
  log_drift(key, v);
  update(false);
}

void ReadinessTracker::on_health(const DeviceKey& key, const HealthReport& health) {
  next().on_health(key, health);
  std::lock_guard<std::mutex> lock(mutex_);
  auto& v = view_of(key);
  v.state = health.state;
  v.bus_state = health.bus_state;
  update(false);
}

void ReadinessTracker::on_gone(const DeviceKey& key) {
  next().on_gone(key);
  std::lock_guard<std::mutex> lock(mutex_);
  // A unit that moved to another address: its new key reports on its own.
  input_.devices.erase(Key{key.bus, key.kind, key.address});
  drift_logged_.erase(Key{key.bus, key.kind, key.address});
  expected_.erase(Key{key.bus, key.kind, key.address});
  update(true);
}

void ReadinessTracker::on_alarm(const AlarmReport& alarm) {
  next().on_alarm(alarm);
  std::lock_guard<std::mutex> lock(mutex_);
  const auto id = std::make_tuple(alarm.bus, alarm.source, alarm.device, alarm.code);
  if (auto it = alarm_index_.find(id); it != alarm_index_.end()) {
    input_.alarms[it->second] = alarm;
  } else {
    alarm_index_.emplace(id, input_.alarms.size());
    input_.alarms.push_back(alarm);
  }
  update(false);
}

ReadinessReport ReadinessTracker::current() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return report_;
}

void ReadinessTracker::update(bool force) {
  input_.now = clock_.steady_now();
  auto reasons = readiness_reasons(input_);
  bool ready = true;
  for (const auto& r : reasons) ready = ready && r.severity != alarms::Severity::Critical;
  const auto now = clock_.steady_now();
  const bool changed = ready != report_.ready || !same(reasons, report_.reasons);
  if (!force && !changed && last_sent_ && now - *last_sent_ < kRepeat) return;
  if (ready != report_.ready) report_.since = clock_.system_now();
  report_.ready = ready;
  report_.reasons = std::move(reasons);
  last_sent_ = now;
  next().on_readiness(report_);
}

}  // namespace pmu::service
