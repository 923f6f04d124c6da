// The hot standby's record of the bus owner's commands (failover_record.hpp) on a fake clock:
// what a takeover does with each request after what the standby saw, which frames count as a
// command to a PMU, and the record's bounds (design.md "Hot standby", docs/safety.md H4, H8).
#include <gtest/gtest.h>

#include <functional>
#include <string>
#include <vector>

#include "pmu/dispatch/failover_record.hpp"
#include "support/pmu_frames.hpp"

namespace pmu::service::test {
namespace {

using namespace std::chrono_literals;
using codec::test::pmu_frame;
using Action = FailoverRecord::Action;

const auto kWall = std::chrono::system_clock::time_point{} + std::chrono::hours(24 * 365 * 50);
const SteadyTime kStart = SteadyTime{} + 1000s;

Now at(std::chrono::milliseconds t) { return Now{kWall + t, kStart + t}; }

CommandSample sample(CommandKind kind, std::string id = "r-1", std::uint16_t address = 1) {
  CommandSample s;
  s.request_id = std::move(id);
  s.sender = "client";
  s.vehicle = "v";
  s.bus = "can0";
  s.address = address;
  s.kind = static_cast<std::uint32_t>(kind);
  return s;
}

CommandSample set_avionics(std::string id = "r-1") {
  auto s = sample(CommandKind::SetParameter, std::move(id));
  s.parameter = "avionics_voltage";
  s.value = 24;
  return s;
}

CommandReplyData reply_to(const CommandSample& s, CommandResult result, std::string reason = "done") {
  CommandReplyData r;
  r.request_id = s.request_id;
  r.bus = s.bus;
  r.address = s.address;
  r.kind = static_cast<CommandKind>(s.kind);
  r.result = result;
  r.reason = std::move(reason);
  return r;
}

std::string key_of(const CommandSample& s) { return s.sender + '\0' + s.request_id; }

struct TakeoverCase {
  const char* what;
  CommandSample request;
  // What the standby sees after the request arrived at 0 ms (the record is given it first).
  std::function<void(FailoverRecord&, const CommandSample&)> saw;
  std::chrono::milliseconds takeover_at;
  Action expected;
  const char* reason_has;  // in the final reply (Unknown, Expired, Answered)
};

TEST(FailoverRecord, EachRequestIsSettledAfterWhatTheStandbySaw) {
  const auto nothing = [](FailoverRecord&, const CommandSample&) {};
  const TakeoverCase cases[] = {
      {"never seen on the bus: runs", set_avionics(), nothing, 500ms, Action::Run, ""},
      {"its frame heard, no reply: outcome unknown", set_avionics(),
       [](FailoverRecord& r, const CommandSample&) { r.heard("can0", pmu_frame(0x10, 1, {240}), kStart + 20ms); },
       500ms, Action::Unknown, "outcome unknown: its frames were on the bus"},
      {"the owner's final reply: answered with it", set_avionics(),
       [](FailoverRecord& r, const CommandSample& s) {
         r.heard("can0", pmu_frame(0x10, 1, {240}), kStart + 20ms);
         r.peer_reply(reply_to(s, CommandResult::Completed, "avionics 24 V read back"), kStart + 40ms);
       },
       500ms, Action::Answered, "avionics 24 V read back"},
      {"the owner's progress only: outcome unknown", sample(CommandKind::EngineStart),
       [](FailoverRecord& r, const CommandSample& s) {
         r.peer_reply(reply_to(s, CommandResult::InProgress, "cranking"), kStart + 40ms);
       },
       500ms, Action::Unknown, "reported it in progress"},
      {"an ENGINE_STOP heard on the bus: runs again", sample(CommandKind::EngineStop),
       [](FailoverRecord& r, const CommandSample&) { r.heard("can0", pmu_frame(0x25, 1, {}), kStart + 20ms); }, 500ms,
       Action::Run, ""},
      {"an ENGINE_STOP long expired: runs", sample(CommandKind::EngineStop), nothing, 30s, Action::Run, ""},
      {"expired before the takeover: rejected, not run", set_avionics(), nothing, 10001ms, Action::Expired,
       "expired before it could be sent"},
      {"a read-only GET whose frames were heard: runs (reading twice changes nothing)", sample(CommandKind::Get),
       [](FailoverRecord& r, const CommandSample&) { r.heard("can0", pmu_frame(0x10, 1, {}), kStart + 20ms); }, 500ms,
       Action::Run, ""},
      {"a frame of another packet to the device: runs", set_avionics(),
       [](FailoverRecord& r, const CommandSample&) { r.heard("can0", pmu_frame(0x11, 1, {200}), kStart + 20ms); },
       500ms, Action::Run, ""},
      {"the same frame to another device: runs", set_avionics(),
       [](FailoverRecord& r, const CommandSample&) { r.heard("can0", pmu_frame(0x10, 2, {240}), kStart + 20ms); },
       500ms, Action::Run, ""},
      {"the same frame on another bus: runs", set_avionics(),
       [](FailoverRecord& r, const CommandSample&) { r.heard("can1", pmu_frame(0x10, 1, {240}), kStart + 20ms); },
       500ms, Action::Run, ""},
      {"the device answering a get heard before it: runs", set_avionics(),
       [](FailoverRecord& r, const CommandSample&) {
         r.heard("can0", pmu_frame(0x10, 1, {}), kStart + 20ms);
         r.heard("can0", pmu_frame(0x10, 1, {240}), kStart + 22ms);
       },
       500ms, Action::Run, ""},
      {"a reply to another request id: runs", set_avionics(),
       [](FailoverRecord& r, const CommandSample&) {
         r.peer_reply(reply_to(set_avionics("r-2"), CommandResult::Completed), kStart + 40ms);
       },
       500ms, Action::Run, ""},
      {"a reply naming another device: runs", set_avionics(),
       [](FailoverRecord& r, const CommandSample& s) {
         auto other = reply_to(s, CommandResult::Completed);
         other.address = 7;
         r.peer_reply(other, kStart + 40ms);
       },
       500ms, Action::Run, ""},
      {"a reset heard: outcome unknown", sample(CommandKind::Reset),
       [](FailoverRecord& r, const CommandSample&) { r.heard("can0", pmu_frame(0x26, 1, {}), kStart + 20ms); }, 500ms,
       Action::Unknown, "outcome unknown"},
      {"outputs disabled heard: outcome unknown",
       [] {
         auto s = sample(CommandKind::DisableOutputs);
         s.outputs = 2;
         return s;
       }(),
       [](FailoverRecord& r, const CommandSample&) { r.heard("can0", pmu_frame(0x22, 1, {2}), kStart + 20ms); }, 500ms,
       Action::Unknown, "outcome unknown"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.what);
    FailoverRecord record(Lifetimes{});
    record.request(key_of(c.request), c.request, at(0ms));
    c.saw(record, c.request);
    const auto verdicts = record.take_over(kStart + c.takeover_at);
    ASSERT_EQ(verdicts.size(), 1u);
    const auto& v = verdicts[0];
    EXPECT_EQ(v.key, key_of(c.request));
    EXPECT_EQ(v.fingerprint, content_fingerprint(c.request));
    EXPECT_EQ(v.action, c.expected);
    EXPECT_EQ(v.reply.request_id, c.request.request_id);
    if (c.expected == Action::Run) {
      ASSERT_TRUE(v.sample);
      EXPECT_EQ(v.sample->request_id, c.request.request_id);
    } else {
      EXPECT_TRUE(is_final(v.reply.result));
      EXPECT_NE(v.reply.reason.find(c.reason_has), std::string::npos) << v.reply.reason;
    }
    if (c.expected == Action::Unknown) {
      EXPECT_EQ(v.reply.result, CommandResult::Failed);
    }
    if (c.expected == Action::Expired) {
      EXPECT_EQ(v.reply.result, CommandResult::Rejected);
    }
    EXPECT_TRUE(record.empty()) << "a takeover settles every request once";
  }
}

TEST(FailoverRecord, WhatArrivesBeforeItsRequestStillCounts) {
  // The other host may see the frame, and even the reply, before this one gets the sample.
  FailoverRecord record(Lifetimes{});
  const auto heard_first = set_avionics("heard");
  const auto answered_first = sample(CommandKind::Reset, "answered");
  record.heard("can0", pmu_frame(0x10, 1, {240}), kStart);
  record.peer_reply(reply_to(answered_first, CommandResult::Completed, "reset"), kStart + 10ms);
  record.request(key_of(heard_first), heard_first, at(300ms));
  record.request(key_of(answered_first), answered_first, at(300ms));
  // A frame an earlier request explains is that one's, not a later one's.
  const auto explained = sample(CommandKind::Reset, "explained");
  const auto after_it = sample(CommandKind::Reset, "after-it");
  record.request(key_of(explained), explained, at(400ms));
  record.heard("can0", pmu_frame(0x26, 1, {}), kStart + 410ms);
  record.request(key_of(after_it), after_it, at(420ms));
  // Heard longer than the slack before the request: another command's.
  const auto long_after = set_avionics("later");
  record.request(key_of(long_after), long_after, at(1500ms));
  const auto verdicts = record.take_over(kStart + 2s);
  ASSERT_EQ(verdicts.size(), 5u);
  EXPECT_EQ(verdicts[0].action, Action::Unknown);
  EXPECT_EQ(verdicts[1].action, Action::Answered);
  EXPECT_EQ(verdicts[1].reply.reason, "reset");
  EXPECT_EQ(verdicts[2].action, Action::Unknown);
  EXPECT_EQ(verdicts[3].action, Action::Run);
  EXPECT_EQ(verdicts[3].reply.request_id, "after-it");
  EXPECT_EQ(verdicts[4].action, Action::Run);
}

TEST(FailoverRecord, AResendChangesNothingAndARelinquishedRequestIsUnknown) {
  FailoverRecord record(Lifetimes{});
  const auto s = set_avionics();
  record.request(key_of(s), s, at(0ms));
  auto resend = s;
  resend.expires_at = 1;  // a resend's other deadline is the same request
  record.request(key_of(resend), resend, at(100ms));
  const auto own = sample(CommandKind::SetGeneration, "own");
  record.relinquished(key_of(own), 42, reply_to(own, CommandResult::Timeout, "fenced"), kStart + 200ms);
  EXPECT_EQ(record.size(), 2u);
  const auto verdicts = record.take_over(kStart + 300ms);
  ASSERT_EQ(verdicts.size(), 2u);
  EXPECT_EQ(verdicts[0].action, Action::Run);
  EXPECT_EQ(verdicts[0].sample->expires_at, 0u) << "the first sample is kept";
  EXPECT_EQ(verdicts[1].action, Action::Unknown);
  EXPECT_EQ(verdicts[1].fingerprint, 42u);
  EXPECT_EQ(verdicts[1].reply.result, CommandResult::Failed);
}

TEST(FailoverRecord, ItIsBoundedInSizeAndAge) {
  Lifetimes lifetimes;
  FailoverRecord record(lifetimes, FailoverLimits{3, 2, 1000ms});
  for (int i = 0; i < 5; ++i) {
    const auto s = set_avionics("r-" + std::to_string(i));
    record.request(key_of(s), s, at(std::chrono::milliseconds(i)));
  }
  EXPECT_EQ(record.size(), 3u) << "oldest forgotten first";
  auto verdicts = record.take_over(kStart + 10ms);
  ASSERT_EQ(verdicts.size(), 3u);
  EXPECT_EQ(verdicts[0].reply.request_id, "r-2");

  const auto old = set_avionics("old");
  record.request(key_of(old), old, at(0ms));
  record.heard("can0", pmu_frame(0x24, 9, {}), kStart + lifetimes.max_lifetime + 1ms);
  EXPECT_EQ(record.size(), 0u) << "no request lives longer than the maximum lifetime";
}

TEST(FailoverRecord, OnlyAFrameThatMakesAPmuDoSomethingIsACommand) {
  struct FrameCase {
    const char* what;
    codec::CanFrame frame;
    FrameRole role;
  };
  auto standard = pmu_frame(0x25, 1, {});
  standard.extended = false;
  standard.id = 0x202;
  const FrameCase cases[] = {
      {"set avionics voltage", pmu_frame(0x10, 1, {240}), FrameRole::Command},
      {"set CAN address", pmu_frame(0x1B, 1, {0, 5}), FrameRole::Command},
      {"set outputs", pmu_frame(0x20, 1, {3}), FrameRole::Command},
      {"enable outputs", pmu_frame(0x21, 1, {2}), FrameRole::Command},
      {"disable outputs", pmu_frame(0x22, 1, {2}), FrameRole::Command},
      {"generation", pmu_frame(0x23, 1, {1}), FrameRole::Command},
      {"engine start", pmu_frame(0x24, 1, {}), FrameRole::Command},
      {"engine stop", pmu_frame(0x25, 1, {}), FrameRole::Command},
      {"reset", pmu_frame(0x26, 1, {}), FrameRole::Command},
      {"get a parameter", pmu_frame(0x10, 1, {}), FrameRole::Get},
      {"get the outputs", pmu_frame(0x20, 1, {}), FrameRole::Get},
      {"voltages (telemetry)", pmu_frame(0x00, 1, {1, 2, 3, 4, 5, 6, 7}), FrameRole::Other},
      {"a voltages poll", pmu_frame(0x00, 1, {}), FrameRole::Other},
      {"a measurement request", pmu_frame(0x0F, 1, {0x1F}), FrameRole::Other},
      {"firmware", pmu_frame(0x31, 1, {}), FrameRole::Other},
      {"a broadcast stop", pmu_frame(0x25, 0xFFFF, {}), FrameRole::Other},
      {"a set of the wrong length", pmu_frame(0x10, 1, {1, 2}), FrameRole::Other},
      {"a battery's 11-bit frame", standard, FrameRole::Other},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.what);
    EXPECT_EQ(frame_role(c.frame), c.role);
  }
}

}  // namespace
}  // namespace pmu::service::test
