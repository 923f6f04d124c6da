#include "pmuctl/agent/target_memory.hpp"

#include "pmu/command/command.hpp"

namespace pmu::tools {

TargetMemory::Key TargetMemory::key_of(const TargetQuery& query) {
  return {query.vehicle, query.bus, query.address ? int{*query.address} : -1};
}

std::optional<Target> TargetMemory::recall(const TargetQuery& query, Clock::time_point now) const {
  const auto it = found_.find(key_of(query));
  if (it == found_.end() || now - it->second.second >= kKeptFor || now < it->second.second) return std::nullopt;
  return it->second.first;
}

void TargetMemory::remember(const TargetQuery& query, const Target& target, Clock::time_point now) {
  found_[key_of(query)] = {target, now};
}

void TargetMemory::forget(const TargetQuery& query) { found_.erase(key_of(query)); }

bool says_target_gone(const std::string& reason, const Target& target) {
  return reason == pmu::service::device_not_seen_reason(target.address, target.bus);
}

}  // namespace pmu::tools
