// When /diagnostics writes its array (diagnostics_pace.hpp, docs/interface.md 11.3): at once
// when a reader sees a device change (level, message, added, gone), otherwise at most once a
// second of the injected clock's time, so devices that each report every second cost one
// array a second, not one per report.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "pmu/endpoints/diagnostics_pace.hpp"

namespace pmu::service {
namespace {

using namespace std::chrono_literals;
using Ms = std::chrono::milliseconds;

DiagnosticsPace::TimePoint at(Ms t) { return DiagnosticsPace::TimePoint{} + t; }

const ShownStatus kOnline{0, "online"};
const ShownStatus kWarn{1, "battery A low"};
const ShownStatus kWarnOther{1, "battery B low"};

enum class Event { Added, Same, LevelChanged, MessageChanged, Gone };

struct Step {
  Ms time;
  Event event;
  bool written;
};

bool apply(DiagnosticsPace& pace, const Step& s) {
  switch (s.event) {
    case Event::Added: return pace.on_report(std::nullopt, kOnline, at(s.time));
    case Event::Same: return pace.on_report(kOnline, kOnline, at(s.time));
    case Event::LevelChanged: return pace.on_report(kOnline, kWarn, at(s.time));
    case Event::MessageChanged: return pace.on_report(kWarn, kWarnOther, at(s.time));
    case Event::Gone: return pace.on_gone(at(s.time));
  }
  return false;
}

TEST(DiagnosticsPace, AChangeIsWrittenAtOnceAndAnUnchangedReportAtMostOnceASecond) {
  struct Case {
    const char* what;
    std::vector<Step> steps;
  };
  const std::vector<Case> cases{
      {"a device added is written; its unchanged reports within the second are not",
       {{0ms, Event::Added, true},
        {300ms, Event::Same, false},
        {999ms, Event::Same, false},
        {1000ms, Event::Same, true}}},
      {"a level change is written at once, in the middle of the second",
       {{0ms, Event::Added, true}, {400ms, Event::LevelChanged, true}, {500ms, Event::LevelChanged, true}}},
      {"a message change at the same level is written at once",
       {{0ms, Event::Added, true}, {200ms, Event::MessageChanged, true}}},
      {"a device gone is written at once",
       {{0ms, Event::Added, true}, {100ms, Event::Same, false}, {150ms, Event::Gone, true}}},
      {"a change writes every device's status: the next unchanged array is a second after it",
       {{0ms, Event::Added, true},
        {600ms, Event::LevelChanged, true},
        {1000ms, Event::Same, false},
        {1599ms, Event::Same, false},
        {1600ms, Event::Same, true}}},
      {"a second device added is a change a reader sees",
       {{0ms, Event::Added, true}, {10ms, Event::Added, true}, {20ms, Event::Same, false}}},
      {"reports a little under a second apart keep one array a second",
       {{0ms, Event::Added, true},
        {990ms, Event::Same, false},
        {1980ms, Event::Same, true},
        {2970ms, Event::Same, true},
        {3960ms, Event::Same, true},
        {4950ms, Event::Same, true}}},
      {"after a silence the second starts again from the report that ends it, with no burst",
       {{0ms, Event::Added, true},
        {5000ms, Event::Same, true},
        {5500ms, Event::Same, false},
        {5999ms, Event::Same, false},
        {6000ms, Event::Same, true}}},
  };
  for (const auto& c : cases) {
    DiagnosticsPace pace;
    for (const auto& s : c.steps) EXPECT_EQ(apply(pace, s), s.written) << c.what << ", at " << s.time.count() << " ms";
  }
}

// Each of N devices reports its unchanged status every second, 10 ms apart, for 10 s: the N
// arrays of their joining, then one a second, where one array per report is N a second.
TEST(DiagnosticsPace, DevicesReportingEverySecondCostOneArrayASecond) {
  struct Case {
    int devices;
    int arrays;
  };
  for (const Case c : {Case{1, 1 + 9}, Case{3, 3 + 9}, Case{10, 10 + 9}}) {
    DiagnosticsPace pace;
    std::vector<bool> joined(static_cast<std::size_t>(c.devices), false);
    int arrays = 0;
    for (int second = 0; second < 10; ++second)
      for (int d = 0; d < c.devices; ++d) {
        const auto now = at(Ms{second * 1000 + d * 10});
        const std::optional<ShownStatus> before =
            joined[static_cast<std::size_t>(d)] ? std::optional<ShownStatus>{kOnline} : std::nullopt;
        joined[static_cast<std::size_t>(d)] = true;
        if (pace.on_report(before, kOnline, now)) ++arrays;
      }
    EXPECT_EQ(arrays, c.arrays) << c.devices << " devices, " << c.devices * 10 << " reports";
  }
}

// Three devices in their steady second: one device's level change is written at once,
// between the once-a-second arrays.
TEST(DiagnosticsPace, ALevelChangeAmongSteadyDevicesIsWrittenAtOnce) {
  DiagnosticsPace pace;
  for (int d = 0; d < 3; ++d) EXPECT_TRUE(pace.on_report(std::nullopt, kOnline, at(Ms{d * 10})));
  EXPECT_FALSE(pace.on_report(kOnline, kOnline, at(1000ms)));
  EXPECT_FALSE(pace.on_report(kOnline, kOnline, at(1010ms)));
  EXPECT_TRUE(pace.on_report(kOnline, kOnline, at(1020ms)));
  EXPECT_TRUE(pace.on_report(kOnline, kWarn, at(1500ms))) << "device 1 went WARN";
  EXPECT_FALSE(pace.on_report(kOnline, kOnline, at(2000ms)));
  EXPECT_FALSE(pace.on_report(kWarn, kWarn, at(2010ms))) << "still WARN: no change";
  EXPECT_FALSE(pace.on_report(kOnline, kOnline, at(2020ms)));
  EXPECT_TRUE(pace.on_report(kOnline, kOnline, at(3000ms)));
}

}  // namespace
}  // namespace pmu::service
