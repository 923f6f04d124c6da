// COMMAND_LONG under a fake clock: what each command means to the service, the acks of an
// engine start, retransmissions executed once, a stop that always goes through, confirm
// rules, floods.
#include <gtest/gtest.h>

#include <limits>

#include "pmu/mavlink_commands/command_handler.hpp"

namespace pmu::mavlink_commands {
namespace {

using namespace std::chrono_literals;
using service::CommandResult;
using service::ConfirmRule;
namespace result = mavlink::mav_result;
namespace cmd = mavlink::mav_cmd;

const Time t0 = Time{} + 1h;
const Sender qgc{255, 190};
const Sender mp{255, 0};

ConfirmSet confirming(std::initializer_list<ConfirmRule> rules) {
  ConfirmSet c{};
  for (const auto r : rules) c[static_cast<std::size_t>(r)] = true;
  return c;
}

CommandHandler handler(ConfirmSet confirm = confirming({ConfirmRule::EngineStart, ConfirmRule::Reset,
                                                        ConfirmRule::DisableAvionics}),
                       std::size_t pmus = 2) {
  CommandConfig c;
  c.pmu_count = pmus;
  c.confirm = confirm;
  return CommandHandler(c);
}

mavlink::CommandLong command(std::uint16_t id, std::array<float, 7> p = {}, std::uint8_t confirmation = 0) {
  mavlink::CommandLong m;
  m.target_system = 1;
  m.target_component = 180;
  m.command = id;
  m.confirmation = confirmation;
  m.param = p;
  return m;
}
mavlink::CommandLong start(std::uint8_t confirmation = 0) { return command(cmd::kDoEngineControl, {1}, confirmation); }
mavlink::CommandLong stop(std::uint8_t confirmation = 0) { return command(cmd::kDoEngineControl, {0}, confirmation); }

std::string texts(const Output& out) {
  std::string t;
  for (const auto& s : out.texts) t += s.text;
  return t;
}

TEST(CommandMeaning, EachCommandIsTheServiceCommandItMeans) {
  struct Case {
    const char* what;
    mavlink::CommandLong m;
    std::size_t kind;  // CommandAction's index
    std::size_t pmu;
  };
  using service::CommandKind;
  const Case cases[] = {
      {"start", start(), static_cast<std::size_t>(CommandKind::EngineStart), 0},
      {"stop PMU 2", command(cmd::kDoEngineControl, {0, 0, 0, 0, 0, 0, 2}),
       static_cast<std::size_t>(CommandKind::EngineStop), 1},
      {"payload on", command(cmd::kDoSetRelay, {1, 1}), static_cast<std::size_t>(CommandKind::EnableOutputs), 0},
      {"charger_b off", command(cmd::kDoSetRelay, {3, 0}), static_cast<std::size_t>(CommandKind::DisableOutputs), 0},
      {"avionics off", command(cmd::kDoSetRelay, {0, 0}), static_cast<std::size_t>(CommandKind::DisableOutputs), 0},
      {"generation off", command(cmd::kDoSetRelay, {4, 0, 0, 0, 0, 0, 1}),
       static_cast<std::size_t>(CommandKind::SetGeneration), 0},
      {"reset", command(cmd::kPreflightRebootShutdown, {0, 0, 1, 180}), static_cast<std::size_t>(CommandKind::Reset),
       0},
      {"reset all components", command(cmd::kPreflightRebootShutdown, {0, 0, 1, 0}),
       static_cast<std::size_t>(CommandKind::Reset), 0},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.what);
    auto h = handler();
    const auto out = h.on_command_long(qgc, c.m, t0);
    ASSERT_TRUE(out.command);
    EXPECT_EQ(out.command->action.index(), c.kind);
    EXPECT_EQ(out.command->pmu, c.pmu);
  }
  auto h = handler();
  const auto payload = h.on_command_long(qgc, command(cmd::kDoSetRelay, {1, 1}), t0);
  EXPECT_EQ(std::get<service::action::EnableOutputs>(payload.command->action).mask, 0x02);
  const auto gen = h.on_command_long(qgc, command(cmd::kDoSetRelay, {4, 1}), t0);
  EXPECT_TRUE(std::get<service::action::SetGeneration>(gen.command->action).enable);
}

TEST(CommandMeaning, BadParamsAndOtherCommandsAreAnsweredHereAndNeverSent) {
  struct Case {
    const char* what;
    mavlink::CommandLong m;
    std::uint8_t result;
  };
  const Case cases[] = {
      {"engine param1 2", command(cmd::kDoEngineControl, {2}), result::kDenied},
      {"cold start", command(cmd::kDoEngineControl, {1, 1}), result::kDenied},
      {"height delay", command(cmd::kDoEngineControl, {1, 0, 30}), result::kDenied},
      {"no PMU 3", command(cmd::kDoEngineControl, {1, 0, 0, 0, 0, 0, 3}), result::kDenied},
      {"PMU 1.5", command(cmd::kDoSetRelay, {1, 1, 0, 0, 0, 0, 1.5F}), result::kDenied},
      {"relay 5", command(cmd::kDoSetRelay, {5, 1}), result::kDenied},
      {"relay setting 2", command(cmd::kDoSetRelay, {1, 2}), result::kDenied},
      {"relay NaN", command(cmd::kDoSetRelay, {std::numeric_limits<float>::quiet_NaN(), 1}), result::kDenied},
      {"reboot autopilot", command(cmd::kPreflightRebootShutdown, {1}), result::kUnsupported},
      {"reboot camera", command(cmd::kPreflightRebootShutdown, {0, 0, 1, 100}), result::kUnsupported},
      {"shutdown", command(cmd::kPreflightRebootShutdown, {0, 0, 2, 180}), result::kUnsupported},
      // The bridge answers these two before the handler sees a command: here they are unknown.
      {"message interval", command(cmd::kSetMessageInterval, {373, 100000}), result::kUnsupported},
      {"pre-arm checks", command(cmd::kRunPrearmChecks), result::kUnsupported},
      {"takeoff", command(22), result::kUnsupported},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.what);
    auto h = handler();
    const auto out = h.on_command_long(qgc, c.m, t0);
    EXPECT_FALSE(out.command);
    ASSERT_EQ(out.acks.size(), 1U);
    EXPECT_EQ(out.acks[0].result, c.result);
    EXPECT_EQ(out.acks[0].command, c.m.command);
    EXPECT_EQ(out.acks[0].target_system, qgc.system);
    EXPECT_EQ(out.acks[0].target_component, qgc.component);
  }
}

