// The verified engine start (engine_start.hpp, interface.md 2.7): the decision on a fake
// clock, the refusals from the 0x04 flags of each firmware, and the whole command through
// CommandService against a simulated PMU whose engine fires, never fires, already runs, or
// is stopped while cranking.
#include <gtest/gtest.h>

#include "support/harness.hpp"
#include "pmu/codec/encode.hpp"
#include "pmu/codec/ids.hpp"
#include "pmu/dispatch/command_service.hpp"
#include "pmu/dispatch/engine_start.hpp"

namespace pmu::service::test {
namespace {

using Clock = std::chrono::steady_clock;

SteadyTime at_s(double s) {
  return SteadyTime{} + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(s));
}

// ---- the decision -------------------------------------------------------------------------

struct WatchCase {
  const char* what;
  double cranking_time;                          // the unit's CT, s
  std::vector<std::pair<double, int>> readings;  // (s after the start, rpm)
  double decided_at;                             // s; the reading or deadline that decides
  CommandResult result;
  const char* reason;
};

const WatchCase kWatch[] = {
    {"fires after 2 s, held 1 s",
     5.0,
     {{0.2, 300}, {1.0, 300}, {2.0, 6000}, {2.4, 6000}, {2.8, 6000}, {3.0, 6000}},
     3.0,
     CommandResult::Completed,
     "engine running: 6000 rpm for 1.0 s, 3.0 s after the start"},
    {"a cough restarts the hold",
     5.0,
     {{1.0, 6000}, {1.4, 300}, {2.0, 5000}, {2.6, 5000}, {3.0, 5000}},
     3.0,
     CommandResult::Completed,
     "engine running: 5000 rpm for 1.0 s"},
    {"exactly the running speed counts", 5.0, {{1.0, 1500}, {2.0, 1500}}, 2.0, CommandResult::Completed, "1500 rpm"},
    {"no reading (65535) is no speed",
     5.0,
     {{1.0, 65535}, {2.0, 65535}, {3.0, 65535}},
     7.0,
     CommandResult::Failed,
     "no start: rpm 0 after 7.0 s (cranking time 5.0 s)"},
    {"never fires: CT + hold + margin",
     5.0,
     {{1.0, 300}, {4.9, 300}, {5.2, 0}},
     7.0,
     CommandResult::Failed,
     "no start: rpm 0 after 7.0 s (cranking time 5.0 s)"},
    {"CT 0 (no timeout on the unit) is given the longest CT",
     0.0,
     {{1.0, 300}, {20.0, 300}},
     27.5,
     CommandResult::Failed,
     "no start: rpm 300 after 27.5 s (cranking time 25.5 s)"},
    {"fires just inside the deadline", 5.0, {{4.9, 6000}, {5.9, 6000}}, 5.9, CommandResult::Completed, "engine running"},
};

TEST(EngineStartWatch, DecidesFromTheGeneratorSpeedAndTheDeadline) {
  for (const auto& c : kWatch) {
    SCOPED_TRACE(c.what);
    EngineStartWatch w(EngineSettings{}, EngineStartTiming{}, c.cranking_time, at_s(0));
    std::optional<Verdict> v;
    double when = -1;
    for (const auto& [t, rpm] : c.readings) {
      if ((v = w.on_time(at_s(t)))) {
        when = t;
        break;
      }
      if ((v = w.on_rpm(static_cast<std::uint16_t>(rpm), at_s(t)))) {
        when = t;
        break;
      }
    }
    if (!v) {
      EXPECT_FALSE(w.on_time(at_s(c.decided_at) - std::chrono::milliseconds(1))) << "decided before the deadline";
      v = w.on_time(at_s(c.decided_at));
      when = c.decided_at;
    }
    ASSERT_TRUE(v);
    EXPECT_DOUBLE_EQ(when, c.decided_at);
    EXPECT_EQ(v->result, c.result);
    EXPECT_NE(v->reason.find(c.reason), std::string::npos) << v->reason;
  }
}

TEST(EngineStartWatch, ProgressAtOnceThenAtMostOnceASecondWithPhaseAndSpeed) {
  EngineStartWatch w(EngineSettings{}, EngineStartTiming{}, 5.0, at_s(0));
  auto first = w.progress(at_s(0));
  ASSERT_TRUE(first);
  EXPECT_EQ(first->result, CommandResult::InProgress);
  EXPECT_EQ(first->reason, "cranking: 0.0 s of up to 5.0 s");
  EXPECT_FALSE(first->value) << "no speed read yet";
  EXPECT_FALSE(w.on_rpm(300, at_s(0.4)));
  EXPECT_FALSE(w.progress(at_s(0.4)));
  EXPECT_FALSE(w.progress(at_s(0.999)));
  auto second = w.progress(at_s(1.0));
  ASSERT_TRUE(second);
  EXPECT_EQ(second->reason, "cranking: 1.0 s of up to 5.0 s, 300 rpm");
  EXPECT_EQ(second->value, 300.0);
  EXPECT_FALSE(w.on_rpm(6000, at_s(1.6)));
  auto third = w.progress(at_s(2.0));
  ASSERT_TRUE(third);
  EXPECT_EQ(third->reason, "running, holding: 2.0 s of up to 5.0 s, 6000 rpm");
}

TEST(EngineStartWatch, CancelledSaysByWhichStop) {
  EngineStartWatch w(EngineSettings{}, EngineStartTiming{}, 5.0, at_s(0));
  (void)w.on_rpm(300, at_s(1.0));
  const auto v = w.cancelled("stop-7", at_s(1.5));
  EXPECT_EQ(v.result, CommandResult::Failed);
  EXPECT_EQ(v.reason, "cancelled by engine stop (request stop-7) after 1.5 s at rpm 300");
}

// ---- the refusals ---------------------------------------------------------------------------

struct RefusalCase {
  const char* what;
  codec::FirmwareVersion firmware;
  std::function<void(codec::Status&)> status;
  const char* refusal;  // nullptr: the start may go ahead
};

codec::Status ready_status(codec::FirmwareVersion fw) {
  codec::Status s;
  s.starter_ready = true;
  s.interpretation = codec::interpret_flags(fw);
  return s;
}

TEST(EngineStartRefusal, FromTheFlagsOfPacket0x04AsTheFirmwareDefinesThem) {
  const RefusalCase cases[] = {
      {"stopped and ready", {1, 17}, [](codec::Status&) {}, nullptr},
      {"cranking speed", {1, 17}, [](codec::Status& s) { s.generator_rpm = 300; }, nullptr},
      {"just below running speed", {1, 17}, [](codec::Status& s) { s.generator_rpm = 1499; }, nullptr},
      {"running",
       {1, 17},
       [](codec::Status& s) { s.generator_rpm = 6000; },
       "engine already running: 6000 rpm (running from 1500 rpm)"},
      {"no speed reading", {1, 17}, [](codec::Status& s) { s.generator_rpm = 65535; }, nullptr},
      {"thermal shutdown", {1, 17}, [](codec::Status& s) { s.thermal_shutdown = true; }, "thermal shutdown"},
      {"SOA shutdown, 1.16", {1, 16}, [](codec::Status& s) { s.soa_shutdown = true; }, "safe-operating-area shutdown"},
      {"bit 6 before 1.16 is the start button", {1, 15}, [](codec::Status& s) { s.start_button = true; }, nullptr},
      {"starter not ready, 1.12",
       {1, 12},
       [](codec::Status& s) { s.starter_ready = false; },
       "the engine starter is not ready"},
      {"before 1.12 there is no ready flag", {1, 11}, [](codec::Status& s) { s.starter_ready = false; }, nullptr},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.what);
    auto s = ready_status(c.firmware);
    c.status(s);
    const auto why = refuse_start(s, c.firmware, EngineSettings{});
    if (!c.refusal) {
      EXPECT_FALSE(why) << *why;
    } else {
      ASSERT_TRUE(why);
      EXPECT_NE(why->find(c.refusal), std::string::npos) << *why;
    }
  }
}

