// Acknowledging an alarm from outside (alarm_ack_service.cpp, interface.md 1.6): the edge
// parse, one reply per request, a resend answered but never applied twice, and each state's
// acknowledgement on a simulated PMU and bus driven by the fake clock.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "support/harness.hpp"
#include "pmu/dispatch/alarm_ack_service.hpp"

namespace pmu::service::test {
namespace {

using alarms::AlarmState;
using alarms::Code;

AlarmAckSample ack(const std::string& id, const char* code = "thermal_shutdown", std::int64_t kind = 0,
                   std::uint16_t device = 1) {
  AlarmAckSample s;
  s.sender = "guid-1";
  s.request_id = id;
  s.vehicle = "";
  s.bus = "sim0";
  s.kind = kind;
  s.device = device;
  s.code = code;
  return s;
}

struct BadSample {
  const char* name;
  void (*spoil)(AlarmAckSample&, std::uint64_t now_ns);
  const char* reason;
};

const BadSample kBad[] = {
    {"empty request id", [](AlarmAckSample& s, std::uint64_t) { s.request_id.clear(); }, "request_id is empty"},
    {"request id of 64 bytes", [](AlarmAckSample& s, std::uint64_t) { s.request_id = std::string(64, 'x'); },
     "request_id is 64 bytes long; at most 63"},
    {"another vehicle", [](AlarmAckSample& s, std::uint64_t) { s.vehicle = "uav7"; },
     "vehicle 'uav7' is not this service's ('')"},
    {"no bus", [](AlarmAckSample& s, std::uint64_t) { s.bus.clear(); }, "bus: a bus name of 1 to 15 bytes"},
    {"kind past the enum", [](AlarmAckSample& s, std::uint64_t) { s.kind = 4; }, "kind 4 is not an AlarmSource"},
    {"kind 2^32-1", [](AlarmAckSample& s, std::uint64_t) { s.kind = 4294967295; },
     "kind 4294967295 is not an AlarmSource"},
    {"unknown code", [](AlarmAckSample& s, std::uint64_t) { s.code = "melting\n"; },
     "code 'melting\\x0A' is not an alarm code"},
    {"code of 32 bytes", [](AlarmAckSample& s, std::uint64_t) { s.code = "thermal_shutdown" + std::string(16, '_'); },
     "code 'thermal_shutdown________________' is not an alarm code"},
    {"a PMU code for a battery", [](AlarmAckSample& s, std::uint64_t) { s.kind = 1; },
     "code thermal_shutdown is not an alarm of a battery"},
    {"a bus code for a PMU", [](AlarmAckSample& s, std::uint64_t) { s.code = "bus_off"; },
     "code bus_off is not an alarm of a pmu"},
    {"a bus alarm with a device",
     [](AlarmAckSample& s, std::uint64_t) {
       s.kind = 3;
       s.code = "bus_off";
     },
     "device must be 0 for a bus alarm"},
    {"expired", [](AlarmAckSample& s, std::uint64_t now) { s.expires_at = now - 2000000000; },
     "expires_at: expired 2000 ms ago"},
};

TEST(AlarmAckParse, EveryBadSampleIsRejectedWithTheFieldNamed) {
  const auto wall = std::chrono::system_clock::time_point(std::chrono::seconds(1800000000));
  const Now now{wall, std::chrono::steady_clock::time_point(std::chrono::seconds(100))};
  for (const auto& c : kBad) {
    SCOPED_TRACE(c.name);
    auto s = ack("a-1");
    c.spoil(s, epoch_ns(wall));
    const auto r = parse_alarm_ack(s, "", now, Lifetimes{});
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error(), c.reason);
  }
}

TEST(AlarmAckParse, AGoodSampleGivesTheTypedRequest) {
  const Now now{std::chrono::system_clock::time_point(std::chrono::seconds(1800000000)),
                std::chrono::steady_clock::time_point(std::chrono::seconds(100))};
  auto s = ack("a-1", "bus_off", 3, 0);
  const auto r = parse_alarm_ack(s, "", now, Lifetimes{});
  ASSERT_TRUE(r) << r.error();
  EXPECT_EQ(r->kind, alarms::DeviceKind::Bus);
  EXPECT_EQ(r->code, Code::BusOff);
  EXPECT_EQ(r->expires, now.steady + Lifetimes{}.default_lifetime);
  const auto b = parse_alarm_ack(ack("a-2", "bms_low_soc", 1, 2), "", now, Lifetimes{});
  ASSERT_TRUE(b) << b.error();
  EXPECT_EQ(b->kind, alarms::DeviceKind::Battery);
}

// A simulated PMU at address 1 streaming every 0.5 s, and the service's acknowledgements.
struct Acks {
  Acks()
      : h(sim_bus({device(1, TelemetryMode::Streaming, 500ms)}), {pmu(1, codec::kCurrentFirmware, 5)}),
        service({&h.worker()}, "", Lifetimes{}, h.clock(),
                [this](const AlarmAckReplyData& r) { replies.push_back(r); }) {
    h.run_for(2s);
  }
  void plant(const std::function<void(sim::Plant&)>& change) {
    h.pmus().with_model(1, [&](sim::PmuModel& m) {
      sim::Plant p = m.plant();
      change(p);
      m.set_plant(p, h.clock().steady_now());
    });
  }
  AlarmAckReplyData run(const AlarmAckSample& s) {
    const auto before = replies.size();
    service.submit(s);
    h.run_for(20ms);
    EXPECT_EQ(replies.size(), before + 1) << "exactly one reply";
    return replies.empty() ? AlarmAckReplyData{} : replies.back();
  }
  AlarmState state(Code code) {
    const auto* a = h.worker().session(1)->alarms().find(code);
    return a ? a->state() : AlarmState::Normal;
  }