// The service's final result and the ack that ends an engine start.
struct StartCase {
  const char* name;
  CommandResult result;
  std::uint8_t ack;
};
class EngineStartAck : public testing::TestWithParam<StartCase> {};

TEST_P(EngineStartAck, InProgressWithProgressThenTheFinalResult) {
  const auto c = GetParam();
  auto h = handler();
  const auto out = h.on_command_long(qgc, start(), t0);
  ASSERT_TRUE(out.command);
  EXPECT_TRUE(out.command->confirm) << "engine_start is configured to be confirmed";
  ASSERT_EQ(out.acks.size(), 1U);
  EXPECT_EQ(out.acks[0].result, result::kInProgress);
  EXPECT_EQ(out.acks[0].progress, 0);
  const auto tag = out.command->tag;
  const auto p1 = h.on_reply(tag, CommandResult::InProgress, "cranking: 1.0 s of up to 5.0 s, 300 rpm", t0 + 1s);
  ASSERT_EQ(p1.acks.size(), 1U);
  EXPECT_EQ(p1.acks[0].result, result::kInProgress);
  EXPECT_EQ(p1.acks[0].progress, 20);
  const auto done = h.on_reply(tag, c.result, "engine running: 1800 rpm for 1.0 s", t0 + 3s);
  ASSERT_EQ(done.acks.size(), 1U);
  EXPECT_EQ(done.acks[0].result, c.ack);
  EXPECT_EQ(done.acks[0].command, cmd::kDoEngineControl);
  EXPECT_EQ(done.texts.empty(), c.result == CommandResult::Completed);
  EXPECT_TRUE(h.on_reply(tag, c.result, "again", t0 + 4s).acks.empty());
  EXPECT_TRUE(h.poll(t0 + 60s).acks.empty()) << "answered: no timeout";
}

