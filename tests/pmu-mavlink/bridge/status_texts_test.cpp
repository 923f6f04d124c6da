#include "status/status_texts.hpp"

#include <gtest/gtest.h>

#include "telemetry/heartbeat.hpp"

namespace pmu::mavlink_bridge {
namespace {

namespace sev = pmu::mavlink::mav_severity;

pmu::v5::Alarm alarm(pmu::v5::AlarmState state, pmu::v5::AlarmSeverity severity = pmu::v5::SEVERITY_CRITICAL) {
  pmu::v5::Alarm a;
  a.bus("sim0");
  a.device(1);
  a.kind(pmu::v5::SOURCE_PMU);
  a.code("battery_a_low_voltage");
  a.severity(severity);
  a.state(state);
  a.message("battery A 20.1 V < 21.0 V");
  return a;
}

TEST(AlarmTexts, EachTransitionOnceWithItsSeverity) {
  AlarmTexts texts;
  struct Step {
    pmu::v5::AlarmState state;
    bool said;
    std::uint8_t severity;
    const char* text;
  };
  const Step steps[] = {
      {pmu::v5::ALARM_NORMAL, false, 0, ""},
      {pmu::v5::ALARM_ACTIVE_UNACKNOWLEDGED, true, sev::kCritical, "PMU: battery A 20.1 V < 21.0 V"},
      {pmu::v5::ALARM_ACTIVE_UNACKNOWLEDGED, false, 0, ""},
      {pmu::v5::ALARM_ACTIVE_ACKNOWLEDGED, true, sev::kCritical, "PMU: battery A 20.1 V < 21.0 V acked"},
      {pmu::v5::ALARM_NORMAL, true, sev::kNotice, "PMU normal: battery_a_low_voltage"},
      {pmu::v5::ALARM_ACTIVE_UNACKNOWLEDGED, true, sev::kCritical, "PMU: battery A 20.1 V < 21.0 V"},
      {pmu::v5::ALARM_CLEARED_UNACKNOWLEDGED, true, sev::kNotice, "PMU cleared: battery_a_low_voltage"},
  };
  int i = 0;
  for (const auto& s : steps) {
    const auto t = texts.on_sample(alarm(s.state));
    ASSERT_EQ(t.has_value(), s.said) << "step " << i;
    if (t) {
      EXPECT_EQ(t->severity, s.severity) << "step " << i;
      EXPECT_EQ(t->text, s.text) << "step " << i;
    }
    ++i;
  }
}

TEST(AlarmTexts, WarningSeverityAndKeysApart) {
  AlarmTexts texts;
  auto w = alarm(pmu::v5::ALARM_ACTIVE_UNACKNOWLEDGED, pmu::v5::SEVERITY_WARNING);
  ASSERT_TRUE(texts.on_sample(w));
  EXPECT_EQ(alarm_text(w).severity, sev::kWarning);
  auto other = w;
  other.device(2);
  EXPECT_TRUE(texts.on_sample(other)) << "another device's alarm is its own";
  texts.forget(w);
  EXPECT_TRUE(texts.on_sample(w)) << "forgotten: said again";
}

TEST(AlarmTexts, LongMessageFitsStatustext) {
  auto a = alarm(pmu::v5::ALARM_ACTIVE_ACKNOWLEDGED);
  a.message(std::string(42, 'x'));
  EXPECT_EQ(alarm_text(a).text.size(), 50U);
}

TEST(PrearmLines, OneLinePerReasonThenTheRest) {
  pmu::v5::Readiness r;
  r.ready(false);
  pmu::v5::ReadinessReason a;
  a.code("device_not_online");
  a.message("PMU 1 on sim0 not online");
  pmu::v5::ReadinessReason b;
  b.code("config_differs");
  r.reasons().push_back(a);
  r.reasons().push_back(b);
  r.reasons_total(5);
  const auto lines = prearm_lines(r);
  ASSERT_EQ(lines.size(), 3U);
  EXPECT_EQ(lines[0].text, "PreArm: PMU 1 on sim0 not online");
  EXPECT_EQ(lines[0].severity, sev::kCritical);
  EXPECT_EQ(lines[1].text, "PreArm: config_differs") << "no message: the code";
  EXPECT_EQ(lines[2].text, "PreArm: +3 more");
  pmu::v5::Readiness ready;
  ready.ready(true);
  EXPECT_TRUE(prearm_lines(ready).empty());
}

TEST(ReadinessTexts, ChangesSaidOnce) {
  ReadinessTexts texts;
  pmu::v5::Readiness r;
  r.ready(false);
  r.reasons_total(2);
  auto t = texts.on_sample(r);
  ASSERT_TRUE(t);
  EXPECT_EQ(t->text, "PMU: not ready, 2 reasons");
  EXPECT_EQ(t->severity, sev::kWarning);
  EXPECT_FALSE(texts.on_sample(r));
  r.ready(true);
  t = texts.on_sample(r);
  ASSERT_TRUE(t);
  EXPECT_EQ(t->text, "PMU: ready");
  EXPECT_EQ(t->severity, sev::kInfo);
  EXPECT_FALSE(texts.on_sample(r));
}

TEST(Heartbeat, BatteryComponentNotAnAutopilot) {
  namespace nm = pmu::mavlink;
  const struct {
    ServiceReadiness readiness;
    std::uint8_t state;
  } cases[] = {{ServiceReadiness::not_heard, nm::mav_state::kBoot},
               {ServiceReadiness::ready, nm::mav_state::kActive},
               {ServiceReadiness::not_ready, nm::mav_state::kStandby}};
  for (const auto& c : cases) {
    const auto h = heartbeat(c.readiness);
    EXPECT_EQ(h.type, nm::mav_type::kBattery);
    EXPECT_EQ(h.autopilot, nm::mav_autopilot::kInvalid);
    EXPECT_EQ(h.system_status, c.state);
  }
}

}  // namespace
}  // namespace pmu::mavlink_bridge
