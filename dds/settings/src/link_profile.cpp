#include "pmu/dds_settings/link_profile.hpp"

#include <cstdio>

namespace pmu::dds {
namespace {

// "0.7 s", "20 s", "1.05 s": milliseconds as seconds without trailing zeros.
std::string seconds(std::chrono::milliseconds ms) {
  char text[32];
  std::snprintf(text, sizeof text, "%.3f", static_cast<double>(ms.count()) / 1000.0);
  std::string s = text;
  while (s.back() == '0') s.pop_back();
  if (s.back() == '.') s.pop_back();
  return s + " s";
}

std::string origin(const std::string& what, const std::string& where) {
  return where.empty() ? what : what + ", " + where;
}

}  // namespace

std::optional<LinkProfile> parse_link_profile(std::string_view text) {
  if (text == "radio") return LinkProfile::Radio;
  if (text == "none") return LinkProfile::None;
  return std::nullopt;
}

const char* to_string(LinkProfile profile) noexcept {
  switch (profile) {
    case LinkProfile::None: return "none";
    case LinkProfile::Radio: return "radio";
  }
  return "none";
}

LinkPlan link_plan(const LinkSettings& s) {
  LinkPlan p;
  p.profile = s.profile;
  const std::string profile_from = origin(std::string("profile ") + to_string(s.profile), s.profile_where);
  if (s.profile == LinkProfile::Radio) {
    p.round_trip = {kRadioRoundTrip, profile_from};
    p.announcement_period = {kRadioAnnouncementPeriod, profile_from};
    p.lease = {kRadioLease, profile_from};
    p.initial_announcements = kRadioInitialAnnouncements;
    p.low_rate_watch = true;
    p.agent_workers = kRadioAgentWorkers;
    if (!s.low_rate_period_given) p.low_rate_period = {kRadioLowRatePeriod, profile_from};
  }
  if (s.round_trip) p.round_trip = {*s.round_trip, origin("round_trip", s.round_trip_where)};
  if (p.round_trip.set()) p.heartbeat_floor = {p.round_trip.value * 3 / 2, "1.5 round trips"};
  return p;
}

std::vector<std::string> LinkPlan::explain() const {
  std::vector<std::string> out;
  if (profile == LinkProfile::None && !round_trip.set()) {
    out.push_back("link: none (Fast DDS's discovery periods, qos.xml's heartbeat periods)");
    return out;
  }
  out.push_back(std::string("link: profile ") + to_string(profile));
  if (round_trip.set()) {
    out.push_back("link: round trip " + seconds(round_trip.value) + " (" + round_trip.from + ")");
    out.push_back("link: reliable writers heartbeat every " + seconds(heartbeat_floor.value) + " at most (" +
                  heartbeat_floor.from + ")");
  }
  if (announcement_period.set())
    out.push_back("link: participant announced every " + seconds(announcement_period.value) + " (" +
                  announcement_period.from + ")");
  if (lease.set()) out.push_back("link: participant lease " + seconds(lease.value) + " (" + lease.from + ")");
  if (initial_announcements > 0)
    out.push_back("link: " + std::to_string(initial_announcements) + " initial announcement(s) (profile " +
                  to_string(profile) + ")");
  if (low_rate_period.set())
    out.push_back("link: the service writes the low-rate topics every " + seconds(low_rate_period.value) +
                  " unless its config sets low_rate_period (" + low_rate_period.from + ")");
  if (low_rate_watch)
    out.push_back(std::string("link: pmuctl watch reads the low-rate topics pmu/low_rate/* (profile ") +
                  to_string(profile) + ")");
  if (agent_workers > 0)
    out.push_back("link: pmuctl agent runs " + std::to_string(agent_workers) + " worker(s) unless --workers (profile " +
                  to_string(profile) + ")");
  return out;
}

}  // namespace pmu::dds