INSTANTIATE_TEST_SUITE_P(Results, EngineStartAck,
                         testing::Values(StartCase{"completed", CommandResult::Completed, result::kAccepted},
                                         StartCase{"failed", CommandResult::Failed, result::kFailed},
                                         StartCase{"timeout", CommandResult::Timeout, result::kFailed},
                                         StartCase{"denied", CommandResult::Denied, result::kDenied},
                                         StartCase{"rejected", CommandResult::Rejected, result::kDenied},
                                         StartCase{"unsupported", CommandResult::Unsupported, result::kUnsupported}),
                         [](const auto& test_info) { return std::string(test_info.param.name); });

TEST(EngineStart, NoReplyIsFailedAtTheTimeout) {
  auto h = handler();
  ASSERT_TRUE(h.on_command_long(qgc, start(), t0).command);
  const auto before = h.poll(t0 + 39s);
  ASSERT_EQ(before.acks.size(), 1U);
  EXPECT_EQ(before.acks[0].result, result::kInProgress) << "still waiting";
  const auto out = h.poll(t0 + 40s);
  ASSERT_EQ(out.acks.size(), 1U);
  EXPECT_EQ(out.acks[0].result, result::kFailed);
  EXPECT_FALSE(texts(out).empty());
}

TEST(EngineStart, InProgressIsRepeatedEverySecondBetweenTheServicesReplies) {
  auto h = handler();
  const auto out = h.on_command_long(qgc, start(), t0);
  ASSERT_TRUE(out.command);
  EXPECT_TRUE(h.poll(t0 + 999ms).acks.empty());
  const auto repeated = h.poll(t0 + 1s);
  ASSERT_EQ(repeated.acks.size(), 1U);
  EXPECT_EQ(repeated.acks[0].result, result::kInProgress);
  EXPECT_EQ(repeated.acks[0].target_component, qgc.component);
  h.on_reply(out.command->tag, CommandResult::InProgress, "cranking: 1.5 s of up to 5.0 s", t0 + 1500ms);
  EXPECT_TRUE(h.poll(t0 + 2s).acks.empty()) << "the service's own came 0.5 s ago";
  const auto again = h.poll(t0 + 2500ms);
  ASSERT_EQ(again.acks.size(), 1U);
  EXPECT_EQ(again.acks[0].progress, 30);
  h.on_reply(out.command->tag, CommandResult::Completed, "engine running", t0 + 3s);
  EXPECT_TRUE(h.poll(t0 + 5s).acks.empty());
  // Other commands are not kept waiting long: no IN_PROGRESS for them.
  ASSERT_TRUE(h.on_command_long(qgc, command(cmd::kDoSetRelay, {1, 1}), t0 + 6s).command);
  EXPECT_TRUE(h.poll(t0 + 8s).acks.empty());
}

TEST(StartProgress, FromTheServicesReason) {
  EXPECT_EQ(start_progress("cranking: 2.5 s of up to 5.0 s, 300 rpm"), 50);
  EXPECT_EQ(start_progress("running, holding: 4.9 s of up to 5.0 s"), 98);
  EXPECT_EQ(start_progress("running, holding: 9.0 s of up to 5.0 s"), 99);
  EXPECT_EQ(start_progress("cranking: 1.0 s of up to 0.0 s"), 255);
  EXPECT_EQ(start_progress("checking"), 255);
  EXPECT_EQ(start_progress(""), 255);
}

