// A PMU session's alarms (device_session.cpp, interface.md 1.6) from a simulated PMU on the
// fake clock: each code raised by the plant or the unit's behaviour, not before its on-delay,
// and cleared (or, critical, left waiting for an acknowledgement) after its off-delay.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <optional>
#include <string>

#include "support/harness.hpp"
#include "pmu/codec/encode.hpp"

namespace pmu::service::test {
namespace {

using alarms::AlarmState;
using alarms::Code;

// Streaming every packet every 0.5 s.
struct PmuAlarms {
  explicit PmuAlarms(DeviceConfig d = device(1, TelemetryMode::Streaming, 500ms),
                     codec::FirmwareVersion fw = codec::kCurrentFirmware)
      : h(sim_bus({d}), {pmu(1, fw, 5)}) {
    h.run_for(2s);  // identity and stored values read, telemetry flowing
  }

  void plant(const std::function<void(sim::Plant&)>& change) {
    h.pmus().with_model(1, [&](sim::PmuModel& m) {
      sim::Plant p = m.plant();
      change(p);
      m.set_plant(p, h.clock().steady_now());
    });
  }
  void engine(bool running) {
    h.pmus().with_model(1, [&](sim::PmuModel& m) { m.set_engine_running(running, h.clock().steady_now()); });
  }
  void faults(const std::function<void(sim::Faults&)>& change) {
    h.pmus().with_model(1, [&](sim::PmuModel& m) {
      sim::Faults f = m.faults();
      change(f);
      m.set_faults(f);
    });
  }
  DeviceSession& session() { return *h.worker().session(1); }

  // The reports of `code`, oldest first.
  std::vector<AlarmReport> reports(Code code) const {
    std::vector<AlarmReport> out;
    for (const auto& a : h.sink.alarms)
      if (a.code == code) out.push_back(a);
    return out;
  }
  std::optional<AlarmState> last(Code code) const {
    const auto r = reports(code);
    if (r.empty()) return std::nullopt;
    return r.back().state;
  }

