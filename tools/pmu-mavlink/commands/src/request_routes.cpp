#include "pmu/mavlink_commands/request_routes.hpp"

namespace pmu::mavlink_commands {

RequestRoutes::RequestRoutes(std::string prefix, std::uint64_t first, std::chrono::milliseconds resend_after)
    : prefix_(std::move(prefix)), next_(first), resend_after_(resend_after) {}

std::string RequestRoutes::open(Route route, Time expires, Time forget_at, Time now) {
  std::string id = prefix_ + std::to_string(next_++);
  routes_[id] = Entry{route, expires, forget_at, now + resend_after_, false};
  ++counters_.opened;
  return id;
}

std::optional<Route> RequestRoutes::on_reply(std::string_view request_id, bool final) {
  const auto it = routes_.find(request_id);
  if (it == routes_.end()) {
    if (request_id.substr(0, prefix_.size()) == prefix_)
      ++counters_.replies_unknown;
    else
      ++counters_.replies_others;
    return std::nullopt;
  }
  ++counters_.replies_routed;
  const Route route = it->second.route;
  it->second.heard = true;
  if (final) routes_.erase(it);
  return route;
}

std::vector<std::string> RequestRoutes::due(Time now) {
  std::vector<std::string> ids;
  for (auto it = routes_.begin(); it != routes_.end();) {
    Entry& e = it->second;
    if (now >= e.forget_at) {
      it = routes_.erase(it);
      continue;
    }
    if (!e.heard && now >= e.next_write && now < e.expires) {
      ids.push_back(it->first);
      e.next_write = now + resend_after_;
      ++counters_.resends;
    }
    ++it;
  }
  return ids;
}

}  // namespace pmu::mavlink_commands