// ---- the whole command, against a simulated PMU ------------------------------------------

class Start {
 public:
  explicit Start(std::function<void(sim::Plant&)> plant = {}, codec::FirmwareVersion fw = codec::kCurrentFirmware,
                 std::optional<std::uint32_t> cranking_time_raw = std::nullopt)
      : h(sim_bus({device(1)}), {unit(fw, cranking_time_raw)}),
        service({&h.worker()}, PolicyConfig{}, Timeouts{}, h.clock(),
                [this](const CommandReplyData& r) { replies.push_back(r); }) {
    h.pmus().with_model(1, [&](sim::PmuModel& m) {
      sim::Plant p = m.plant();
      if (plant) plant(p);
      m.set_plant(p, h.clock().steady_now());
      m.set_engine_running(false, h.clock().steady_now());
    });
    h.run_for(300ms);  // start-up reading done
    h.clear_sent();
  }

  static sim::DeviceConfig unit(codec::FirmwareVersion fw, std::optional<std::uint32_t> cranking_time_raw) {
    auto d = pmu(1, fw);
    if (cranking_time_raw) d.parameters.set_raw(codec::Parameter::CrankingTime, *cranking_time_raw);
    return d;
  }

  CommandSample command(CommandKind kind, const std::string& id) const {
    CommandSample c;
    c.request_id = id;
    c.sender = "ground";
    c.bus = "sim0";
    c.address = 1;
    c.kind = static_cast<std::uint32_t>(kind);
    c.confirm = kind == CommandKind::EngineStart;
    return c;
  }
  // Runs the bus until `id` has its final reply, or `limit` of bus time passes.
  void run_until_final(const std::string& id, std::chrono::milliseconds limit = 40s) {
    for (auto t = 0ms; t < limit && !final_of(id); t += 10ms) h.run_for(10ms);
  }
  std::optional<CommandReplyData> final_of(const std::string& id) const {
    for (const auto& r : replies)
      if (r.request_id == id && is_final(r.result)) return r;
    return std::nullopt;
  }
  std::size_t count(const std::string& id, bool final) const {
    std::size_t n = 0;
    for (const auto& r : replies) n += r.request_id == id && is_final(r.result) == final;
    return n;
  }
  std::size_t frames(std::uint8_t packet, bool with_data) const {
    std::size_t n = 0;
    for (const auto& f : h.sent_frames()) n += ((f.id >> 16) & 0xFF) == packet && (f.length > 0) == with_data;
    return n;
  }
  // Zero-length frames (gets, starts, stops) of `packet` sent to `address`.
  std::size_t frames_to(codec::PacketId packet, std::uint16_t address) const {
    std::size_t n = 0;
    for (const auto& f : h.sent_frames()) n += f.id == codec::make_id(packet, address) && f.length == 0;
    return n;
  }
  sim::EngineState engine() {
    sim::EngineState e{};
    h.pmus().with_model(1, [&](sim::PmuModel& m) { e = m.engine_state(); });
    return e;
  }