TEST(Retransmission, WhileRunningAnsweredWithTheFirstsStateNeverSentAgain) {
  auto h = handler();
  const auto first = h.on_command_long(qgc, start(), t0);
  ASSERT_TRUE(first.command);
  h.on_reply(first.command->tag, CommandResult::InProgress, "cranking: 1.0 s of up to 4.0 s", t0 + 1s);
  for (const std::uint8_t confirmation : {std::uint8_t{1}, std::uint8_t{2}, std::uint8_t{0}}) {
    const auto again = h.on_command_long(qgc, start(confirmation), t0 + 2s);
    EXPECT_FALSE(again.command) << "confirmation " << int{confirmation};
    ASSERT_EQ(again.acks.size(), 1U);
    EXPECT_EQ(again.acks[0].result, result::kInProgress);
    EXPECT_EQ(again.acks[0].progress, 25);
  }
  EXPECT_EQ(h.counters().sent, 1U);
  EXPECT_EQ(h.counters().retransmissions, 3U);
}

TEST(Retransmission, AfterTheAnswerWithConfirmationAboveZeroGetsTheAnswerAgain) {
  auto h = handler();
  const auto first = h.on_command_long(qgc, command(cmd::kDoSetRelay, {1, 1}), t0);
  ASSERT_TRUE(first.command);
  h.on_reply(first.command->tag, CommandResult::Completed, "", t0 + 100ms);
  const auto again = h.on_command_long(qgc, command(cmd::kDoSetRelay, {1, 1}, 1), t0 + 1s);
  EXPECT_FALSE(again.command);
  ASSERT_EQ(again.acks.size(), 1U);
  EXPECT_EQ(again.acks[0].result, result::kAccepted);
  // Another sender's same command, a first transmission later on, or a retransmission after
  // the window are new commands.
  EXPECT_TRUE(h.on_command_long(mp, command(cmd::kDoSetRelay, {1, 1}, 1), t0 + 1s).command);
  EXPECT_TRUE(h.on_command_long(qgc, command(cmd::kDoSetRelay, {1, 1}, 0), t0 + 2s).command);
  auto late = handler();
  const auto f = late.on_command_long(qgc, command(cmd::kDoSetRelay, {1, 1}), t0);
  late.on_reply(f.command->tag, CommandResult::Completed, "", t0);
  late.poll(t0 + 11s);
  EXPECT_TRUE(late.on_command_long(qgc, command(cmd::kDoSetRelay, {1, 1}, 1), t0 + 11s).command);
}

TEST(Retransmission, ADeniedCommandRetransmittedIsDeniedAgainFromMemory) {
  auto h = handler(confirming({}));
  const auto first = h.on_command_long(qgc, start(), t0);
  EXPECT_FALSE(first.command);
  EXPECT_EQ(first.acks.at(0).result, result::kDenied);
  const auto again = h.on_command_long(qgc, start(1), t0 + 1s);
  EXPECT_EQ(again.acks.at(0).result, result::kDenied);
  EXPECT_TRUE(again.texts.empty()) << "the reason went with the first answer";
}

TEST(EngineStop, DuringAPendingStartIsSentAtOnce) {
  auto h = handler();
  ASSERT_TRUE(h.on_command_long(qgc, start(), t0).command);
  const auto s = h.on_command_long(qgc, stop(), t0 + 500ms);
  ASSERT_TRUE(s.command);
  EXPECT_TRUE(std::holds_alternative<service::action::EngineStop>(s.command->action));
  EXPECT_FALSE(s.command->confirm);
}

TEST(EngineStop, IsNeverRefusedByRulesOrTheFloodBound) {
  CommandConfig c;
  c.pmu_count = 1;
  c.max_pending = 2;
  CommandHandler h(c);  // confirms no rule
  ASSERT_TRUE(h.on_command_long(qgc, command(cmd::kDoSetRelay, {1, 1}), t0).command);
  ASSERT_TRUE(h.on_command_long(qgc, command(cmd::kDoSetRelay, {2, 1}), t0).command);
  const auto busy = h.on_command_long(qgc, command(cmd::kDoSetRelay, {3, 1}), t0);
  EXPECT_FALSE(busy.command);
  EXPECT_EQ(busy.acks.at(0).result, result::kTemporarilyRejected);
  EXPECT_TRUE(h.on_command_long(qgc, stop(), t0).command);
  EXPECT_TRUE(h.on_command_long(mp, stop(), t0).command);
  EXPECT_EQ(h.counters().flood_rejected, 1U);
}