  Harness h;
};

struct RaiseCase {
  const char* name;
  Code code;
  std::function<void(PmuAlarms&)> setup;  // before the plant changes (an engine that runs)
  std::function<void(sim::Plant&)> raise;
  std::chrono::milliseconds on_delay;
  std::chrono::milliseconds off_delay;
  AlarmState after_clear;  // a warning is NORMAL again; a critical waits, CLEARED_UNACKNOWLEDGED
  double value;            // at the raise; NaN for a flag
  // How the plant recovers; none: as it was before the raise.
  std::function<void(sim::Plant&)> clear = nullptr;
};

const RaiseCase kRaise[] = {
    {"internal temperature above T_U (80 degC)", Code::ThermalShutdown, nullptr,
     [](sim::Plant& p) { p.internal_temperature = 90; }, 0ms, 0ms, AlarmState::ClearedUnacknowledged, NAN},
    {"SOA shutdown flag (firmware 1.17)", Code::SoaShutdown, nullptr, [](sim::Plant& p) { p.soa_shutdown = true; }, 0ms,
     0ms, AlarmState::ClearedUnacknowledged, NAN},
    {"payload shed", Code::PayloadShed, nullptr, [](sim::Plant& p) { p.payload_shed = true; }, 0ms, 5000ms,
     AlarmState::Normal, NAN},
    {"battery A 20.5 V", Code::BatteryALowVoltage, nullptr, [](sim::Plant& p) { p.battery_a_voltage = 20.5; }, 10000ms,
     10000ms, AlarmState::Normal, 20.5},
    {"battery A 19.5 V", Code::BatteryACriticalVoltage, nullptr, [](sim::Plant& p) { p.battery_a_voltage = 19.5; },
     10000ms, 10000ms, AlarmState::ClearedUnacknowledged, 19.5},
    {"battery B 20.5 V", Code::BatteryBLowVoltage, nullptr, [](sim::Plant& p) { p.battery_b_voltage = 20.5; }, 10000ms,
     10000ms, AlarmState::Normal, 20.5},
    {"battery B 19.5 V", Code::BatteryBCriticalVoltage, nullptr, [](sim::Plant& p) { p.battery_b_voltage = 19.5; },
     10000ms, 10000ms, AlarmState::ClearedUnacknowledged, 19.5},
    {"internal 75 degC, under T_U", Code::InternalOverTemperature, nullptr,
     [](sim::Plant& p) { p.internal_temperature = 75; }, 5000ms, 10000ms, AlarmState::Normal, 75},
    {"starter 90 degC", Code::StarterOverTemperature, nullptr, [](sim::Plant& p) { p.starter_temperature = 90; },
     5000ms, 10000ms, AlarmState::Normal, 90},
    {"generator sensor fitted, 110 degC", Code::GeneratorOverTemperature, nullptr,
     [](sim::Plant& p) { p.generator_temperature = 110; }, 5000ms, 10000ms, AlarmState::Normal, 110,
     // Taking the sensor away again would hold the alarm: "no sensor" is not a cool generator.
     [](sim::Plant& p) { p.generator_temperature = 40; }},
    {"battery A 65 degC", Code::BatteryAOverTemperature, nullptr, [](sim::Plant& p) { p.battery_a_temperature = 65; },
     5000ms, 10000ms, AlarmState::ClearedUnacknowledged, 65},
    {"battery B 65 degC", Code::BatteryBOverTemperature, nullptr, [](sim::Plant& p) { p.battery_b_temperature = 65; },
     5000ms, 10000ms, AlarmState::ClearedUnacknowledged, 65},
    {"engine running, generator at 10 V (V_B 25.2 V)", Code::GeneratorNotProducing,
     [](PmuAlarms& a) {
       a.engine(true);
       a.h.run_for(2s);
     },
     [](sim::Plant& p) { p.generator_voltage = 10; }, 10000ms, 5000ms, AlarmState::Normal, NAN},
};

TEST(PmuAlarms, EachCodeIsRaisedAfterItsOnDelayAndClearedAfterItsOffDelay) {
  // A packet shows a change within one period; the waits count from that packet.
  constexpr auto kPacket = 500ms;
  for (const auto& c : kRaise) {
    SCOPED_TRACE(c.name);
    PmuAlarms a;
    if (c.setup) c.setup(a);
    ASSERT_TRUE(a.h.sink.alarms.empty()) << "a healthy unit raises nothing; first: "
                                         << alarms::to_string(a.h.sink.alarms.front().code);
    sim::Plant original;
    a.h.pmus().with_model(1, [&](sim::PmuModel& m) { original = m.plant(); });
    const auto wall_at_change = a.h.clock().system_now();
    a.plant(c.raise);
    if (c.on_delay > 0ms) {
      a.h.run_for(c.on_delay - 10ms);
      EXPECT_FALSE(a.last(c.code)) << "raised before its on-delay";
    }
    a.h.run_for(kPacket + 100ms);
    ASSERT_EQ(a.last(c.code), AlarmState::ActiveUnacknowledged);
    const AlarmReport raised = a.reports(c.code).back();
    EXPECT_EQ(raised.bus, "sim0");
    EXPECT_EQ(raised.source, alarms::DeviceKind::Pmu);
    EXPECT_EQ(raised.device, 1);
    EXPECT_EQ(raised.severity, alarms::spec_of(c.code).severity);
    if (std::isnan(c.value))
      EXPECT_TRUE(std::isnan(raised.value));
    else
      EXPECT_NEAR(raised.value, c.value, 0.05);
    EXPECT_FALSE(raised.message.empty());
    EXPECT_GE(raised.since, wall_at_change + c.on_delay);
    EXPECT_LE(raised.since, a.h.clock().system_now());

    a.plant([&](sim::Plant& p) {
      p = original;
      if (c.clear) c.clear(p);
    });
    const std::size_t reports = a.reports(c.code).size();
    if (c.off_delay > 0ms) {
      a.h.run_for(c.off_delay - 10ms);
      EXPECT_EQ(a.reports(c.code).size(), reports) << "cleared before its off-delay";
    }
    a.h.run_for(kPacket + 100ms);
    EXPECT_EQ(a.last(c.code), c.after_clear);
    EXPECT_EQ(a.reports(c.code).size(), reports + 1) << "one report per change";
  }
}

TEST(PmuAlarms, BeforeFirmware116Bit6IsTheStartButtonNotAnSoaShutdown) {
  PmuAlarms a(device(1, TelemetryMode::Streaming, 500ms), codec::FirmwareVersion{1, 15});
  a.plant([](sim::Plant& p) { p.start_button = true; });
  a.h.run_for(3s);
  EXPECT_TRUE(a.h.sink.alarms.empty()) << alarms::to_string(a.h.sink.alarms.front().code);
}

TEST(PmuAlarms, AnAbsentBatteryRaisesNoVoltageAlarm) {
  PmuAlarms a;
  a.plant([](sim::Plant& p) { p.battery_b_voltage = 0; });
  a.h.run_for(30s);
  EXPECT_TRUE(a.h.sink.alarms.empty()) << alarms::to_string(a.h.sink.alarms.front().code);
}

TEST(PmuAlarms, ALowBatteryThatIsPulledKeepsItsAlarm) {
  PmuAlarms a;
  a.plant([](sim::Plant& p) { p.battery_a_voltage = 20.5; });
  a.h.run_for(11s);
  ASSERT_EQ(a.last(Code::BatteryALowVoltage), AlarmState::ActiveUnacknowledged);
  a.plant([](sim::Plant& p) { p.battery_a_voltage = 0; });
  a.h.run_for(30s);
  EXPECT_EQ(a.last(Code::BatteryALowVoltage), AlarmState::ActiveUnacknowledged)
      << "0 V is no battery, not a battery back above its limit";
}

TEST(PmuAlarms, AnEngineThatStopsByItselfRaisesUncommandedEngineStop) {
  PmuAlarms a;
  a.engine(true);
  a.h.run_for(3s);
  a.engine(false);
  a.h.run_for(900ms);  // 1 s on-delay from the first 0x04 at 0 rpm
  EXPECT_FALSE(a.last(Code::UncommandedEngineStop));
  a.h.run_for(700ms);
  EXPECT_EQ(a.last(Code::UncommandedEngineStop), AlarmState::ActiveUnacknowledged);
  // Critical: it clears once the engine runs again, and waits for an acknowledgement.
  a.engine(true);
  a.h.run_for(1s);
  EXPECT_EQ(a.last(Code::UncommandedEngineStop), AlarmState::ClearedUnacknowledged);
  for (const auto& r : a.h.sink.alarms)
    EXPECT_EQ(r.code, Code::UncommandedEngineStop) << "the engine's stop raises nothing else";
}

TEST(PmuAlarms, ACommandedEngineStopRaisesNothing) {
  PmuAlarms a;
  a.engine(true);
  a.h.run_for(3s);
  a.session().on_engine_stop("stop-1", a.h.clock().steady_now());
  a.engine(false);  // what the unit does with the 0x25 the command sent
  a.h.run_for(5s);
  EXPECT_TRUE(a.h.sink.alarms.empty()) << alarms::to_string(a.h.sink.alarms.front().code);
  // The stop was spent on that run: the next one that stops by itself is alarmed.
  a.engine(true);
  a.h.run_for(3s);
  a.engine(false);
  a.h.run_for(2s);
  EXPECT_EQ(a.last(Code::UncommandedEngineStop), AlarmState::ActiveUnacknowledged);
}

TEST(PmuAlarms, AFailedStartRaisesNothing) {
  PmuAlarms a;
  a.plant([](sim::Plant& p) { p.engine_starts_after.reset(); });  // cranks at 300 rpm, never fires
  Request start;
  start.frame = *codec::encode_engine_start(1);
  a.session().submit(std::move(start), a.h.clock().steady_now());
  a.h.run_for(1s);
  sim::EngineState e{};
  a.h.pmus().with_model(1, [&](sim::PmuModel& m) { e = m.engine_state(); });
  ASSERT_EQ(e, sim::EngineState::Cranking);
  a.h.run_for(10s);  // the cranking time (5 s) ends it
  a.h.pmus().with_model(1, [&](sim::PmuModel& m) { e = m.engine_state(); });
  ASSERT_EQ(e, sim::EngineState::Stopped);
  EXPECT_TRUE(a.h.sink.alarms.empty()) << alarms::to_string(a.h.sink.alarms.front().code);
}

TEST(PmuAlarms, AnAcknowledgementIsReportedAndACriticalThenClearsToNormal) {
  PmuAlarms a;
  a.plant([](sim::Plant& p) { p.soa_shutdown = true; });
  a.h.run_for(1s);
  ASSERT_EQ(a.last(Code::SoaShutdown), AlarmState::ActiveUnacknowledged);
  const auto wall = a.h.clock().system_now();
  EXPECT_EQ(a.session().acknowledge_alarm(Code::SoaShutdown, a.h.clock().steady_now(), wall),
            alarms::AckResult::Acknowledged);
  EXPECT_EQ(a.last(Code::SoaShutdown), AlarmState::ActiveAcknowledged);
  EXPECT_EQ(a.reports(Code::SoaShutdown).back().since, wall);
  EXPECT_EQ(a.session().acknowledge_alarm(Code::SoaShutdown, a.h.clock().steady_now(), wall),
            alarms::AckResult::NothingToAcknowledge);
  EXPECT_EQ(a.session().acknowledge_alarm(Code::CellLow, a.h.clock().steady_now(), wall), alarms::AckResult::NotFound);
  a.plant([](sim::Plant& p) { p.soa_shutdown = false; });
  a.h.run_for(1s);
  EXPECT_EQ(a.last(Code::SoaShutdown), AlarmState::Normal) << "acknowledged while active: nothing left to latch";
}

TEST(PmuAlarms, ASilentUnitIsStaleThenOfflineAndBothClearWhenItIsBack) {
  PmuAlarms a;
  a.faults([](sim::Faults& f) { f.silent = true; });
  a.h.run_for(1400ms);  // stale after 3 x 0.5 s without a frame
  EXPECT_FALSE(a.last(Code::DeviceStale));
  a.h.run_for(600ms);
  EXPECT_EQ(a.last(Code::DeviceStale), AlarmState::ActiveUnacknowledged);
  EXPECT_FALSE(a.last(Code::DeviceOffline));
  a.h.run_for(3500ms);  // offline after 10 x 0.5 s
  EXPECT_EQ(a.last(Code::DeviceOffline), AlarmState::ActiveUnacknowledged);
  EXPECT_EQ(a.last(Code::DeviceStale), AlarmState::ActiveUnacknowledged) << "still stale while offline";
  a.faults([](sim::Faults& f) { f.silent = false; });
  a.h.run_for(1s);
  EXPECT_EQ(a.last(Code::DeviceStale), AlarmState::Normal);
  EXPECT_EQ(a.last(Code::DeviceOffline), AlarmState::ClearedUnacknowledged);
}

TEST(PmuAlarms, TheDevicesSettingsApply) {
  DeviceConfig d = device(1, TelemetryMode::Streaming, 500ms);
  d.alarms[Code::BatteryALowVoltage].limit = 23.0;
  d.alarms[Code::BatteryALowVoltage].on_delay_s = 1.0;
  d.alarms[Code::BatteryBLowVoltage].enabled = false;
  PmuAlarms a(d);
  a.plant([](sim::Plant& p) { p.battery_b_voltage = 20.5; });  // 22.2 V: under the new limit for A
  a.h.run_for(2s);
  ASSERT_EQ(a.last(Code::BatteryALowVoltage), AlarmState::ActiveUnacknowledged);
  EXPECT_NEAR(a.reports(Code::BatteryALowVoltage).back().limit, 23.0, 1e-9);
  a.h.run_for(10s);
  EXPECT_FALSE(a.last(Code::BatteryBLowVoltage)) << "disabled";
  EXPECT_EQ(a.session().alarms().find(Code::BatteryBLowVoltage), nullptr);
}

TEST(PmuAlarms, AMovedUnitsAlarmsAreReportedUnderItsNewAddress) {
  PmuAlarms a;
  a.plant([](sim::Plant& p) { p.payload_shed = true; });
  a.h.run_for(1s);
  ASSERT_EQ(a.last(Code::PayloadShed), AlarmState::ActiveUnacknowledged);
  const std::size_t before = a.h.sink.alarms.size();
  a.session().move_to(9, DeviceSession::MoveCause::Commanded, a.h.clock().steady_now());
  ASSERT_EQ(a.h.sink.alarms.size(), before + 1);
  EXPECT_EQ(a.h.sink.alarms.back().device, 9);
  EXPECT_EQ(a.h.sink.alarms.back().code, Code::PayloadShed);
  EXPECT_EQ(a.h.sink.alarms.back().state, AlarmState::ActiveUnacknowledged);
  EXPECT_EQ(a.h.sink.alarms.back().since, a.reports(Code::PayloadShed).front().since) << "the time of the change";
}

}  // namespace
}  // namespace pmu::service::test