  Harness h;
  std::vector<CommandReplyData> replies;
  CommandService service;
};

TEST(EngineStart, AStartThatFiresIsCompletedOnceTheSpeedHeldWithProgressBefore) {
  Start s([](sim::Plant& p) { p.engine_starts_after = 2s; });
  const auto sent_at = s.h.clock().steady_now();
  s.service.submit(s.command(CommandKind::EngineStart, "start-1"));
  s.run_until_final("start-1");
  const auto final = s.final_of("start-1");
  ASSERT_TRUE(final);
  EXPECT_EQ(final->result, CommandResult::Completed) << final->reason;
  EXPECT_NE(final->reason.find("engine running: 6000 rpm for 1.0 s"), std::string::npos) << final->reason;
  const double took = std::chrono::duration<double>(s.h.clock().steady_now() - sent_at).count();
  EXPECT_GE(took, 3.0) << "fires at 2 s, then held for 1 s";
  EXPECT_LT(took, 3.5);
  EXPECT_EQ(s.count("start-1", true), 1u);
  // IN_PROGRESS at once and about once a second: at 0, 1, 2 (and maybe 3) s.
  EXPECT_GE(s.count("start-1", false), 3u);
  EXPECT_LE(s.count("start-1", false), 4u);
  EXPECT_EQ(s.replies.front().result, CommandResult::InProgress);
  EXPECT_EQ(s.frames(0x24, false), 1u) << "one start frame";
  EXPECT_GE(s.frames(0x04, false), 10u) << "the speed polled while it cranked and ran";
  EXPECT_EQ(s.frames(0x25, false), 0u) << "no stop after a good start";
  EXPECT_EQ(s.engine(), sim::EngineState::Running);
  s.h.run_for(2s);
  EXPECT_EQ(s.count("start-1", true), 1u) << "exactly one final reply";
}

