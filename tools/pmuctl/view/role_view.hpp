#pragma once
// What pmuctl shows of a hot-standby pair (interface.md 1.10, 3.2): each instance seen on
// pmu/role with the age of its last sample, and whether the vehicle's pair may fly on, as pure
// functions of the plain reports (pmu/redundancy/role.hpp), so each rule is tested without DDS.
//
// pmuctl cannot know the pair's lease (a setting of the services' configs, 0.3 s by default, at
// most 10 s): an instance whose last sample arrived longer ago than kRoleSilentAfter is shown as
// SILENT, never by its last role, so a dead bus owner is never shown as ACTIVE (docs/safety.md
// H7). 1.5 s: an instance writes every heartbeat_period, at most 1 s, and half of that more
// lets a reliable repair of a lost sample through before a live instance is called silent.

#include <chrono>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "pmu/redundancy/role.hpp"

namespace pmu::tools {

inline constexpr std::chrono::milliseconds kRoleSilentAfter{1500};

// An instance's last pmu/role sample and how long ago it arrived (by pmuctl's clock).
struct SeenInstance {
  std::string vehicle;
  redundancy::RoleReport report;
  std::chrono::steady_clock::duration age{};
};

bool role_silent(const SeenInstance& s) noexcept;

// Whether every instance heard has its peer heard too: the pair is complete, or a peer is
// silent for good, which only the caller's deadline tells.
bool peers_heard(const std::vector<SeenInstance>& instances);

// "ACTIVE", "STANDBY", ...; "SILENT" for a silent instance, whatever it last said.
std::string role_shown(const SeenInstance& s);

// Why the vehicle's pair may not fly on, one line each, or none: exactly one instance ACTIVE
// and heard, no instance raising an alarm or silent, and every instance's peer heard.
// `instances`: one vehicle's.
std::vector<std::string> pair_problems(const std::vector<SeenInstance>& instances);

// The rows of list's pair table, a header first: VEHICLE INSTANCE ROLE TERM PRIORITY BUS ALARM
// LAST HEARD; the caller aligns them.
std::vector<std::vector<std::string>> role_rows(const std::vector<SeenInstance>& instances);

// What `watch` prints of pairs: an instance whose shown role (role_shown, SILENT included) or
// term differs from what was last printed of it, with what that was ("" when first heard).
struct ShownRoleChange {
  SeenInstance now;
  std::string was;  // role_shown of the line printed before, "" for none
};
// The changes since the last call; `printed` (by vehicle and name: "ROLE term N") is the
// caller's record of what was printed, updated here.
std::vector<ShownRoleChange> shown_role_changes(const std::vector<SeenInstance>& instances,
                                                std::map<std::pair<std::string, std::string>, std::string>& printed);
// A watch line's words after its time: "uav7/mc-b role ACTIVE term 3 (was STANDBY)"; the
// unnamed vehicle's instance is "mc-b", and an instance first heard has no "(was ...)".
std::string role_change_text(const ShownRoleChange& change);

// One JSON line's object: topic "role", vehicle, values {name, peer, role (role_shown in lower
// case), last_role, term, priority, hands_over, bus_state, alarm, age (s), silent}, contract.
nlohmann::ordered_json role_json(const SeenInstance& s, int contract);

}  // namespace pmu::tools
