// An apply's hold on a device's configuration (docs/interface.md 2.8, docs/safety.md H11),
// through the command service against a simulated PMU with a fake clock: while an apply holds
// the device, another writer's change is DENIED naming the holder and sends nothing; reads and
// the engine stop are never refused; the hold ends with the apply's last command or, when its
// caller is gone, by itself at the expiry of the apply's latest command.
#include <gtest/gtest.h>

#include <regex>

#include "frame_text.hpp"
#include "support/harness.hpp"
#include "pmu/dispatch/command_service.hpp"
#include "support/pmu_frames.hpp"

namespace pmu::service::test {
namespace {

using codec::test::pmu_frame;

// A harness plus a CommandService whose replies are collected.
class Service {
 public:
  Service() : service({&h.worker()}, {}, {}, h.clock(), [this](const CommandReplyData& r) { replies.push_back(r); }) {
    h.run_for(300ms);  // start-up reading done
    h.clear_sent();
  }

  // A command of `sender`'s; with `apply`, one of that apply's (groups bit 0x80, id APPLY#N).
  CommandSample req(CommandKind kind, const std::string& sender, const std::string& apply = "",
                    std::uint8_t hold_bits = hold_bit::Hold) {
    CommandSample s;
    s.request_id = apply.empty() ? "t-" + std::to_string(++next_) : apply + "#" + std::to_string(++next_);
    s.sender = sender;
    s.bus = "sim0";
    s.address = 1;
    s.kind = static_cast<std::uint32_t>(kind);
    if (!apply.empty()) s.groups = hold_bits;
    return s;
  }
  CommandSample set(const std::string& sender, const std::string& apply = "", std::uint8_t hold_bits = hold_bit::Hold) {
    auto s = req(CommandKind::SetParameter, sender, apply, hold_bits);
    s.parameter = "payload_voltage";
    s.value = 13.0 + static_cast<double>(next_ % 10);
    return s;
  }
  CommandSample get(const std::string& sender, const std::string& apply = "", std::uint8_t hold_bits = hold_bit::Hold) {
    auto s = req(CommandKind::Get, sender, apply, hold_bits);
    s.parameter = "outputs";
    return s;
  }
  // Submits and runs the bus until the reply arrives.
  CommandReplyData run(const CommandSample& s) {
    const auto before = replies.size();
    service.submit(s);
    for (int i = 0; i < 1000 && replies.size() == before; ++i) h.run_for(10ms);
    EXPECT_EQ(replies.size(), before + 1) << "exactly one reply";
    return replies.empty() ? CommandReplyData{} : replies.back();
  }

  Harness h{sim_bus({device(1)}), {pmu(1)}};
  std::vector<CommandReplyData> replies;
  CommandService service;