TEST(EngineStart, AFloodedEngineFailsAfterTheCrankingTimeAndTheStarterIsStopped) {
  Start s([](sim::Plant& p) { p.engine_starts_after.reset(); });
  const auto sent_at = s.h.clock().steady_now();
  s.service.submit(s.command(CommandKind::EngineStart, "start-1"));
  s.run_until_final("start-1");
  const auto final = s.final_of("start-1");
  ASSERT_TRUE(final);
  EXPECT_EQ(final->result, CommandResult::Failed);
  EXPECT_NE(final->reason.find("no start: rpm 0 after 7.0 s (cranking time 5.0 s)"), std::string::npos)
      << final->reason;
  const double took = std::chrono::duration<double>(s.h.clock().steady_now() - sent_at).count();
  EXPECT_NEAR(took, 7.0, 0.1);
  EXPECT_EQ(s.frames(0x25, false), 1u) << "a stop in case the starter still turns";
  EXPECT_EQ(s.engine(), sim::EngineState::Stopped);
}

struct DeniedCase {
  const char* what;
  std::function<void(Start&)> set_up;
  codec::FirmwareVersion firmware;
  const char* reason;
};

TEST(EngineStart, IsDeniedWithNoStartFrameWhenItMustNotCrank) {
  const DeniedCase cases[] = {
      {"already running",
       [](Start& s) {
         s.h.pmus().with_model(1, [&](sim::PmuModel& m) { m.set_engine_running(true, s.h.clock().steady_now()); });
       },
       codec::kCurrentFirmware, "engine already running: 6000 rpm"},
      {"starter not ready",
       [](Start& s) {
         s.h.pmus().with_model(1, [&](sim::PmuModel& m) {
           auto p = m.plant();
           p.starter_ready = false;
           m.set_plant(p, s.h.clock().steady_now());
         });
       },
       codec::kCurrentFirmware, "the engine starter is not ready"},
      {"thermal shutdown",
       [](Start& s) {
         s.h.pmus().with_model(1, [&](sim::PmuModel& m) {
           auto p = m.plant();
           p.internal_temperature = 95;  // T_U is 80 degC
           m.set_plant(p, s.h.clock().steady_now());
         });
         s.h.run_for(100ms);
       },
       codec::kCurrentFirmware, "thermal shutdown"},
      {"SOA shutdown",
       [](Start& s) {
         s.h.pmus().with_model(1, [&](sim::PmuModel& m) {
           auto p = m.plant();
           p.soa_shutdown = true;
           m.set_plant(p, s.h.clock().steady_now());
         });
       },
       codec::kCurrentFirmware, "safe-operating-area shutdown"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.what);
    Start s({}, c.firmware);
    c.set_up(s);
    s.h.clear_sent();
    s.service.submit(s.command(CommandKind::EngineStart, "start-1"));
    s.run_until_final("start-1", 5s);
    const auto final = s.final_of("start-1");
    ASSERT_TRUE(final);
    EXPECT_EQ(final->result, CommandResult::Denied);
    EXPECT_NE(final->reason.find(c.reason), std::string::npos) << final->reason;
    EXPECT_EQ(s.frames(0x24, false), 0u) << "no start frame";
    EXPECT_EQ(s.count("start-1", false), 0u) << "no progress for a refused start";
  }
}

