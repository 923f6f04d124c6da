#include "pmu/command/config_holds.hpp"

#include <algorithm>
#include <cstdio>

namespace pmu::service {

std::string ConfigHolds::held_by(const Holder& h, const CommandRequest& r, Time now) {
  const double left = std::chrono::duration<double>(h.until - now).count();
  char buf[48];
  std::snprintf(buf, sizeof buf, " for another %.1f s", left);
  return "configuration of " + printable(r.bus) + "/" + std::to_string(r.address) + " held by an apply from " +
         printable(h.sender) + " (request id " + printable(h.request_id) + ")" + buf;
}

std::optional<std::string> ConfigHolds::admit(const CommandRequest& r, Time now) {
  const auto key = std::make_pair(r.bus, r.address);
  auto it = holds_.find(key);
  if (it != holds_.end() && it->second.until <= now) {  // its apply's commands have all expired
    holds_.erase(it);
    it = holds_.end();
  }
  const bool held = it != holds_.end();
  if (!r.hold) {
    if (held && changes_configuration(r.kind())) return held_by(it->second, r, now);
    return std::nullopt;
  }
  if (held && !same(it->second, r)) return held_by(it->second, r, now);
  if (r.hold->release) {
    // Every device this apply holds: one that moved the unit holds its old address too.
    for (auto h = holds_.begin(); h != holds_.end();) h = same(h->second, r) ? holds_.erase(h) : std::next(h);
    return std::nullopt;
  }
  if (held)
    it->second.until = std::max(it->second.until, r.expires);
  else
    holds_.emplace(key, Holder{r.sender, r.hold->apply, r.request_id, r.expires});
  return std::nullopt;
}

std::size_t ConfigHolds::held(Time now) const {
  return static_cast<std::size_t>(
      std::count_if(holds_.begin(), holds_.end(), [now](const auto& h) { return h.second.until > now; }));
}

}  // namespace pmu::service
