#include "pmuctl/view/role_view.hpp"

#include <algorithm>
#include <cctype>
#include <cstdio>

#include "pmuctl/view/table_text.hpp"

namespace pmu::tools {
namespace {

std::string upper(std::string_view text) {
  std::string out(text);
  std::transform(out.begin(), out.end(), out.begin(),
                 [](unsigned char c) { return static_cast<char>(std::toupper(c)); });
  return out;
}

double seconds(std::chrono::steady_clock::duration d) { return std::chrono::duration<double>(d).count(); }

const char* bus_text(redundancy::BusState b) {
  switch (b) {
    case redundancy::BusState::Ok: return "ok";
    case redundancy::BusState::BusOff: return "bus_off";
    case redundancy::BusState::Down: return "down";
  }
  return "unknown";
}

std::string name_of(const SeenInstance& s) { return s.report.name.empty() ? std::string("(unnamed)") : s.report.name; }

}  // namespace

bool role_silent(const SeenInstance& s) noexcept { return s.age > kRoleSilentAfter; }

bool peers_heard(const std::vector<SeenInstance>& instances) {
  for (const auto& s : instances) {
    if (s.report.peer.empty()) continue;
    bool heard = false;
    for (const auto& t : instances) heard = heard || (t.vehicle == s.vehicle && t.report.name == s.report.peer);
    if (!heard) return false;
  }
  return true;
}

std::string role_shown(const SeenInstance& s) {
  return role_silent(s) ? std::string("SILENT") : upper(redundancy::role_name(s.report.beat.role));
}

std::vector<std::string> pair_problems(const std::vector<SeenInstance>& instances) {
  std::vector<std::string> problems;
  std::vector<std::string> active;
  for (const auto& s : instances) {
    if (role_silent(s)) {
      char age[32];
      std::snprintf(age, sizeof age, "%.1f", seconds(s.age));
      problems.push_back(name_of(s) + " silent for " + age + " s (last " +
                         upper(redundancy::role_name(s.report.beat.role)) + ")");
      continue;
    }
    if (s.report.beat.role == redundancy::Role::Active) active.push_back(name_of(s));
    if (s.report.alarm != redundancy::PeerAlarm::None)
      problems.push_back(name_of(s) + " raises " + std::string(redundancy::alarm_name(s.report.alarm)));
  }
  // An instance names its peer: a peer never heard is no standby to take over, whatever the
  // other instance says of it yet.
  for (const auto& s : instances) {
    if (s.report.peer.empty()) continue;
    bool heard = false;
    for (const auto& t : instances) heard = heard || t.report.name == s.report.peer;
    if (!heard) problems.push_back(s.report.peer + " (the peer of " + name_of(s) + ") not heard");
  }
  if (active.empty()) {
    std::string roles;
    for (const auto& s : instances) roles += (roles.empty() ? "" : ", ") + name_of(s) + " " + role_shown(s);
    problems.insert(problems.begin(), "no instance owns the bus (" + roles + ")");
  } else if (active.size() > 1) {
    std::string names;
    for (const auto& n : active) names += (names.empty() ? "" : " and ") + n;
    problems.insert(problems.begin(), "two instances own the bus: " + names);
  }
  return problems;
}

std::vector<std::vector<std::string>> role_rows(const std::vector<SeenInstance>& instances) {
  std::vector<std::vector<std::string>> rows{
      {"VEHICLE", "INSTANCE", "ROLE", "TERM", "PRIORITY", "BUS", "ALARM", "LAST HEARD"}};
  for (const auto& s : instances)
    rows.push_back({s.vehicle.empty() ? "-" : s.vehicle, name_of(s), role_shown(s), std::to_string(s.report.beat.term),
                    std::to_string(s.report.beat.priority), bus_text(s.report.bus),
                    std::string(redundancy::alarm_name(s.report.alarm)), age_text(seconds(s.age)) + " ago"});
  return rows;
}

std::vector<ShownRoleChange> shown_role_changes(const std::vector<SeenInstance>& instances,
                                                std::map<std::pair<std::string, std::string>, std::string>& printed) {
  std::vector<ShownRoleChange> changes;
  for (const auto& s : instances) {
    const std::string shown = role_shown(s);
    const std::string record = shown + " term " + std::to_string(s.report.beat.term);
    auto& last = printed[{s.vehicle, s.report.name}];
    if (last == record) continue;
    changes.push_back({s, last.substr(0, last.find(' '))});
    last = record;
  }
  return changes;
}

std::string role_change_text(const ShownRoleChange& change) {
  const auto& s = change.now;
  std::string text = (s.vehicle.empty() ? std::string() : s.vehicle + "/") + name_of(s) + " role " + role_shown(s) +
                     " term " + std::to_string(s.report.beat.term);
  if (!change.was.empty()) text += " (was " + change.was + ")";
  return text;
}

nlohmann::ordered_json role_json(const SeenInstance& s, int contract) {
  std::string shown = role_shown(s);
  std::transform(shown.begin(), shown.end(), shown.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  nlohmann::ordered_json values{{"name", s.report.name},
                                {"peer", s.report.peer},
                                {"role", shown},
                                {"last_role", std::string(redundancy::role_name(s.report.beat.role))},
                                {"term", s.report.beat.term},
                                {"priority", s.report.beat.priority},
                                {"hands_over", s.report.beat.hands_over},
                                {"bus_state", bus_text(s.report.bus)},
                                {"alarm", std::string(redundancy::alarm_name(s.report.alarm))},
                                {"age", seconds(s.age)},
                                {"silent", role_silent(s)}};
  return nlohmann::ordered_json{{"topic", "role"}, {"vehicle", s.vehicle}, {"values", values}, {"contract", contract}};
}

}  // namespace pmu::tools
