// What pmuctl shows of a hot-standby pair (pmuctl/view/role_view.hpp, interface.md 3.2): a
// silent instance is SILENT, never its last role (docs/safety.md H7), and a pair with no bus
// owner, two, a silent instance or an alarm is never judged fit to fly on (H6).
#include "pmuctl/view/role_view.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <string>
#include <vector>

namespace pmu::tools {
namespace {

using namespace std::chrono_literals;
using redundancy::BusState;
using redundancy::PeerAlarm;
using redundancy::Role;

SeenInstance seen(const std::string& name, Role role, std::chrono::milliseconds age = 100ms,
                  PeerAlarm alarm = PeerAlarm::None) {
  return SeenInstance{"uav7", {name, name == "mc-a" ? "mc-b" : "mc-a", {role, 3, 2, false}, BusState::Ok, alarm}, age};
}

TEST(RoleView, ASilentInstanceIsShownSilentWhateverItLastSaid) {
  struct Case {
    std::chrono::milliseconds age;
    const char* shown;
  };
  for (const auto& c :
       std::vector<Case>{{0ms, "ACTIVE"}, {1500ms, "ACTIVE"}, {1501ms, "SILENT"}, {60000ms, "SILENT"}}) {
    const auto s = seen("mc-a", Role::Active, c.age);
    EXPECT_EQ(role_shown(s), c.shown) << c.age.count();
    const auto j = role_json(s, 5);
    EXPECT_EQ(j["values"]["role"], std::string(c.shown) == "SILENT" ? "silent" : "active");
    EXPECT_EQ(j["values"]["last_role"], "active");
    EXPECT_EQ(j["values"]["silent"], std::string(c.shown) == "SILENT");
  }
}

TEST(RoleView, OnlyOneHeardOwnerAndNoAlarmIsAPairThatMayFlyOn) {
  struct Case {
    const char* what;
    std::vector<SeenInstance> pair;
    std::vector<std::string> problems;
  };
  const std::vector<Case> cases{
      {"one owner, a standby", {seen("mc-a", Role::Active), seen("mc-b", Role::Standby)}, {}},
      {"no owner",
       {seen("mc-a", Role::Standby), seen("mc-b", Role::Claiming)},
       {"no instance owns the bus (mc-a STANDBY, mc-b CLAIMING)"}},
      {"two owners",
       {seen("mc-a", Role::Active), seen("mc-b", Role::Active)},
       {"two instances own the bus: mc-a and mc-b"}},
      {"the owner silent",
       {seen("mc-a", Role::Active, 2500ms), seen("mc-b", Role::Standby)},
       {"no instance owns the bus (mc-a SILENT, mc-b STANDBY)", "mc-a silent for 2.5 s (last ACTIVE)"}},
      {"the standby silent",
       {seen("mc-a", Role::Active), seen("mc-b", Role::Standby, 2000ms)},
       {"mc-b silent for 2.0 s (last STANDBY)"}},
      {"an alarm",
       {seen("mc-a", Role::Active, 100ms, PeerAlarm::PeerUnreachable),
        seen("mc-b", Role::Fenced, 100ms, PeerAlarm::Partition)},
       {"mc-a raises peer_unreachable", "mc-b raises partition"}},
      {"a priority clash",
       {seen("mc-a", Role::Active, 100ms, PeerAlarm::PriorityClash), seen("mc-b", Role::Standby)},
       {"mc-a raises priority_clash"}},
      {"the peer never heard", {seen("mc-a", Role::Active)}, {"mc-b (the peer of mc-a) not heard"}},
  };
  for (const auto& c : cases) EXPECT_EQ(pair_problems(c.pair), c.problems) << c.what;
}

TEST(RoleView, APairIsCompleteWhenEveryPeerNamedIsHeard) {
  EXPECT_TRUE(peers_heard({}));
  EXPECT_FALSE(peers_heard({seen("mc-a", Role::Active)}));
  EXPECT_TRUE(peers_heard({seen("mc-a", Role::Active), seen("mc-b", Role::Standby)}));
  auto elsewhere = seen("mc-b", Role::Standby);
  elsewhere.vehicle = "uav8";
  EXPECT_FALSE(peers_heard({seen("mc-a", Role::Active), elsewhere}));
}

TEST(RoleView, ListRows) {
  const auto rows = role_rows({seen("mc-a", Role::Active, 200ms), seen("mc-b", Role::NoBus, 5000ms)});
  ASSERT_EQ(rows.size(), 3u);
  EXPECT_EQ(rows[0], (std::vector<std::string>{"VEHICLE", "INSTANCE", "ROLE", "TERM", "PRIORITY", "BUS", "ALARM",
                                               "LAST HEARD"}));
  EXPECT_EQ(rows[1], (std::vector<std::string>{"uav7", "mc-a", "ACTIVE", "3", "2", "ok", "none", "0.2s ago"}));
  EXPECT_EQ(rows[2][2], "SILENT");
  EXPECT_EQ(rows[2][7], "5.0s ago");
}

// watch prints a line when an instance's shown role or term changes, and only then: a dead
// owner's line says SILENT once its samples stop, never ACTIVE again (H7).
TEST(RoleView, WatchPrintsAnInstanceOnlyWhenItsShownRoleOrTermChanges) {
  struct Step {
    std::vector<SeenInstance> seen;
    std::vector<std::string> lines;
  };
  auto term = [](SeenInstance s, std::uint32_t t) {
    s.report.beat.term = t;
    return s;
  };
  const std::vector<Step> steps{
      {{seen("mc-a", Role::Active), seen("mc-b", Role::Standby)},
       {"uav7/mc-a role ACTIVE term 3", "uav7/mc-b role STANDBY term 3"}},
      {{seen("mc-a", Role::Active, 900ms), seen("mc-b", Role::Standby)}, {}},
      {{seen("mc-a", Role::Active, 1600ms), seen("mc-b", Role::Claiming)},
       {"uav7/mc-a role SILENT term 3 (was ACTIVE)", "uav7/mc-b role CLAIMING term 3 (was STANDBY)"}},
      {{seen("mc-a", Role::Active, 5000ms), term(seen("mc-b", Role::Active), 4)},
       {"uav7/mc-b role ACTIVE term 4 (was CLAIMING)"}},
      {{term(seen("mc-a", Role::Standby), 4), term(seen("mc-b", Role::Active), 4)},
       {"uav7/mc-a role STANDBY term 4 (was SILENT)"}},
  };
  std::map<std::pair<std::string, std::string>, std::string> printed;
  for (std::size_t i = 0; i < steps.size(); ++i) {
    std::vector<std::string> lines;
    for (const auto& c : shown_role_changes(steps[i].seen, printed)) lines.push_back(role_change_text(c));
    EXPECT_EQ(lines, steps[i].lines) << "step " << i;
  }
  SeenInstance unnamed = seen("mc-a", Role::Standby);
  unnamed.vehicle.clear();
  EXPECT_EQ(role_change_text({unnamed, ""}), "mc-a role STANDBY term 3");
}

}  // namespace
}  // namespace pmu::tools