TEST(EngineStart, AStopWhileCrankingEndsTheStartWhichSaysSo) {
  Start s([](sim::Plant& p) { p.engine_starts_after = 4s; });
  s.service.submit(s.command(CommandKind::EngineStart, "start-1"));
  s.h.run_for(1500ms);
  ASSERT_EQ(s.engine(), sim::EngineState::Cranking);
  s.service.submit(s.command(CommandKind::EngineStop, "stop-1"));
  s.run_until_final("stop-1", 2s);
  ASSERT_TRUE(s.final_of("stop-1"));
  EXPECT_EQ(s.final_of("stop-1")->result, CommandResult::Completed);
  const auto start = s.final_of("start-1");
  ASSERT_TRUE(start) << "the start is answered when the stop goes out";
  EXPECT_EQ(start->result, CommandResult::Failed);
  EXPECT_NE(start->reason.find("cancelled by engine stop (request stop-1)"), std::string::npos) << start->reason;
  EXPECT_EQ(s.engine(), sim::EngineState::Stopped);
  const auto replies = s.replies.size();
  s.h.run_for(8s);
  EXPECT_EQ(s.replies.size(), replies) << "nothing more from the ended start";
  EXPECT_EQ(s.count("start-1", true), 1u);
}

TEST(EngineStart, ASecondStartWhileOneRunsIsDeniedAndAResendIsAnsweredOnce) {
  Start s([](sim::Plant& p) { p.engine_starts_after = 2s; });
  s.service.submit(s.command(CommandKind::EngineStart, "start-1"));
  s.h.run_for(500ms);
  s.service.submit(s.command(CommandKind::EngineStart, "start-2"));
  s.service.submit(s.command(CommandKind::EngineStart, "start-1"));  // the same request again
  s.run_until_final("start-2", 1s);
  ASSERT_TRUE(s.final_of("start-2"));
  EXPECT_EQ(s.final_of("start-2")->result, CommandResult::Denied);
  EXPECT_NE(s.final_of("start-2")->reason.find("an engine start is in progress (request start-1)"), std::string::npos);
  s.run_until_final("start-1");
  ASSERT_TRUE(s.final_of("start-1"));
  EXPECT_EQ(s.final_of("start-1")->result, CommandResult::Completed);
  EXPECT_EQ(s.count("start-1", true), 2u) << "the resend gets the first one's final reply";
  EXPECT_EQ(s.frames(0x24, false), 1u) << "never started twice";
}

TEST(EngineStart, AUnitThatFallsSilentWhileStartingTimesOut) {
  Start s([](sim::Plant& p) { p.engine_starts_after.reset(); });
  s.service.submit(s.command(CommandKind::EngineStart, "start-1"));
  s.h.run_for(1s);
  s.h.pmus().with_model(1, [](sim::PmuModel& m) {
    sim::Faults f;
    f.silent = true;
    m.set_faults(f);
  });
  s.run_until_final("start-1", 5s);
  const auto final = s.final_of("start-1");
  ASSERT_TRUE(final);
  EXPECT_EQ(final->result, CommandResult::Timeout);
  EXPECT_NE(final->reason.find("stopped answering while its engine was starting"), std::string::npos);
  EXPECT_EQ(s.frames(0x25, false), 1u);
}

// A CT of 0: the unit never lets go of the starter by itself, so only a stop that reaches
// it ends the cranking (docs/safety.md H5).
constexpr std::uint32_t kNoCrankingTimeout = 0;

