// Commands across a hot-standby failover (command_service.hpp's role gate, failover_record.hpp;
// design.md "Hot standby", interface.md 2.4, docs/safety.md H4, H8): a standby neither
// executes nor answers; after it takes over, each request it recorded is answered once from
// the former owner's reply, answered "outcome unknown" when its frames were heard without a
// reply, run when never seen, never run twice, and an ENGINE_STOP always runs. Simulated PMUs
// and a fake clock; the former owner is played by hand (its replies and its frames).
#include <gtest/gtest.h>

#include <atomic>
#include <string>
#include <vector>

#include "support/harness.hpp"
#include "pmu/dispatch/alarm_ack_service.hpp"
#include "pmu/dispatch/command_service.hpp"
#include "support/pmu_frames.hpp"

namespace pmu::service::test {
namespace {

using codec::test::pmu_frame;

// A harness and a CommandService behind a role gate the test moves.
class Pair {
 public:
  explicit Pair(bool owns = false)
      : h(sim_bus({device(1)}), {pmu(1)}),
        service({&h.worker()}, PolicyConfig{}, Timeouts{}, h.clock(),
                [this](const CommandReplyData& r) { replies.push_back(r); }) {
    owner = owns;
    service.set_role_gate([this] { return this->owner.load(); });
    h.run_for(300ms);  // start-up reading done
    h.clear_sent();
  }

  CommandSample req(CommandKind kind, std::string id) {
    CommandSample r;
    r.request_id = std::move(id);
    r.sender = "client-guid";
    r.bus = "sim0";
    r.address = 1;
    r.kind = static_cast<std::uint32_t>(kind);
    return r;
  }
  CommandSample set_avionics(std::string id, double volts = 24.0) {
    auto r = req(CommandKind::SetParameter, std::move(id));
    r.parameter = "avionics_voltage";
    r.value = volts;
    return r;
  }
  static CommandReplyData reply_of(const CommandSample& s, CommandResult result, std::string reason) {
    CommandReplyData d;
    d.request_id = s.request_id;
    d.bus = s.bus;
    d.address = s.address;
    d.kind = static_cast<CommandKind>(s.kind);
    d.result = result;
    d.reason = std::move(reason);
    return d;
  }
  void take_over() {
    owner = true;
    service.took_over(h.clock().steady_now());
    h.run_for(500ms);
  }
  std::vector<CommandReplyData> replies_to(const std::string& id) const {
    std::vector<CommandReplyData> out;
    for (const auto& r : replies)
      if (r.request_id == id) out.push_back(r);
    return out;
  }
  std::size_t frames_with(std::uint8_t packet) const {
    std::size_t n = 0;
    for (const auto& f : h.sent_frames())
      if (((f.id >> 16) & 0xFF) == packet) ++n;
    return n;
  }
  std::uint32_t avionics_raw() {
    std::uint32_t v = 0;
    h.pmus().with_model(1, [&](sim::PmuModel& m) { v = m.parameter(codec::Parameter::AvionicsVoltage); });
    return v;
  }

