#include "pmu/alarms/alarm_set.hpp"

#include <algorithm>

namespace pmu::alarms {

codec::Result<AlarmSet, std::string> AlarmSet::make(DeviceKind kind, const DeviceSettings& settings) {
  auto configs = resolve(kind, settings);
  if (!configs) return codec::Unexpected{configs.error()};
  std::vector<Alarm> alarms;
  alarms.reserve(configs->size());
  for (const auto& c : *configs)
    if (c.enabled) alarms.emplace_back(c);
  return AlarmSet(kind, std::move(alarms));
}

Alarm* AlarmSet::find_mutable(Code code) noexcept {
  const auto it = std::find_if(alarms_.begin(), alarms_.end(), [code](const Alarm& a) { return a.code() == code; });
  return it == alarms_.end() ? nullptr : &*it;
}

const Alarm* AlarmSet::find(Code code) const noexcept {
  const auto it = std::find_if(alarms_.begin(), alarms_.end(), [code](const Alarm& a) { return a.code() == code; });
  return it == alarms_.end() ? nullptr : &*it;
}

bool AlarmSet::observe(Code code, double value, Time now) noexcept {
  Alarm* a = find_mutable(code);
  return a != nullptr && a->observe(value, now);
}

bool AlarmSet::observe_flag(Code code, bool set, Time now) noexcept {
  Alarm* a = find_mutable(code);
  return a != nullptr && a->observe_flag(set, now);
}

std::vector<Code> AlarmSet::tick(Time now) {
  std::vector<Code> changed;
  for (auto& a : alarms_)
    if (a.tick(now)) changed.push_back(a.code());
  return changed;
}

AckResult AlarmSet::acknowledge(Code code, Time now) noexcept {
  Alarm* a = find_mutable(code);
  return a == nullptr ? AckResult::NotFound : a->acknowledge(now);
}

std::vector<const Alarm*> AlarmSet::not_normal() const {
  std::vector<const Alarm*> out;
  for (const auto& a : alarms_)
    if (a.state() != AlarmState::Normal) out.push_back(&a);
  return out;
}

}  // namespace pmu::alarms