// docs/safety.md H4, H10: our own address change while the start is verified. The start goes
// on reading the speed of this unit at its new address, and its stop goes there.
TEST(EngineStart, AUnitMovedByCommandWhileCrankingIsStillTheOneWatchedAndItsStopFollowsIt) {
  Start s([](sim::Plant& p) { p.engine_starts_after.reset(); }, codec::kCurrentFirmware, kNoCrankingTimeout);
  s.service.submit(s.command(CommandKind::EngineStart, "start-1"));
  s.h.run_for(1s);
  ASSERT_EQ(s.engine(), sim::EngineState::Cranking);
  auto move = s.command(CommandKind::SetParameter, "move-1");
  move.parameter = "can_address";
  move.value = 7;
  move.confirm = true;
  s.service.submit(move);
  s.run_until_final("move-1", 5s);
  ASSERT_TRUE(s.final_of("move-1"));
  ASSERT_EQ(s.final_of("move-1")->result, CommandResult::Completed) << s.final_of("move-1")->reason;
  s.h.clear_sent();

  s.run_until_final("start-1");
  const auto final = s.final_of("start-1");
  ASSERT_TRUE(final);
  EXPECT_EQ(final->result, CommandResult::Failed) << final->reason;
  EXPECT_NE(final->reason.find("no start: rpm 300 after 27.5 s"), std::string::npos)
      << "the cranking speed read at the new address: " << final->reason;
  EXPECT_GE(s.frames_to(codec::PacketId::Status, 7), 10u) << "the speed polled where the unit is";
  EXPECT_EQ(s.frames_to(codec::PacketId::Status, 1), 0u) << "nothing to the address it left";
  EXPECT_EQ(s.frames_to(codec::PacketId::EngineStop, 7), 1u);
  EXPECT_EQ(s.frames_to(codec::PacketId::EngineStop, 1), 0u);
  EXPECT_EQ(s.engine(), sim::EngineState::Stopped) << "the stop reached the unit";
}

// docs/safety.md H4, H5: another tool moves the unit while it cranks. It falls silent at its
// address, so the start ends and its stop goes there, where the unit no longer is; once the
// service finds the unit at its new address, the stop is sent again there.
TEST(EngineStart, AUnitThatMovesByItselfWhileCrankingIsSentTheStopAgainWhereItIsFound) {
  Start s([](sim::Plant& p) { p.engine_starts_after.reset(); }, codec::kCurrentFirmware, kNoCrankingTimeout);
  s.service.submit(s.command(CommandKind::EngineStart, "start-1"));
  s.h.run_for(1s);
  ASSERT_EQ(s.engine(), sim::EngineState::Cranking);
  auto tool = s.h.network().attach("other-tool");
  ASSERT_TRUE(tool->send(*codec::encode_parameter_reply(codec::Parameter::CanAddress, 9, 1), 100ms).ok());
  s.run_until_final("start-1", 5s);
  const auto final = s.final_of("start-1");
  ASSERT_TRUE(final);
  EXPECT_EQ(final->result, CommandResult::Timeout) << final->reason;
  EXPECT_EQ(s.frames_to(codec::PacketId::EngineStop, 1), 1u);
  EXPECT_EQ(s.engine(), sim::EngineState::Cranking) << "a stop to address 1 does not reach it";

  s.h.run_for(10s);
  ASSERT_EQ(s.h.worker().addresses(), (std::vector<std::uint16_t>{9})) << "found by its serial";
  EXPECT_EQ(s.frames_to(codec::PacketId::EngineStop, 9), 1u);
  EXPECT_EQ(s.engine(), sim::EngineState::Stopped);
}

// docs/safety.md H5, H9: the start frame is bound by the request's expiry like the check
// before it. A check answered only after the expiry (its first answer late, past the reply
// timeout) must not crank an engine whose caller has given up.
TEST(EngineStart, NoStartFrameAfterTheExpiryEvenWhenTheCheckIsAnsweredLate) {
  Start s;
  s.h.pmus().with_model(1, [](sim::PmuModel& m) {
    auto f = m.faults();
    f.delay = std::chrono::milliseconds(300);  // past the 250 ms reply timeout
    m.set_faults(f);
  });
  auto start = s.command(CommandKind::EngineStart, "start-1");
  start.expires_at = static_cast<std::uint64_t>(
      std::chrono::duration_cast<std::chrono::nanoseconds>((s.h.clock().system_now() + 200ms).time_since_epoch())
          .count());
  s.service.submit(start);
  s.run_until_final("start-1", 5s);
  const auto final = s.final_of("start-1");
  ASSERT_TRUE(final);
  EXPECT_EQ(final->result, CommandResult::Rejected) << final->reason;
  EXPECT_EQ(final->reason, "expired before it could be sent");
  EXPECT_EQ(s.frames(0x24, false), 0u) << "no start frame";
  EXPECT_EQ(s.engine(), sim::EngineState::Stopped);
}

}  // namespace
}  // namespace pmu::service::test
