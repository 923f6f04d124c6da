// The alarm engine on a fake clock: every code of the table through the ISA-18.2 states
// (on-delay, blips, deadband, off-delay, latching, acknowledge, not measured), then the
// table itself, the messages, the settings' validation and a device's set.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <ostream>
#include <regex>
#include <set>
#include <string>

#include "pmu/alarms/alarm.hpp"
#include "pmu/alarms/alarm_set.hpp"
#include "pmu/alarms/alarm_table.hpp"
#include "pmu/alarms/settings.hpp"

namespace pmu::alarms {
// gtest names a parameter by this, in ctest's test names too.
void PrintTo(Code c, std::ostream* os) { *os << to_string(c); }
}  // namespace pmu::alarms

namespace pmu::alarms::alarm_test {
namespace {

using namespace std::chrono_literals;

const Time t0 = Time{} + 1h;
const double kNaN = std::numeric_limits<double>::quiet_NaN();

// How far past the limit the test values go: at least the deadband, at least one step of
// the row's resolution.
double margin(const AlarmSpec& s) { return std::max(s.deadband, std::pow(10.0, -s.decimals)); }

// A value that raises the row's alarm.
double raising(const AlarmSpec& s) {
  switch (s.condition) {
    case Condition::Flag: return 1;
    case Condition::Above: return s.limit + margin(s);
    case Condition::Below: return s.limit - margin(s);
  }
  return kNaN;
}

// A value past the limit by more than the deadband: it clears.
double clearing(const AlarmSpec& s) {
  switch (s.condition) {
    case Condition::Flag: return 0;
    case Condition::Above: return s.limit - s.deadband - margin(s);
    case Condition::Below: return s.limit + s.deadband + margin(s);
  }
  return kNaN;
}

// Back on the good side of the limit, but not by the deadband.
double in_deadband(const AlarmSpec& s) {
  return s.condition == Condition::Above ? s.limit - s.deadband / 2 : s.limit + s.deadband / 2;
}

Alarm make_alarm(Code code, std::optional<Severity> severity = std::nullopt) {
  AlarmOverride o;
  o.severity = severity;
  const auto c = resolve(code, o);
  EXPECT_TRUE(c.ok()) << (c.ok() ? "" : c.error());
  return Alarm(c.ok() ? *c : default_config(code));
}

class AlarmEveryCode : public testing::TestWithParam<Code> {
 protected:
  const AlarmSpec& spec() const { return spec_of(GetParam()); }
  std::chrono::steady_clock::duration on() const { return spec().on_delay; }
  std::chrono::steady_clock::duration off() const { return spec().off_delay; }