TEST(EngineStop, AStopAfterAnAnsweredStopIsSentAgainAndARunningOneIsNotLost) {
  auto h = handler();
  const auto s1 = h.on_command_long(qgc, stop(), t0);
  ASSERT_TRUE(s1.command);
  const auto retransmitted = h.on_command_long(qgc, stop(1), t0 + 200ms);
  EXPECT_FALSE(retransmitted.command) << "the first is still going out";
  ASSERT_EQ(retransmitted.acks.size(), 1U);
  h.on_reply(s1.command->tag, CommandResult::Completed, "stop sent", t0 + 300ms);
  EXPECT_TRUE(h.on_command_long(qgc, stop(2), t0 + 1s).command) << "answered: sent again";
  EXPECT_EQ(h.counters().stops, 2U);
}

TEST(ConfirmRules, UnconfiguredRulesAreDeniedNamingTheRuleConfiguredOnesSentConfirmed) {
  struct Case {
    const char* what;
    mavlink::CommandLong m;
    ConfirmRule rule;
  };
  const Case cases[] = {
      {"start", start(), ConfirmRule::EngineStart},
      {"reset", command(cmd::kPreflightRebootShutdown, {0, 0, 1, 180}), ConfirmRule::Reset},
      {"avionics off", command(cmd::kDoSetRelay, {0, 0}), ConfirmRule::DisableAvionics},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.what);
    auto none = handler(confirming({}));
    const auto denied = none.on_command_long(qgc, c.m, t0);
    EXPECT_FALSE(denied.command);
    EXPECT_EQ(denied.acks.at(0).result, result::kDenied);
    EXPECT_NE(texts(denied).find("rule " + std::string(service::to_string(c.rule))), std::string::npos)
        << texts(denied);
    auto some = handler(confirming({c.rule}));
    const auto sent = some.on_command_long(qgc, c.m, t0);
    ASSERT_TRUE(sent.command);
    EXPECT_TRUE(sent.command->confirm);
  }
  // No rule: sent unconfirmed.
  auto none = handler(confirming({}));
  const auto payload = none.on_command_long(qgc, command(cmd::kDoSetRelay, {1, 0}), t0);
  ASSERT_TRUE(payload.command);
  EXPECT_FALSE(payload.command->confirm);
}

TEST(ServiceReplies, DeniedByTheServiceSaysItsReason) {
  auto h = handler();
  const auto out = h.on_command_long(qgc, command(cmd::kDoSetRelay, {1, 1}), t0);
  const auto denied =
      h.on_reply(out.command->tag, CommandResult::Denied, "configuration of can0/1 held by an apply", t0 + 100ms);
  EXPECT_EQ(denied.acks.at(0).result, result::kDenied);
  EXPECT_NE(texts(denied).find("held by an apply"), std::string::npos);
  EXPECT_TRUE(h.on_reply(999, CommandResult::Completed, "", t0).acks.empty());
  EXPECT_EQ(h.counters().replies_unmatched, 1U);
}

TEST(Flood, ManyCommandsAreCountedBoundedAndEachSentAtMostOnce) {
  auto h = handler();
  std::size_t sent = 0;
  for (int i = 0; i < 1000; ++i) {
    const auto m = command(cmd::kDoSetRelay, {static_cast<float>(i % 4), 1, 0, 0, 0, 0, static_cast<float>(i % 3)},
                           static_cast<std::uint8_t>(i % 7));
    const auto out = h.on_command_long(qgc, m, t0 + std::chrono::milliseconds(i));
    EXPECT_EQ(out.acks.size() + (out.command ? 1 : 0), 1U) << "exactly one answer or one command";
    if (out.command) ++sent;
  }
  EXPECT_EQ(sent, 12U) << "4 instances x 3 PMU numbers, each once";
  EXPECT_EQ(h.counters().received, 1000U);
  EXPECT_EQ(h.counters().retransmissions, 988U);
}

}  // namespace
}  // namespace pmu::mavlink_commands