  Harness h;
  std::vector<AlarmAckReplyData> replies;
  AlarmAckService service;
};

TEST(AlarmAck, AnActiveAlarmIsAcknowledgedAndStaysActive) {
  Acks a;
  a.plant([](sim::Plant& p) { p.internal_temperature = 90; });
  a.h.run_for(600ms);
  ASSERT_EQ(a.state(Code::ThermalShutdown), AlarmState::ActiveUnacknowledged);
  const auto r = a.run(ack("a-1"));
  EXPECT_EQ(r.result, AckReplyResult::Completed);
  EXPECT_EQ(r.reason, "acknowledged");
  EXPECT_EQ(r.state, AlarmState::ActiveAcknowledged);
  EXPECT_EQ(r.code, "thermal_shutdown");
  EXPECT_EQ(a.h.sink.alarms.back().state, AlarmState::ActiveAcknowledged) << "reported on pmu/alarms";
}

TEST(AlarmAck, AClearedCriticalIsAcknowledgedToNormal) {
  Acks a;
  a.plant([](sim::Plant& p) { p.internal_temperature = 90; });
  a.h.run_for(600ms);
  a.plant([](sim::Plant& p) { p.internal_temperature = 40; });
  a.h.run_for(600ms);
  ASSERT_EQ(a.state(Code::ThermalShutdown), AlarmState::ClearedUnacknowledged);
  const auto r = a.run(ack("a-1"));
  EXPECT_EQ(r.result, AckReplyResult::Completed);
  EXPECT_EQ(r.state, AlarmState::Normal);
  EXPECT_EQ(a.h.sink.alarms.back().state, AlarmState::Normal);
}

TEST(AlarmAck, ANormalAlarmHasNothingToAcknowledge) {
  Acks a;
  const auto r = a.run(ack("a-1"));
  EXPECT_EQ(r.result, AckReplyResult::Completed);
  EXPECT_EQ(r.reason, "nothing to acknowledge: NORMAL");
  EXPECT_EQ(r.state, AlarmState::Normal);
}

TEST(AlarmAck, AnAlarmAlreadyAcknowledgedHasNothingToAcknowledge) {
  Acks a;
  a.plant([](sim::Plant& p) { p.internal_temperature = 90; });
  a.h.run_for(600ms);
  a.run(ack("a-1"));
  const auto r = a.run(ack("a-2"));
  EXPECT_EQ(r.result, AckReplyResult::Completed);
  EXPECT_EQ(r.reason, "nothing to acknowledge: ACTIVE_ACKNOWLEDGED");
  EXPECT_EQ(r.state, AlarmState::ActiveAcknowledged);
}

TEST(AlarmAck, NoSuchDeviceOrBusOrAlarm) {
  Acks a;
  auto absent = ack("a-1");
  absent.device = 9;
  EXPECT_EQ(a.run(absent).reason, "no such alarm");
  auto battery = ack("a-2", "bms_low_soc", 1, 2);
  EXPECT_EQ(a.run(battery).reason, "no such alarm");
  auto other = ack("a-3");
  other.bus = "can7";
  const auto r = a.run(other);
  EXPECT_EQ(r.result, AckReplyResult::Rejected);
  EXPECT_EQ(r.reason, "bus can7 is not served");
}

TEST(AlarmAck, AResendIsAnsweredAgainAndNeverAppliedTwice) {
  Acks a;
  a.plant([](sim::Plant& p) { p.internal_temperature = 90; });
  a.h.run_for(600ms);
  a.plant([](sim::Plant& p) { p.internal_temperature = 40; });
  a.h.run_for(600ms);
  ASSERT_EQ(a.state(Code::ThermalShutdown), AlarmState::ClearedUnacknowledged);
  // Sent twice before the worker turns: the second is owed the first one's reply.
  a.service.submit(ack("a-1"));
  a.service.submit(ack("a-1"));
  a.h.run_for(20ms);
  ASSERT_EQ(a.replies.size(), 2u);
  const auto alarm_reports = a.h.sink.alarms.size();
  // The alarm is raised again meanwhile: a late resend must not acknowledge the new one.
  a.plant([](sim::Plant& p) { p.internal_temperature = 90; });
  a.h.run_for(600ms);
  ASSERT_EQ(a.state(Code::ThermalShutdown), AlarmState::ActiveUnacknowledged);
  const auto again = a.run(ack("a-1"));
  EXPECT_EQ(again.reason, "acknowledged");
  EXPECT_EQ(again.state, AlarmState::Normal) << "the first answer, again";
  EXPECT_EQ(a.state(Code::ThermalShutdown), AlarmState::ActiveUnacknowledged) << "not applied again";
  EXPECT_GT(a.h.sink.alarms.size(), alarm_reports);
  for (const auto& r : a.replies) EXPECT_EQ(r.state, AlarmState::Normal);
  // The same id from another sender is another request.
  auto other = ack("a-1");
  other.sender = "guid-2";
  EXPECT_EQ(a.run(other).state, AlarmState::ActiveAcknowledged);
  // The same id with other content is refused.
  auto reused = ack("a-1", "soa_shutdown");
  const auto r = a.run(reused);
  EXPECT_EQ(r.result, AckReplyResult::Rejected);
  EXPECT_NE(r.reason.find("already used"), std::string::npos) << r.reason;
}

TEST(AlarmAck, ABusAlarmIsAcknowledged) {
  Acks a;
  a.h.network().set_state(transport::BusState::BusOff);
  a.h.run_for(50ms);
  a.h.network().set_state(transport::BusState::Up);
  a.h.run_for(50ms);
  const auto r = a.run(ack("a-1", "bus_off", 3, 0));
  EXPECT_EQ(r.result, AckReplyResult::Completed);
  EXPECT_EQ(r.reason, "acknowledged");
  EXPECT_EQ(r.state, AlarmState::Normal);
  EXPECT_EQ(a.h.worker().bus_alarms().find(Code::BusOff)->state(), AlarmState::Normal);
}

TEST(AlarmAck, AnAckThatExpiresBeforeTheWorkerTakesItIsRejected) {
  Acks a;
  auto s = ack("a-1");
  s.expires_at = epoch_ns(a.h.clock().system_now()) + 5000000;  // 5 ms
  a.service.submit(s);
  a.h.clock().advance(10ms);
  a.h.settle();
  ASSERT_EQ(a.replies.size(), 1u);
  EXPECT_EQ(a.replies.back().result, AckReplyResult::Rejected);
  EXPECT_EQ(a.replies.back().reason, "expired before the bus worker took it");
}

}  // namespace
}  // namespace pmu::service::test