  std::atomic<bool> owner{false};
  Harness h;
  std::vector<CommandReplyData> replies;
  CommandService service;
};

TEST(Failover, AStandbyNeitherExecutesNorAnswers) {
  Pair p;
  p.service.submit(p.set_avionics("s-1", 13.0));
  auto stop = p.req(CommandKind::EngineStop, "s-2");
  p.service.submit(stop);
  p.service.submit(stop);  // a resend
  auto nameless = p.req(CommandKind::Reset, "");
  p.service.submit(nameless);
  p.h.run_for(2s);
  EXPECT_TRUE(p.replies.empty());
  EXPECT_TRUE(p.h.sent_frames().empty());
  EXPECT_NE(p.avionics_raw(), 130u);
  EXPECT_EQ(p.service.recorded(), 2u);
  EXPECT_EQ(p.service.counters().received, 0u);
}

TEST(Failover, AfterATakeoverEachRecordedRequestGetsExactlyOneFinalReplyAndRunsAtMostOnce) {
  Pair p;
  // Answered by the former owner: not run again, and a resend gets the owner's reply.
  const auto answered = p.set_avionics("answered", 13.0);
  p.service.submit(answered);
  p.service.heard_on_can("sim0", pmu_frame(0x10, 1, {130}), p.h.clock().steady_now());
  p.service.peer_reply(Pair::reply_of(answered, CommandResult::Completed, "avionics_voltage is 13 V"));
  // Its frame heard, no reply: outcome unknown.
  auto heard = p.req(CommandKind::SetOutputs, "heard");
  heard.outputs = 0x01;
  p.service.submit(heard);
  p.service.heard_on_can("sim0", pmu_frame(0x20, 1, {0x01}), p.h.clock().steady_now());
  // Never seen on the bus: runs.
  const auto unseen = p.set_avionics("unseen", 20.0);
  p.service.submit(unseen);
  // An engine stop whose frame was heard: runs all the same.
  const auto stop = p.req(CommandKind::EngineStop, "stop");
  p.service.submit(stop);
  p.service.heard_on_can("sim0", pmu_frame(0x25, 1, {}), p.h.clock().steady_now());
  ASSERT_EQ(p.service.recorded(), 4u);
  EXPECT_TRUE(p.replies.empty());

  p.take_over();

  EXPECT_TRUE(p.replies_to("answered").empty()) << "the former owner answered it";
  // Its outcome unknown: not answered until asked again, as the former owner's reply may have
  // reached the client already.
  EXPECT_TRUE(p.replies_to("heard").empty());
  const auto ran = p.replies_to("unseen");
  ASSERT_EQ(ran.size(), 1u);
  EXPECT_EQ(ran[0].result, CommandResult::Completed) << ran[0].reason;
  EXPECT_EQ(p.avionics_raw(), 200u);
  const auto stopped = p.replies_to("stop");
  ASSERT_EQ(stopped.size(), 1u);
  EXPECT_EQ(stopped[0].result, CommandResult::Completed) << stopped[0].reason;
  EXPECT_EQ(p.frames_with(0x25), 1u) << "the stop went out";
  EXPECT_EQ(p.frames_with(0x20), 0u) << "the unknown one was not run";
  EXPECT_EQ(p.frames_with(0x10), 2u) << "one set and its read-back, the unseen one's alone";
  EXPECT_EQ(p.service.recorded(), 0u);

  // Resends after the takeover: answered from the record, never executed.
  p.h.clear_sent();
  p.replies.clear();
  for (const auto& again : {answered, heard, unseen, stop}) p.service.submit(again);
  p.h.run_for(500ms);
  EXPECT_TRUE(p.h.sent_frames().empty());
  ASSERT_EQ(p.replies.size(), 4u);
  EXPECT_EQ(p.replies[0].reason, "avionics_voltage is 13 V");
  EXPECT_EQ(p.replies[0].result, CommandResult::Completed);
  EXPECT_EQ(p.replies[1].reason, FailoverRecord::kHeardReason);
  EXPECT_EQ(p.replies[2].result, CommandResult::Completed);
  EXPECT_EQ(p.replies[3].result, CommandResult::Completed);
  EXPECT_NE(p.avionics_raw(), 130u) << "the former owner's command was not run here";

  // A second takeover call finds nothing to do.
  p.replies.clear();
  p.service.took_over(p.h.clock().steady_now());
  p.h.run_for(100ms);
  EXPECT_TRUE(p.replies.empty());
}

TEST(Failover, ARequestThatExpiredBeforeTheTakeoverIsRejectedNotRun) {
  Pair p;
  const auto late = p.set_avionics("late", 20.0);  // the default lifetime, 10 s
  p.service.submit(late);
  p.h.run_for(10500ms);
  p.take_over();
  const auto r = p.replies_to("late");
  ASSERT_EQ(r.size(), 1u);
  EXPECT_EQ(r[0].result, CommandResult::Rejected);
  EXPECT_EQ(r[0].reason, "expired before it could be sent");
  EXPECT_TRUE(p.h.sent_frames().empty());
  EXPECT_NE(p.avionics_raw(), 200u);
}

TEST(Failover, AnEngineStopRecordedLongAgoStillGoesOut) {
  Pair p;
  p.service.submit(p.req(CommandKind::EngineStop, "old-stop"));
  p.h.run_for(30s);
  p.take_over();
  const auto r = p.replies_to("old-stop");
  ASSERT_EQ(r.size(), 1u);
  EXPECT_EQ(r[0].result, CommandResult::Completed) << r[0].reason;
  EXPECT_EQ(p.frames_with(0x25), 1u);
}

TEST(Failover, TheFirstRequestAfterTheGateOpensFindsTheRecordSettledFirst) {
  // The resend reaches the new owner before its holder calls took_over(): it is answered from
  // the record, not run as new.
  Pair p;
  const auto heard = p.set_avionics("heard", 20.0);
  p.service.submit(heard);
  p.service.heard_on_can("sim0", pmu_frame(0x10, 1, {200}), p.h.clock().steady_now());
  p.owner = true;
  p.service.submit(heard);
  p.h.run_for(500ms);
  EXPECT_TRUE(p.h.sent_frames().empty());
  const auto r = p.replies_to("heard");
  ASSERT_EQ(r.size(), 1u) << "the resend's, and nothing at the takeover itself";
  EXPECT_EQ(r[0].reason, FailoverRecord::kHeardReason);
}

TEST(Failover, ARequestRunningWhenTheGateClosesIsNotAnsweredHereButRecorded) {
  Pair p(true);
  const auto running = p.set_avionics("running", 20.0);
  p.service.submit(running);
  p.owner = false;  // demoted before the worker took it
  p.h.run_for(2s);
  EXPECT_TRUE(p.replies.empty()) << "the new owner answers it";
  EXPECT_TRUE(p.h.sent_frames().empty());
  EXPECT_EQ(p.service.recorded(), 1u);
  // Back as the owner with no reply from the peer: its frames may have gone out. Answered
  // when the client asks again.
  p.take_over();
  EXPECT_TRUE(p.replies_to("running").empty());
  p.service.submit(running);
  p.h.run_for(100ms);
  const auto r = p.replies_to("running");
  ASSERT_EQ(r.size(), 1u);
  EXPECT_EQ(r[0].result, CommandResult::Failed);
  EXPECT_EQ(p.frames_with(0x10), 0u);
}

TEST(Failover, ARequestWhoseFramesWentOutBeforeTheGateClosedIsNotAnsweredHere) {
  Pair p(true);
  const auto half = p.set_avionics("half-done", 20.0);
  p.service.submit(half);
  p.h.worker().run_once(0ms);  // the worker takes it and sends its set
  ASSERT_FALSE(p.h.sent_frames().empty());
  p.owner = false;
  p.h.run_for(2s);  // the device answers the read-back; the reply is the new owner's to give
  EXPECT_TRUE(p.replies.empty());
  EXPECT_EQ(p.service.recorded(), 1u);
  p.h.clear_sent();
  p.take_over();
  EXPECT_TRUE(p.replies_to("half-done").empty()) << "not until it is sent again";
  p.service.submit(half);
  p.h.run_for(100ms);
  const auto r = p.replies_to("half-done");
  ASSERT_EQ(r.size(), 1u);
  EXPECT_EQ(r[0].result, CommandResult::Failed);
  EXPECT_EQ(r[0].reason, FailoverRecord::kHeardReason);
  EXPECT_TRUE(p.h.sent_frames().empty()) << "not run again";
}

TEST(Failover, WithoutAGateTheServiceExecutesAsAlways) {
  Harness h(sim_bus({device(1)}), {pmu(1)});
  std::vector<CommandReplyData> replies;
  CommandService service({&h.worker()}, PolicyConfig{}, Timeouts{}, h.clock(),
                         [&](const CommandReplyData& r) { replies.push_back(r); });
  h.run_for(300ms);
  h.clear_sent();
  CommandSample s;
  s.request_id = "x";
  s.sender = "c";
  s.bus = "sim0";
  s.address = 1;
  s.kind = static_cast<std::uint32_t>(CommandKind::EngineStop);
  service.submit(s);
  service.heard_on_can("sim0", pmu_frame(0x25, 1, {}), h.clock().steady_now());
  h.run_for(100ms);
  ASSERT_EQ(replies.size(), 1u);
  EXPECT_EQ(replies[0].result, CommandResult::Completed);
  EXPECT_EQ(service.recorded(), 0u);
}

TEST(Failover, AStandbyNeitherAppliesNorAnswersAnAlarmAcknowledgement) {
  // A PMU streaming every 0.5 s whose internal temperature raises thermal_shutdown.
  Harness h(sim_bus({device(1, TelemetryMode::Streaming, 500ms)}), {pmu(1, codec::kCurrentFirmware, 5)});
  std::vector<AlarmAckReplyData> replies;
  std::atomic<bool> owner{false};
  AlarmAckService acks({&h.worker()}, "", Lifetimes{}, h.clock(),
                       [&](const AlarmAckReplyData& r) { replies.push_back(r); });
  acks.set_role_gate([&] { return owner.load(); });
  h.run_for(2s);
  h.pmus().with_model(1, [&](sim::PmuModel& m) {
    sim::Plant p = m.plant();
    p.internal_temperature = 90;
    m.set_plant(p, h.clock().steady_now());
  });
  h.run_for(600ms);
  const auto state = [&] { return h.worker().session(1)->alarms().find(alarms::Code::ThermalShutdown)->state(); };
  ASSERT_EQ(state(), alarms::AlarmState::ActiveUnacknowledged);
  AlarmAckSample s;
  s.sender = "guid-1";
  s.request_id = "a-1";
  s.bus = "sim0";
  s.kind = 0;
  s.device = 1;
  s.code = "thermal_shutdown";
  acks.submit(s);
  h.run_for(100ms);
  EXPECT_TRUE(replies.empty());
  EXPECT_EQ(state(), alarms::AlarmState::ActiveUnacknowledged) << "not applied by the standby";
  EXPECT_EQ(acks.remembered(), 0u);
  owner = true;
  acks.submit(s);  // the resend reaches the new owner
  h.run_for(100ms);
  ASSERT_EQ(replies.size(), 1u);
  EXPECT_EQ(replies[0].result, AckReplyResult::Completed);
  EXPECT_EQ(state(), alarms::AlarmState::ActiveAcknowledged);
}

}  // namespace
}  // namespace pmu::service::test