  // Raises `a` from `t` (the condition first seen then); returns when it became active.
  Time raise(Alarm& a, Time t) const {
    a.observe(raising(spec()), t);
    a.tick(t + on());
    EXPECT_EQ(a.state(), AlarmState::ActiveUnacknowledged);
    return t + on();
  }
  // Clears `a` from `t`; returns when it cleared.
  Time clear(Alarm& a, Time t) const {
    a.observe(clearing(spec()), t);
    a.tick(t + off());
    EXPECT_TRUE(a.state() == AlarmState::Normal || a.state() == AlarmState::ClearedUnacknowledged)
        << to_string(a.state());
    return t + off();
  }
};

TEST_P(AlarmEveryCode, RaisesAfterTheOnDelayNotBefore) {
  Alarm a = make_alarm(GetParam());
  EXPECT_EQ(a.state(), AlarmState::Normal);
  EXPECT_FALSE(a.observe(clearing(spec()), t0));
  const bool at_once = a.observe(raising(spec()), t0);
  if (on() == 0ms) {
    EXPECT_TRUE(at_once);
  } else {
    EXPECT_FALSE(at_once);
    EXPECT_FALSE(a.tick(t0 + on() - 1ms));
    EXPECT_FALSE(a.observe(raising(spec()), t0 + on() - 1ms));  // still the same wait
    EXPECT_EQ(a.state(), AlarmState::Normal);
    EXPECT_TRUE(a.tick(t0 + on()));
  }
  EXPECT_EQ(a.state(), AlarmState::ActiveUnacknowledged);
  EXPECT_EQ(a.since(), t0 + on());
  EXPECT_DOUBLE_EQ(a.value(), raising(spec()));
  EXPECT_DOUBLE_EQ(a.limit(), spec().limit);
  EXPECT_EQ(a.code(), GetParam());
  EXPECT_EQ(a.severity(), spec().severity);
  EXPECT_FALSE(a.message().empty());
  EXPECT_LE(a.message().size(), kMaxMessageLength);
  EXPECT_FALSE(a.tick(t0 + on() + 1h));  // nothing more to do
}

TEST_P(AlarmEveryCode, ABlipShorterThanTheOnDelayRaisesNothing) {
  Alarm a = make_alarm(GetParam());
  if (on() == 0ms) {
    // The row asks for no delay: the PMU or the health tracker has already decided.
    EXPECT_TRUE(a.observe(raising(spec()), t0));
    EXPECT_EQ(a.state(), AlarmState::ActiveUnacknowledged);
    return;
  }
  EXPECT_FALSE(a.observe(raising(spec()), t0));
  EXPECT_FALSE(a.observe(clearing(spec()), t0 + on() - 1ms));
  EXPECT_FALSE(a.tick(t0 + 10 * on()));
  EXPECT_EQ(a.state(), AlarmState::Normal);
  // Two blips with a gap between them do not add up: the wait starts again.
  const Time t1 = t0 + 20 * on();
  EXPECT_FALSE(a.observe(raising(spec()), t1));
  EXPECT_FALSE(a.observe(clearing(spec()), t1 + on() / 2));
  EXPECT_FALSE(a.observe(raising(spec()), t1 + on() / 2 + 1ms));
  EXPECT_FALSE(a.tick(t1 + on()));
  EXPECT_FALSE(a.tick(t1 + on() / 2 + on()));
  EXPECT_EQ(a.state(), AlarmState::Normal);
  EXPECT_TRUE(a.tick(t1 + on() / 2 + 1ms + on()));
  EXPECT_EQ(a.state(), AlarmState::ActiveUnacknowledged);
}

TEST_P(AlarmEveryCode, TheDeadbandHoldsItActive) {
  if (spec().condition == Condition::Flag) {
    // A flag has no value between set and clear, and no deadband to give it one.
    EXPECT_EQ(spec().deadband, 0);
    AlarmOverride o;
    o.deadband = 1;
    EXPECT_FALSE(resolve(GetParam(), o).ok());
    return;
  }
  ASSERT_GT(spec().deadband, 0) << "a value alarm without a deadband chatters at its limit";
  Alarm a = make_alarm(GetParam());
  const Time t1 = raise(a, t0);
  EXPECT_FALSE(a.observe(in_deadband(spec()), t1 + 1s));
  EXPECT_FALSE(a.tick(t1 + 1s + off() + 1h));
  EXPECT_EQ(a.state(), AlarmState::ActiveUnacknowledged);
  // At the limit itself it is not an alarm, so it does not raise from NORMAL either.
  Alarm b = make_alarm(GetParam());
  EXPECT_FALSE(b.observe(spec().limit, t0));
  EXPECT_FALSE(b.observe(in_deadband(spec()), t0 + 1s));
  EXPECT_FALSE(b.tick(t0 + on() + 1h));
  EXPECT_EQ(b.state(), AlarmState::Normal);
  // Once past the deadband the off-delay runs; a return into the band restarts it.
  const Time t2 = t1 + 2h;
  a.observe(clearing(spec()), t2);
  if (off() > 0ms) {
    EXPECT_FALSE(a.observe(in_deadband(spec()), t2 + off() - 1ms));
    EXPECT_FALSE(a.tick(t2 + off()));
    EXPECT_EQ(a.state(), AlarmState::ActiveUnacknowledged);
    a.observe(clearing(spec()), t2 + off());
    EXPECT_TRUE(a.tick(t2 + 2 * off()));
  }
  EXPECT_NE(a.state(), AlarmState::ActiveUnacknowledged);
}

TEST_P(AlarmEveryCode, ClearsAfterTheOffDelay) {
  Alarm a = make_alarm(GetParam());
  const Time t1 = raise(a, t0) + 1s;
  const bool at_once = a.observe(clearing(spec()), t1);
  if (off() == 0ms) {
    EXPECT_TRUE(at_once);
  } else {
    EXPECT_FALSE(at_once);
    EXPECT_FALSE(a.tick(t1 + off() - 1ms));
    EXPECT_EQ(a.state(), AlarmState::ActiveUnacknowledged);
    EXPECT_TRUE(a.tick(t1 + off()));
  }
  EXPECT_EQ(a.since(), t1 + off());
  EXPECT_DOUBLE_EQ(a.value(), clearing(spec()));
  EXPECT_EQ(a.state(), spec().severity == Severity::Critical ? AlarmState::ClearedUnacknowledged : AlarmState::Normal);
  EXPECT_LE(a.message().size(), kMaxMessageLength);
}

TEST_P(AlarmEveryCode, AWarningDoesNotLatch) {
  Alarm a = make_alarm(GetParam(), Severity::Warning);
  // Cleared unacknowledged: NORMAL.
  Time t = clear(a, raise(a, t0));
  EXPECT_EQ(a.state(), AlarmState::Normal);
  // Acknowledged, then cleared: NORMAL too.
  t = raise(a, t + 1s);
  EXPECT_EQ(a.acknowledge(t), AckResult::Acknowledged);
  EXPECT_EQ(a.state(), AlarmState::ActiveAcknowledged);
  clear(a, t + 1s);
  EXPECT_EQ(a.state(), AlarmState::Normal);
}

TEST_P(AlarmEveryCode, ACriticalLatches) {
  Alarm a = make_alarm(GetParam(), Severity::Critical);
  Time t = clear(a, raise(a, t0));
  EXPECT_EQ(a.state(), AlarmState::ClearedUnacknowledged);
  EXPECT_FALSE(a.tick(t + 24h));  // stays until someone acknowledges
  EXPECT_EQ(a.state(), AlarmState::ClearedUnacknowledged);
  // Back before anyone acknowledged: active and unacknowledged again.
  t = raise(a, t + 25h);
  t = clear(a, t + 1s);
  EXPECT_EQ(a.state(), AlarmState::ClearedUnacknowledged);
  EXPECT_EQ(a.acknowledge(t + 1s), AckResult::Acknowledged);
  EXPECT_EQ(a.state(), AlarmState::Normal);
  EXPECT_EQ(a.since(), t + 1s);
  // Acknowledged while active: clearing ends it.
  t = raise(a, t + 2s);
  EXPECT_EQ(a.acknowledge(t), AckResult::Acknowledged);
  EXPECT_EQ(a.state(), AlarmState::ActiveAcknowledged);
  clear(a, t + 1s);
  EXPECT_EQ(a.state(), AlarmState::Normal);
}

TEST_P(AlarmEveryCode, AcknowledgeInEachState) {
  Alarm a = make_alarm(GetParam(), Severity::Critical);
  // NORMAL: nothing to acknowledge, nothing changes.
  EXPECT_EQ(a.acknowledge(t0), AckResult::NothingToAcknowledge);
  EXPECT_EQ(a.state(), AlarmState::Normal);
  EXPECT_EQ(a.since(), Time{});
  // ACTIVE_UNACKNOWLEDGED -> ACTIVE_ACKNOWLEDGED.
  Time t = raise(a, t0);
  EXPECT_EQ(a.acknowledge(t + 1s), AckResult::Acknowledged);
  EXPECT_EQ(a.state(), AlarmState::ActiveAcknowledged);
  EXPECT_EQ(a.since(), t + 1s);
  // ACTIVE_ACKNOWLEDGED: nothing to acknowledge, since unchanged.
  EXPECT_EQ(a.acknowledge(t + 2s), AckResult::NothingToAcknowledge);
  EXPECT_EQ(a.state(), AlarmState::ActiveAcknowledged);
  EXPECT_EQ(a.since(), t + 1s);
  // CLEARED_UNACKNOWLEDGED -> NORMAL.
  t = clear(a, t + 3s);
  t = clear(a, raise(a, t + 1s));
  EXPECT_EQ(a.state(), AlarmState::ClearedUnacknowledged);
  EXPECT_EQ(a.acknowledge(t + 1s), AckResult::Acknowledged);
  EXPECT_EQ(a.state(), AlarmState::Normal);
  EXPECT_EQ(a.acknowledge(t + 2s), AckResult::NothingToAcknowledge);
}

TEST_P(AlarmEveryCode, NotMeasuredHoldsTheState) {
  Alarm a = make_alarm(GetParam());
  // NORMAL stays NORMAL, however long nothing is measured.
  EXPECT_FALSE(a.observe(kNaN, t0));
  EXPECT_FALSE(a.tick(t0 + 24h));
  EXPECT_EQ(a.state(), AlarmState::Normal);
  // A gap in the measurement restarts the on-delay: the condition was not seen to hold.
  const Time t1 = t0 + 25h;
  a.observe(raising(spec()), t1);
  if (on() > 0ms) {
    EXPECT_FALSE(a.observe(kNaN, t1 + on() / 2));
    EXPECT_FALSE(a.tick(t1 + on()));
    EXPECT_EQ(a.state(), AlarmState::Normal);
    a.observe(raising(spec()), t1 + on());
    a.tick(t1 + 2 * on());
  }
  ASSERT_EQ(a.state(), AlarmState::ActiveUnacknowledged);
  const double value = a.value();
  // Active stays active, and the value at the change stays the measured one.
  const Time t2 = t1 + 2 * on() + 1s;
  EXPECT_FALSE(a.observe(kNaN, t2));
  EXPECT_FALSE(a.tick(t2 + 24h));
  EXPECT_EQ(a.state(), AlarmState::ActiveUnacknowledged);
  EXPECT_DOUBLE_EQ(a.value(), value);
  // A change after a gap (an acknowledge) keeps the last value measured, not "not measured".
  EXPECT_EQ(a.acknowledge(t2 + 24h + 1s), AckResult::Acknowledged);
  EXPECT_DOUBLE_EQ(a.value(), value);
  EXPECT_EQ(a.message().find("nan"), std::string_view::npos) << a.message();
  // ... and a gap restarts the off-delay too.
  const Time t3 = t2 + 25h;
  a.observe(clearing(spec()), t3);
  if (off() > 0ms) {
    EXPECT_FALSE(a.observe(kNaN, t3 + off() / 2));
    EXPECT_FALSE(a.tick(t3 + off()));
    EXPECT_EQ(a.state(), AlarmState::ActiveAcknowledged);
    a.observe(clearing(spec()), t3 + off());
    a.tick(t3 + 2 * off());
  }
  EXPECT_EQ(a.state(), AlarmState::Normal);
}

std::string code_name(const testing::TestParamInfo<Code>& info) { return std::string(to_string(info.param)); }

std::vector<Code> every_code() {
  std::vector<Code> codes;
  for (const auto& row : alarm_table()) codes.push_back(row.code);
  return codes;
}

INSTANTIATE_TEST_SUITE_P(Table, AlarmEveryCode, testing::ValuesIn(every_code()), code_name);

TEST(AlarmTable, NamesAreLowerSnakeUniqueAndFoundAgain) {
  const std::regex lower_snake("[a-z][a-z0-9]*(_[a-z0-9]+)*");
  std::set<std::string_view> names;
  for (const auto& row : alarm_table()) {
    SCOPED_TRACE(row.name);
    EXPECT_TRUE(std::regex_match(std::string(row.name), lower_snake));
    EXPECT_TRUE(names.insert(row.name).second);
    EXPECT_EQ(code_named(row.name), row.code);
    EXPECT_EQ(to_string(row.code), row.name);
  }
  EXPECT_EQ(names.size(), kCodeCount);
  EXPECT_EQ(code_named("thermal"), std::nullopt);
  EXPECT_EQ(code_named(""), std::nullopt);
}

TEST(AlarmTable, RowsAreComplete) {
  for (const auto& row : alarm_table()) {
    SCOPED_TRACE(row.name);
    EXPECT_FALSE(row.subject.empty());
    EXPECT_GE(row.deadband, 0);
    EXPECT_GE(row.on_delay, 0ms);
    EXPECT_GE(row.off_delay, 0ms);
    if (row.condition == Condition::Flag) {
      EXPECT_EQ(row.limit, 0);
      EXPECT_TRUE(row.unit.empty());
    } else {
      EXPECT_TRUE(std::isfinite(row.limit));
      EXPECT_FALSE(row.unit.empty());
      EXPECT_GT(row.deadband, 0);
    }
  }
}

// The values taken from the documents, ArduPilot and PX4, pinned so a change to them is deliberate.
TEST(AlarmTable, DefaultsThatComeFromTheDocumentsOrAreNamedElsewhere) {
  EXPECT_EQ(spec_of(Code::ThermalShutdown).basis, Basis::Documented);
  EXPECT_EQ(spec_of(Code::ThermalShutdown).severity, Severity::Critical);
  EXPECT_EQ(spec_of(Code::SoaShutdown).basis, Basis::Documented);
  EXPECT_EQ(spec_of(Code::PayloadShed).basis, Basis::Documented);
  EXPECT_EQ(spec_of(Code::PayloadShed).severity, Severity::Warning);
  EXPECT_DOUBLE_EQ(spec_of(Code::BatteryALowVoltage).limit, 21.0);
  EXPECT_DOUBLE_EQ(spec_of(Code::BatteryACriticalVoltage).limit, 19.8);
  EXPECT_EQ(spec_of(Code::BatteryALowVoltage).on_delay, 10s);  // ArduPilot's BATT_LOW_TIMER
  EXPECT_DOUBLE_EQ(spec_of(Code::BmsLowSoc).limit, 15);        // PX4's BAT_LOW_THR
  EXPECT_DOUBLE_EQ(spec_of(Code::BmsCriticalSoc).limit, 7);    // PX4's BAT_CRIT_THR
  // Each low/critical pair: the critical limit is the further one.
  EXPECT_LT(spec_of(Code::BatteryACriticalVoltage).limit, spec_of(Code::BatteryALowVoltage).limit);
  EXPECT_LT(spec_of(Code::BatteryBCriticalVoltage).limit, spec_of(Code::BatteryBLowVoltage).limit);
  EXPECT_LT(spec_of(Code::BmsCriticalSoc).limit, spec_of(Code::BmsLowSoc).limit);
}

TEST(AlarmTable, WhichRowsEachKindOfSetHolds) {
  EXPECT_TRUE(applies_to(spec_of(Code::ThermalShutdown), DeviceKind::Pmu));
  EXPECT_TRUE(applies_to(spec_of(Code::DeviceOffline), DeviceKind::Pmu));
  EXPECT_TRUE(applies_to(spec_of(Code::DeviceOffline), DeviceKind::Battery));
  EXPECT_TRUE(applies_to(spec_of(Code::DeviceStale), DeviceKind::Mppt));
  EXPECT_FALSE(applies_to(spec_of(Code::DeviceOffline), DeviceKind::Bus));
  EXPECT_FALSE(applies_to(spec_of(Code::BusOff), DeviceKind::Pmu));
  EXPECT_FALSE(applies_to(spec_of(Code::CellLow), DeviceKind::Pmu));
  EXPECT_FALSE(applies_to(spec_of(Code::ThermalShutdown), DeviceKind::Battery));
  EXPECT_TRUE(applies_to(spec_of(Code::MpptFault), DeviceKind::Mppt));
}

// Raises `code` at once (no delays) with `value`, for the messages below.
Alarm raised_with(Code code, double value) {
  AlarmOverride o;
  o.on_delay_s = 0;
  o.off_delay_s = 0;
  const auto c = resolve(code, o);
  EXPECT_TRUE(c.ok());
  Alarm a(*c);
  EXPECT_TRUE(a.observe(value, t0));
  return a;
}

TEST(AlarmMessage, SaysTheValueAgainstTheLimit) {
  EXPECT_EQ(raised_with(Code::BatteryALowVoltage, 20.1).message(), "battery A 20.1 V < 21.0 V");
  EXPECT_EQ(raised_with(Code::BatteryBCriticalVoltage, 19.5).message(), "battery B 19.5 V < 19.8 V");
  EXPECT_EQ(raised_with(Code::InternalOverTemperature, 71).message(), "PMU internal 71 degC > 70 degC");
  EXPECT_EQ(raised_with(Code::BmsLowSoc, 14).message(), "SOC 14 % < 15 %");
  EXPECT_EQ(raised_with(Code::CellImbalance, 0.123).message(), "cell spread 0.12 V > 0.10 V");
  EXPECT_EQ(raised_with(Code::ThermalShutdown, 1).message(), "thermal shutdown");
}

TEST(AlarmMessage, SaysWhenItCleared) {
  Alarm v = raised_with(Code::BatteryALowVoltage, 20.1);
  EXPECT_TRUE(v.observe(21.6, t0 + 1s));
  EXPECT_EQ(v.message(), "battery A back to 21.6 V");
  Alarm f = raised_with(Code::ThermalShutdown, 1);
  EXPECT_TRUE(f.observe_flag(false, t0 + 1s));
  EXPECT_EQ(f.state(), AlarmState::ClearedUnacknowledged);
  EXPECT_EQ(f.message(), "thermal shutdown cleared");
}

TEST(AlarmMessage, NeverLongerThanTheLimitWhateverTheValue) {
  const double extremes[] = {1e300, -1e300, std::numeric_limits<double>::infinity(),
                             -std::numeric_limits<double>::infinity(), 123456789.123456};
  for (const auto& row : alarm_table()) {
    for (double x : extremes) {
      SCOPED_TRACE(testing::Message() << row.name << " " << x);
      Alarm a(default_config(row.code));
      a.observe(x, t0);
      a.tick(t0 + 1h);
      a.acknowledge(t0 + 2h);
      a.observe(-x, t0 + 3h);
      a.tick(t0 + 4h);
      EXPECT_LE(a.message().size(), kMaxMessageLength);
    }
  }
}

TEST(AlarmMessage, EmptyBeforeTheFirstChange) {
  Alarm a(default_config(Code::BusOff));
  EXPECT_TRUE(a.message().empty());
  EXPECT_TRUE(std::isnan(a.value()));
}

TEST(AlarmSettings, OverridesReplaceTheDefaults) {
  AlarmOverride o;
  o.limit = 22.2;
  o.deadband = 0.5;
  o.on_delay_s = 2.5;
  o.off_delay_s = 0;
  o.severity = Severity::Critical;
  o.enabled = false;
  const auto c = resolve(Code::BatteryALowVoltage, o);
  ASSERT_TRUE(c.ok()) << c.error();
  EXPECT_EQ(c->code, Code::BatteryALowVoltage);
  EXPECT_DOUBLE_EQ(c->limit, 22.2);
  EXPECT_DOUBLE_EQ(c->deadband, 0.5);
  EXPECT_EQ(c->on_delay, 2500ms);
  EXPECT_EQ(c->off_delay, 0ms);
  EXPECT_EQ(c->severity, Severity::Critical);
  EXPECT_FALSE(c->enabled);
  // Nothing set: the table's row.
  const auto d = resolve(Code::BatteryALowVoltage, AlarmOverride{});
  ASSERT_TRUE(d.ok());
  EXPECT_DOUBLE_EQ(d->limit, 21.0);
  EXPECT_DOUBLE_EQ(d->deadband, 0.3);
  EXPECT_EQ(d->on_delay, 10s);
  EXPECT_EQ(d->severity, Severity::Warning);
  EXPECT_TRUE(d->enabled);
}

TEST(AlarmSettings, EachBadFieldIsNamedWithItsCode) {
  const double inf = std::numeric_limits<double>::infinity();
  struct Case {
    const char* what;
    Code code;
    AlarmOverride o;
    const char* error;
  };
  auto with = [](auto field, auto value) {
    AlarmOverride o;
    o.*field = value;
    return o;
  };
  const Case cases[] = {
      {"negative deadband", Code::BatteryALowVoltage, with(&AlarmOverride::deadband, -0.5),
       "battery_a_low_voltage: deadband -0.5 is negative"},
      {"NaN deadband", Code::CellLow, with(&AlarmOverride::deadband, kNaN),
       "cell_low: deadband is not a finite number"},
      {"NaN limit", Code::BmsLowSoc, with(&AlarmOverride::limit, kNaN), "bms_low_soc: limit is not a finite number"},
      {"infinite limit", Code::BmsLowSoc, with(&AlarmOverride::limit, -inf),
       "bms_low_soc: limit is not a finite number"},
      {"negative on-delay", Code::DeviceStale, with(&AlarmOverride::on_delay_s, -1.0),
       "device_stale: on_delay -1 s is negative"},
      {"NaN off-delay", Code::BusOff, with(&AlarmOverride::off_delay_s, kNaN),
       "bus_off: off_delay is not a number of seconds"},
      {"infinite on-delay", Code::BusOff, with(&AlarmOverride::on_delay_s, inf),
       "bus_off: on_delay is not a number of seconds"},
      {"a delay past a day", Code::MpptFault, with(&AlarmOverride::off_delay_s, 86401.0),
       "mppt_fault: off_delay 86401 s is longer than a day"},
      {"a flag's limit", Code::ThermalShutdown, with(&AlarmOverride::limit, 1.0),
       "thermal_shutdown: limit cannot be set: the alarm is a flag"},
      {"a flag's deadband", Code::PayloadShed, with(&AlarmOverride::deadband, 0.0),
       "payload_shed: deadband cannot be set: the alarm is a flag"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.what);
    const auto r = resolve(c.code, c.o);
    ASSERT_FALSE(r.ok());
    EXPECT_EQ(r.error(), c.error);
  }
  // The edges that are allowed.
  EXPECT_TRUE(resolve(Code::MpptFault, with(&AlarmOverride::off_delay_s, 86400.0)).ok());
  EXPECT_TRUE(resolve(Code::CellLow, with(&AlarmOverride::deadband, 0.0)).ok());
  EXPECT_TRUE(resolve(Code::CellLow, with(&AlarmOverride::limit, -5.0)).ok());
}

TEST(AlarmSettings, AnOverrideOfAnotherKindsAlarmIsAnError) {
  DeviceSettings s;
  s[Code::CellLow].limit = 3.2;
  const auto r = resolve(DeviceKind::Pmu, s);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error(), "cell_low: not an alarm of a pmu");
  const auto b = resolve(DeviceKind::Battery, s);
  ASSERT_TRUE(b.ok()) << b.error();
  // The first bad field of a device's settings is the one reported.
  s[Code::BmsLowSoc].on_delay_s = -2;
  const auto e = resolve(DeviceKind::Battery, s);
  ASSERT_FALSE(e.ok());
  EXPECT_EQ(e.error(), "bms_low_soc: on_delay -2 s is negative");
}

std::vector<Code> codes_of(const AlarmSet& set) {
  std::vector<Code> out;
  for (const auto& a : set.alarms()) out.push_back(a.code());
  return out;
}

TEST(AlarmSet, HoldsTheRowsOfItsKind) {
  const std::vector<Code> pmu{Code::ThermalShutdown,
                              Code::SoaShutdown,
                              Code::PayloadShed,
                              Code::BatteryALowVoltage,
                              Code::BatteryACriticalVoltage,
                              Code::BatteryBLowVoltage,
                              Code::BatteryBCriticalVoltage,
                              Code::InternalOverTemperature,
                              Code::StarterOverTemperature,
                              Code::GeneratorOverTemperature,
                              Code::BatteryAOverTemperature,
                              Code::BatteryBOverTemperature,
                              Code::GeneratorNotProducing,
                              Code::UncommandedEngineStop,
                              Code::DeviceStale,
                              Code::DeviceOffline};
  const std::vector<Code> battery{Code::BmsLowSoc,     Code::BmsCriticalSoc,     Code::CellLow,
                                  Code::CellImbalance, Code::BmsOverTemperature, Code::DeviceStale,
                                  Code::DeviceOffline};
  const std::vector<Code> mppt{Code::MpptFault, Code::DeviceStale, Code::DeviceOffline};
  const std::vector<Code> bus{Code::BusErrorPassive, Code::BusOff};
  struct Case {
    DeviceKind kind;
    const std::vector<Code>& codes;
  };
  for (const auto& c : {Case{DeviceKind::Pmu, pmu}, Case{DeviceKind::Battery, battery}, Case{DeviceKind::Mppt, mppt},
                        Case{DeviceKind::Bus, bus}}) {
    SCOPED_TRACE(to_string(c.kind));
    const auto set = AlarmSet::make(c.kind);
    ASSERT_TRUE(set.ok()) << set.error();
    EXPECT_EQ(set->kind(), c.kind);
    EXPECT_EQ(codes_of(*set), c.codes);
    EXPECT_TRUE(set->not_normal().empty());
  }
}

TEST(AlarmSet, ADisabledAlarmIsNotThere) {
  DeviceSettings s;
  s[Code::BatteryBLowVoltage].enabled = false;
  s[Code::BatteryBCriticalVoltage].enabled = false;
  auto made = AlarmSet::make(DeviceKind::Pmu, s);
  ASSERT_TRUE(made.ok());
  AlarmSet& set = made.value();
  EXPECT_EQ(set.find(Code::BatteryBLowVoltage), nullptr);
  EXPECT_NE(set.find(Code::BatteryALowVoltage), nullptr);
  EXPECT_FALSE(set.observe(Code::BatteryBCriticalVoltage, 0, t0));
  EXPECT_TRUE(set.tick(t0 + 1h).empty());
  EXPECT_EQ(set.acknowledge(Code::BatteryBCriticalVoltage, t0), AckResult::NotFound);
}

TEST(AlarmSet, SettingsAreAppliedAndABadOneRefusesTheSet) {
  DeviceSettings s;
  s[Code::BatteryALowVoltage].limit = 22.0;
  auto set = AlarmSet::make(DeviceKind::Pmu, s);
  ASSERT_TRUE(set.ok());
  EXPECT_DOUBLE_EQ(set->find(Code::BatteryALowVoltage)->limit(), 22.0);
  s[Code::BatteryALowVoltage].deadband = -1;
  const auto bad = AlarmSet::make(DeviceKind::Pmu, s);
  ASSERT_FALSE(bad.ok());
  EXPECT_EQ(bad.error(), "battery_a_low_voltage: deadband -1 is negative");
}

TEST(AlarmSet, TickReportsTheCodesThatChangedAndAcknowledgeSaysWhatItDid) {
  auto made = AlarmSet::make(DeviceKind::Pmu);
  ASSERT_TRUE(made.ok());
  AlarmSet& set = made.value();
  // Flags with no on-delay change at once; the battery waits its 10 s.
  EXPECT_TRUE(set.observe_flag(Code::ThermalShutdown, true, t0));
  EXPECT_FALSE(set.observe(Code::BatteryALowVoltage, 20.0, t0));
  EXPECT_FALSE(set.observe(Code::BatteryACriticalVoltage, 20.0, t0));  // above 19.8 V
  EXPECT_FALSE(set.observe(Code::CellLow, 1.0, t0));                   // not a PMU's alarm
  EXPECT_TRUE(set.tick(t0 + 9s).empty());
  EXPECT_EQ(set.tick(t0 + 10s), std::vector<Code>{Code::BatteryALowVoltage});
  EXPECT_TRUE(set.tick(t0 + 11s).empty());

  const auto up = set.not_normal();
  ASSERT_EQ(up.size(), 2u);
  EXPECT_EQ(up[0]->code(), Code::ThermalShutdown);
  EXPECT_EQ(up[1]->code(), Code::BatteryALowVoltage);
  EXPECT_EQ(up[1]->message(), "battery A 20.0 V < 21.0 V");

  EXPECT_EQ(set.acknowledge(Code::BatteryALowVoltage, t0 + 12s), AckResult::Acknowledged);
  EXPECT_EQ(set.acknowledge(Code::BatteryALowVoltage, t0 + 13s), AckResult::NothingToAcknowledge);
  EXPECT_EQ(set.acknowledge(Code::PayloadShed, t0 + 13s), AckResult::NothingToAcknowledge);
  EXPECT_EQ(set.acknowledge(Code::BusOff, t0 + 13s), AckResult::NotFound);
  EXPECT_EQ(set.find(Code::BatteryALowVoltage)->state(), AlarmState::ActiveAcknowledged);

  // The thermal shutdown ends unacknowledged: a critical, it stays listed until acknowledged.
  EXPECT_TRUE(set.observe_flag(Code::ThermalShutdown, false, t0 + 20s));
  EXPECT_EQ(set.find(Code::ThermalShutdown)->state(), AlarmState::ClearedUnacknowledged);
  EXPECT_EQ(set.not_normal().size(), 2u);
  EXPECT_EQ(set.acknowledge(Code::ThermalShutdown, t0 + 21s), AckResult::Acknowledged);
  EXPECT_EQ(set.not_normal().size(), 1u);
}

TEST(AlarmNames, StatesAndResultsHaveTheirText) {
  EXPECT_EQ(to_string(AlarmState::Normal), "NORMAL");
  EXPECT_EQ(to_string(AlarmState::ActiveUnacknowledged), "ACTIVE_UNACKNOWLEDGED");
  EXPECT_EQ(to_string(AlarmState::ActiveAcknowledged), "ACTIVE_ACKNOWLEDGED");
  EXPECT_EQ(to_string(AlarmState::ClearedUnacknowledged), "CLEARED_UNACKNOWLEDGED");
  EXPECT_EQ(to_string(AckResult::NothingToAcknowledge), "nothing to acknowledge");
  EXPECT_EQ(to_string(Severity::Critical), "critical");
  EXPECT_EQ(to_string(DeviceKind::Mppt), "mppt");
}

}  // namespace
}  // namespace pmu::alarms::alarm_test