 private:
  int next_ = 0;
};

const std::string kApply = "pmuctl-gs1-4242-1765000000000000000";
const std::string kA = "sender-a";
const std::string kB = "sender-b";

void expect_denied_by_holder(const CommandReplyData& r, const std::string& holder_id, const std::string& holder = kA) {
  EXPECT_EQ(r.result, CommandResult::Denied) << r.reason;
  EXPECT_NE(
      r.reason.find("configuration of sim0/1 held by an apply from " + holder + " (request id " + holder_id + ")"),
      std::string::npos)
      << r.reason;
  EXPECT_TRUE(std::regex_search(r.reason, std::regex(R"(for another [0-9]+\.[0-9] s)"))) << r.reason;
}

// Every kind another client may send while the apply holds the device: the writers are
// DENIED with nothing on the bus, everything else runs.
TEST(ConfigHold, AnotherWritersChangesAreDeniedNamingTheHolderAndReadsAndStopsRun) {
  struct Case {
    const char* what;
    std::function<CommandSample(Service&)> make;
    bool denied;
  };
  const Case cases[] = {
      {"set_parameter", [](Service& s) { return s.set(kB); }, true},
      {"set_outputs",
       [](Service& s) {
         auto c = s.req(CommandKind::SetOutputs, kB);
         c.outputs = 0x03;
         return c;
       },
       true},
      {"enable_outputs",
       [](Service& s) {
         auto c = s.req(CommandKind::EnableOutputs, kB);
         c.outputs = 0x02;
         return c;
       },
       true},
      {"disable_outputs",
       [](Service& s) {
         auto c = s.req(CommandKind::DisableOutputs, kB);
         c.outputs = 0x02;
         return c;
       },
       true},
      {"set_generation",
       [](Service& s) {
         auto c = s.req(CommandKind::SetGeneration, kB);
         c.enable = 1;
         return c;
       },
       true},
      {"reset",
       [](Service& s) {
         auto c = s.req(CommandKind::Reset, kB);
         c.confirm = 1;
         return c;
       },
       true},
      // Another apply (another sender, or the same sender's other apply) cannot take it.
      {"another apply's get", [](Service& s) { return s.get(kB, "pmuctl-gs2-77-1"); }, true},
      {"the same sender's other apply", [](Service& s) { return s.set(kA, "pmuctl-gs1-4242-2"); }, true},
      // The holder's sender without the hold bits is not the apply.
      {"the holder's sender, not holding", [](Service& s) { return s.set(kA); }, true},
      {"get", [](Service& s) { return s.get(kB); }, false},
      {"request_measurements",
       [](Service& s) {
         auto c = s.req(CommandKind::RequestMeasurements, kB);
         c.groups = 0x01;
         return c;
       },
       false},
      {"get_serial", [](Service& s) { return s.req(CommandKind::GetSerial, kB); }, false},
      {"get_firmware", [](Service& s) { return s.req(CommandKind::GetFirmware, kB); }, false},
      {"engine_stop", [](Service& s) { return s.req(CommandKind::EngineStop, kB); }, false},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.what);
    Service s;
    const auto take = s.get(kA, kApply);
    ASSERT_EQ(s.run(take).result, CommandResult::Completed);
    s.h.clear_sent();
    const auto r = s.run(c.make(s));
    if (c.denied) {
      expect_denied_by_holder(r, take.request_id);
      EXPECT_TRUE(s.h.sent_frames().empty()) << "a denied command sends nothing";
    } else {
      EXPECT_EQ(r.result, CommandResult::Completed) << r.reason;
      EXPECT_FALSE(s.h.sent_frames().empty());
    }
  }
}

TEST(ConfigHold, TheHoldersChangesRunAndItsLastCommandReleasesTheDevice) {
  Service s;
  const auto take = s.get(kA, kApply);
  ASSERT_EQ(s.run(take).result, CommandResult::Completed);
  const auto mine = s.set(kA, kApply);
  ASSERT_EQ(s.run(mine).result, CommandResult::Completed);
  std::uint32_t payload = 0;
  s.h.pmus().with_model(1, [&](sim::PmuModel& m) { payload = m.parameter(codec::Parameter::PayloadVoltage); });
  EXPECT_EQ(payload, static_cast<std::uint32_t>(mine.value * 10));
  expect_denied_by_holder(s.run(s.set(kB)), take.request_id);
  // The last command of the apply, with the release bit: the next writer gets through at once.
  ASSERT_EQ(s.run(s.get(kA, kApply, hold_bit::Hold | hold_bit::Release)).result, CommandResult::Completed);
  EXPECT_EQ(s.run(s.set(kB)).result, CommandResult::Completed);
  // And another apply may now take the device.
  const auto other = s.get(kB, "pmuctl-gs2-77-1");
  EXPECT_EQ(s.run(other).result, CommandResult::Completed);
  expect_denied_by_holder(s.run(s.set(kA, kApply)), other.request_id, kB);
}

// The caller may die holding the device: the hold lasts until its latest command's expiry
// and no longer; each command of the apply renews it.
TEST(ConfigHold, AHoldEndsByItselfAtTheExpiryOfTheApplysLatestCommand) {
  Service s;
  auto take = s.get(kA, kApply);
  take.expires_at = epoch_ns(s.h.clock().system_now() + 3s);
  ASSERT_EQ(s.run(take).result, CommandResult::Completed);
  s.h.run_for(2000ms);
  auto renew = s.set(kA, kApply);
  renew.expires_at = epoch_ns(s.h.clock().system_now() + 3s);  // now the hold lasts 3 s more
  ASSERT_EQ(s.run(renew).result, CommandResult::Completed);
  s.h.run_for(2000ms);  // past the first command's expiry, within the second's
  expect_denied_by_holder(s.run(s.set(kB)), take.request_id);
  s.h.run_for(1500ms);  // past the latest expiry: nobody holds the device
  EXPECT_EQ(s.run(s.set(kB)).result, CommandResult::Completed);
  EXPECT_EQ(s.service.counters().refused, 1u);
}

// A stop never waits for a hold, and the hold bits cannot make it refused.
TEST(ConfigHold, AnEngineStopIsNeverRefusedNorHeldBack) {
  Service s;
  ASSERT_EQ(s.run(s.get(kA, kApply)).result, CommandResult::Completed);
  s.h.clear_sent();
  for (const std::uint8_t bits : {std::uint8_t{0}, hold_bit::Hold, std::uint8_t{hold_bit::Hold | hold_bit::Release}}) {
    auto stop = s.req(CommandKind::EngineStop, kB, bits ? "pmuctl-gs2-77-1" : "", bits);
    stop.request_id += "-stop";  // no APPLY#N needed: a stop carries no hold
    const auto r = s.run(stop);
    EXPECT_EQ(r.result, CommandResult::Completed) << r.reason;
  }
  const std::string stop_frame = hex(pmu_frame(0x25, 1, {}));
  std::size_t stops = 0;
  for (const auto& f : s.h.sent_frames()) stops += hex(f) == stop_frame ? 1u : 0u;
  EXPECT_EQ(stops, 3u);
}

// The boundary: the hold's bits and its request id are checked when the sample arrives.
TEST(ConfigHold, AHoldWithoutAnApplyNameOrAReleaseWithoutHoldIsRejected) {
  struct Case {
    const char* what;
    std::string request_id;
    std::uint8_t groups;
    const char* reason;
  };
  const Case cases[] = {
      {"no #", "pmuctl-gs1-1-2", hold_bit::Hold, "has a request id APPLY#N, not 'pmuctl-gs1-1-2'"},
      {"nothing before #", "#3", hold_bit::Hold, "has a request id APPLY#N, not '#3'"},
      {"nothing after #", "apply#", hold_bit::Hold, "has a request id APPLY#N, not 'apply#'"},
      {"release alone", "apply#2", hold_bit::Release, "groups bit 0x40 (release a hold) needs bit 0x80 (hold)"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.what);
    Service s;
    auto set = s.set(kA);
    set.request_id = c.request_id;
    set.groups = c.groups;
    const auto r = s.run(set);
    EXPECT_EQ(r.result, CommandResult::Rejected);
    EXPECT_NE(r.reason.find(c.reason), std::string::npos) << r.reason;
    EXPECT_TRUE(s.h.sent_frames().empty());
  }
}

}  // namespace
}  // namespace pmu::service::test
