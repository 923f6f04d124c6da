#include "pmu/readiness/readiness_tracker.hpp"

namespace pmu::service {
namespace {

bool same(const std::vector<ReadinessReason>& a, const std::vector<ReadinessReason>& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i)
    if (a[i].code != b[i].code || a[i].severity != b[i].severity || a[i].bus != b[i].bus ||
        a[i].source != b[i].source || a[i].device != b[i].device || a[i].message != b[i].message)
      return false;
  return true;
}

}  // namespace

ReadinessTracker::ReadinessTracker(const std::vector<BusConfig>& buses, StateSink& next,
                                   const transport::Clock& clock)
    : next_(next), clock_(clock) {
  for (const auto& b : buses) buses_[b.name] = b;
  report_.since = clock_.system_now();
}

DeviceView& ReadinessTracker::view_of(const DeviceKey& key) {
  auto [it, added] = input_.devices.try_emplace(Key{key.bus, key.kind, key.address});
  if (added && key.kind == DeviceKind::Pmu) {
    if (auto b = buses_.find(key.bus); b != buses_.end()) {
      it->second.min_firmware = b->second.discovered_defaults.min_firmware;
      for (const auto& d : b->second.devices)
        if (d.address == key.address) it->second.min_firmware = d.min_firmware;
    }
  }
  return it->second;
}

void ReadinessTracker::on_info(const DeviceKey& key, const InfoState& info) {
  next_.on_info(key, info);
  std::lock_guard<std::mutex> lock(mutex_);
  if (info.firmware_known) view_of(key).firmware = info.firmware.version();
  update(false);
}

void ReadinessTracker::on_health(const DeviceKey& key, const HealthReport& health) {
  next_.on_health(key, health);
  std::lock_guard<std::mutex> lock(mutex_);
  auto& v = view_of(key);
  v.state = health.state;
  v.bus_state = health.bus_state;
  update(false);
}

void ReadinessTracker::on_gone(const DeviceKey& key) {
  next_.on_gone(key);
  std::lock_guard<std::mutex> lock(mutex_);
  // A unit that moved to another address: its new key reports on its own.
  input_.devices.erase(Key{key.bus, key.kind, key.address});
  update(true);
}

void ReadinessTracker::on_alarm(const AlarmReport& alarm) {
  next_.on_alarm(alarm);
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
  next_.on_readiness(report_);
}

}  // namespace pmu::service
