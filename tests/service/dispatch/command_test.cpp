// The command path against simulated PMUs with a fake clock (interface.md, commands):
// every command kind's frames byte for byte, verification by read-back, every rejection
// with zero frames sent, the safety policy, duplicates, timeouts, retries, serialisation,
// and a burst of 1000 mixed commands from two senders.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <random>

#include "frame_text.hpp"
#include "support/harness.hpp"
#include "pmu/codec/encode.hpp"
#include "pmu/dispatch/command_service.hpp"
#include "support/pmu_frames.hpp"

namespace pmu::service::test {
namespace {

using codec::CanFrame;

using codec::test::pmu_frame;

std::uint32_t wire(CommandKind k) { return static_cast<std::uint32_t>(k); }

// A harness plus a CommandService whose replies are collected.
class Commands {
 public:
  explicit Commands(std::vector<sim::DeviceConfig> pmus, PolicyConfig policy = {}, Timeouts timeouts = {},
                    std::vector<DeviceConfig> devices = {device(1)})
      : h(sim_bus(devices), std::move(pmus), timeouts),
        service({&h.worker()}, policy, timeouts, h.clock(),
                [this](const CommandReplyData& r) { replies.push_back(r); }) {
    h.run_for(300ms);  // start-up reading done
    h.clear_sent();
  }

  CommandSample req(CommandKind kind, std::uint16_t address = 1) {
    CommandSample r;
    r.request_id = "t-" + std::to_string(++next_id_);
    r.sender = "test";
    r.bus = "sim0";
    r.address = address;
    r.kind = wire(kind);
    return r;
  }
  // Submits and runs the bus until the reply arrives (or 10 s of bus time pass).
  CommandReplyData run(const CommandSample& r) {
    const auto before = replies.size();
    service.submit(r);
    for (int i = 0; i < 1000 && replies.size() == before; ++i) h.run_for(10ms);
    EXPECT_EQ(replies.size(), before + 1) << "exactly one reply";
    return replies.empty() ? CommandReplyData{} : replies.back();
  }
  std::vector<std::string> sent() const {
    std::vector<std::string> v;
    for (const auto& f : h.sent_frames()) v.push_back(hex(f));
    return v;
  }

  Harness h;
  std::vector<CommandReplyData> replies;
  CommandService service;

 private:
  int next_id_ = 0;
};

CommandSample set_param(Commands& c, const char* name, double value, std::uint16_t address = 1) {
  auto r = c.req(CommandKind::SetParameter, address);
  r.parameter = name;
  r.value = value;
  return r;
}

// ---- happy paths: the frames of the spec, and the state that follows --------------------

struct HappyCase {
  const char* what;
  std::function<CommandSample(Commands&)> make;
  std::vector<CanFrame> frames;  // exactly what goes on the bus, in order
  std::function<void(Commands&, const CommandReplyData&)> check;
};

std::uint32_t sim_param(Commands& c, codec::Parameter p) {
  std::uint32_t v = 0;
  c.h.pmus().with_model(1, [&](sim::PmuModel& m) { v = m.parameter(p); });
  return v;
}
std::uint8_t sim_outputs(Commands& c) {
  std::uint8_t v = 0;
  c.h.pmus().with_model(1, [&](sim::PmuModel& m) { v = m.outputs(); });
  return v;
}

TEST(Commands, EveryKindPutsTheSpecsFramesOnTheBusAndTheResultShowsUp) {
  const HappyCase cases[] = {
      {"set avionics_voltage 24.0",
       [](Commands& c) { return set_param(c, "avionics_voltage", 24.0); },
       {pmu_frame(0x10, 1, {240}), pmu_frame(0x10, 1, {})},
       [](Commands& c, const CommandReplyData& r) {
         EXPECT_DOUBLE_EQ(r.value, 24.0);
         EXPECT_EQ(sim_param(c, codec::Parameter::AvionicsVoltage), 240u);
         EXPECT_DOUBLE_EQ(c.h.sink.configs.back().second.value(codec::Parameter::AvionicsVoltage), 24.0);
       }},
      {"set cranking_time 2.5",
       [](Commands& c) { return set_param(c, "cranking_time", 2.5); },
       {pmu_frame(0x19, 1, {25}), pmu_frame(0x19, 1, {})},
       [](Commands& c, const CommandReplyData&) { EXPECT_EQ(sim_param(c, codec::Parameter::CrankingTime), 25u); }},
      {"set outputs avionics+payload",
       [](Commands& c) {
         auto r = c.req(CommandKind::SetOutputs);
         r.outputs = 0x03;
         return r;
       },
       {pmu_frame(0x20, 1, {0x03}), pmu_frame(0x20, 1, {})},
       [](Commands& c, const CommandReplyData& r) {
         EXPECT_EQ(sim_outputs(c), 0x03);
         EXPECT_EQ(r.value, 3);
         EXPECT_EQ(c.h.sink.configs.back().second.outputs, 0x03);
       }},
      {"disable payload",
       [](Commands& c) {
         auto r = c.req(CommandKind::DisableOutputs);
         r.outputs = 0x02;
         return r;
       },
       {pmu_frame(0x22, 1, {0x02}), pmu_frame(0x20, 1, {})},
       [](Commands& c, const CommandReplyData&) { EXPECT_EQ(sim_outputs(c) & 0x02, 0); }},
      {"enable payload",
       [](Commands& c) {
         auto r = c.req(CommandKind::EnableOutputs);
         r.outputs = 0x02;
         return r;
       },
       {pmu_frame(0x21, 1, {0x02}), pmu_frame(0x20, 1, {})},
       [](Commands& c, const CommandReplyData&) { EXPECT_EQ(sim_outputs(c) & 0x02, 0x02); }},
      {"generation off",
       [](Commands& c) {
         auto r = c.req(CommandKind::SetGeneration);
         r.enable = false;
         return r;
       },
       {pmu_frame(0x23, 1, {0x00}), pmu_frame(0x23, 1, {})},
       [](Commands& c, const CommandReplyData&) {
         bool on = true;
         c.h.pmus().with_model(1, [&](sim::PmuModel& m) { on = m.generation_enabled(); });
         EXPECT_FALSE(on);
       }},
      {"measure temperatures",
       [](Commands& c) {
         auto r = c.req(CommandKind::RequestMeasurements);
         r.groups = 0x08;
         return r;
       },
       {pmu_frame(0x0F, 1, {0x08})},
       [](Commands& c, const CommandReplyData&) { EXPECT_GE(c.h.sink.count(codec::PacketId::Temperatures, 1), 1u); }},
      {"engine stop", [](Commands& c) { return c.req(CommandKind::EngineStop); }, {pmu_frame(0x25, 1, {})}, nullptr},
      {"get avionics_voltage",
       [](Commands& c) {
         auto r = c.req(CommandKind::Get);
         r.parameter = "avionics_voltage";
         return r;
       },
       {pmu_frame(0x10, 1, {})},
       [](Commands&, const CommandReplyData& r) {
         EXPECT_TRUE(r.has_value);
         EXPECT_DOUBLE_EQ(r.value, 12.0);
       }},
      {"get serial",
       [](Commands& c) { return c.req(CommandKind::GetSerial); },
       {pmu_frame(0x30, 1, {})},
       [](Commands&, const CommandReplyData& r) { EXPECT_EQ(r.value, 4001); }},
      {"get firmware",
       [](Commands& c) { return c.req(CommandKind::GetFirmware); },
       {pmu_frame(0x31, 1, {})},
       [](Commands&, const CommandReplyData& r) { EXPECT_EQ(r.value_text, "1.17 built 2023-06-15"); }},
  };
  for (const auto& hc : cases) {
    SCOPED_TRACE(hc.what);
    Commands c({pmu(1)});
    const auto r = c.run(hc.make(c));
    EXPECT_EQ(r.result, CommandResult::Completed) << r.reason;
    std::vector<std::string> want;
    for (const auto& f : hc.frames) want.push_back(hex(f));
    EXPECT_EQ(c.sent(), want);
    if (hc.check) hc.check(c, r);
  }
}

TEST(Commands, ResetIsSentThenEverythingIsReadAgain) {
  Commands c({pmu(1)});
  auto r = c.req(CommandKind::Reset);
  r.confirm = true;
  const auto infos = c.h.sink.infos.size();
  EXPECT_EQ(c.run(r).result, CommandResult::Completed);
  c.h.run_for(300ms);
  ASSERT_GE(c.sent().size(), 16u);
  EXPECT_EQ(c.sent()[0], hex(pmu_frame(0x26, 1, {})));
  EXPECT_EQ(c.h.sink.infos.size(), infos + 1);
}

TEST(Commands, CanAddressChangeIsVerifiedAtTheNewAddressAndTheSessionMoves) {
  Commands c({pmu(1)});
  auto r = set_param(c, "can_address", 5);
  r.confirm = true;
  const auto reply = c.run(r);
  EXPECT_EQ(reply.result, CommandResult::Completed) << reply.reason;
  EXPECT_EQ(c.sent(), (std::vector<std::string>{hex(pmu_frame(0x1B, 1, {0x00, 0x05})), hex(pmu_frame(0x1B, 5, {}))}));
  c.h.run_for(50ms);
  EXPECT_EQ(c.h.worker().addresses(), (std::vector<std::uint16_t>{5}));
  EXPECT_EQ(c.run(c.req(CommandKind::GetSerial, 5)).result, CommandResult::Completed);
}

// ---- rejected before the bus ----------------------------------------------------------------

struct RefusedCase {
  const char* what;
  std::function<CommandSample(Commands&)> make;
  CommandResult result;
  const char* reason;  // a part of the reason
};

TEST(Commands, InvalidRequestsAreRefusedWithAReasonAndNothingIsSent) {
  const RefusedCase cases[] = {
      {"unknown parameter", [](Commands& c) { return set_param(c, "avionics", 12); }, CommandResult::Rejected,
       "unknown parameter 'avionics'"},
      {"out of range", [](Commands& c) { return set_param(c, "avionics_voltage", 30.0); }, CommandResult::Rejected,
       "value 30.0 V out of range 12.0..24.0 V for avionics_voltage"},
      {"one step past", [](Commands& c) { return set_param(c, "battery_voltage", 25.3); }, CommandResult::Rejected,
       "out of range 20.0..25.2 V"},
      {"NaN", [](Commands& c) { return set_param(c, "servo_voltage", std::nan("")); }, CommandResult::Rejected,
       "is not a number"},
      {"between steps", [](Commands& c) { return set_param(c, "avionics_voltage", 12.05); }, CommandResult::Rejected,
       "not a multiple of 0.1 V"},
      {"unknown output",
       [](Commands& c) {
         auto r = c.req(CommandKind::EnableOutputs);
         r.outputs = 0x10;
         return r;
       },
       CommandResult::Rejected, "unknown output bits 0x10"},
      {"enable nothing", [](Commands& c) { return c.req(CommandKind::EnableOutputs); }, CommandResult::Rejected,
       "no output named"},
      {"unknown get",
       [](Commands& c) {
         auto r = c.req(CommandKind::Get);
         r.parameter = "volts";
         return r;
       },
       CommandResult::Rejected, "unknown parameter 'volts'"},
      {"expired",
       [](Commands& c) {
         auto r = c.req(CommandKind::GetSerial);
         r.expires_at = epoch_ns(c.h.clock().system_now() - 1s);
         return r;
       },
       CommandResult::Rejected, "expired 1000 ms ago"},
      {"unknown bus",
       [](Commands& c) {
         auto r = c.req(CommandKind::GetSerial);
         r.bus = "can9";
         return r;
       },
       CommandResult::Rejected, "bus 'can9' is not served here (buses: sim0)"},
      {"unknown device", [](Commands& c) { return c.req(CommandKind::GetSerial, 7); }, CommandResult::Rejected,
       "device 7 not seen on sim0"},
      {"broadcast set", [](Commands& c) { return set_param(c, "avionics_voltage", 12.0, 0xFFFF); },
       CommandResult::Rejected, "broadcast (65535) is only accepted for engine_stop"},
      {"disable avionics without confirm",
       [](Commands& c) {
         auto r = c.req(CommandKind::DisableOutputs);
         r.outputs = 0x01;
         return r;
       },
       CommandResult::Denied, "needs confirm"},
      {"set outputs without avionics, no confirm",
       [](Commands& c) {
         auto r = c.req(CommandKind::SetOutputs);
         r.outputs = 0x02;
         return r;
       },
       CommandResult::Denied, "rule disable_avionics"},
      {"reset without confirm", [](Commands& c) { return c.req(CommandKind::Reset); }, CommandResult::Denied,
       "rule reset"},
      {"engine start without confirm", [](Commands& c) { return c.req(CommandKind::EngineStart); },
       CommandResult::Denied, "rule engine_start"},
      {"can address without confirm", [](Commands& c) { return set_param(c, "can_address", 9); }, CommandResult::Denied,
       "rule set_can_address"},
      {"T_U = 0 without confirm", [](Commands& c) { return set_param(c, "upper_temperature_limit", 0); },
       CommandResult::Denied, "rule thermal_shutdown"},
      {"S0 without avionics, no confirm", [](Commands& c) { return set_param(c, "power_up_state", 0x0E); },
       CommandResult::Denied, "rule power_up_avionics_off"},
      // Policy judges the value the wire would carry: each of these rounds to 0.
      {"T_U 0.0005 without confirm", [](Commands& c) { return set_param(c, "upper_temperature_limit", 0.0005); },
       CommandResult::Denied, "rule thermal_shutdown"},
      {"T_U -0.0009 without confirm", [](Commands& c) { return set_param(c, "upper_temperature_limit", -0.0009); },
       CommandResult::Denied, "rule thermal_shutdown"},
      {"S0 -0.0004 without confirm", [](Commands& c) { return set_param(c, "power_up_state", -0.0004); },
       CommandResult::Denied, "rule power_up_avionics_off"},
      {"kind from a newer client",
       [](Commands& c) {
         auto r = c.req(CommandKind::Get);
         r.kind = 99;
         return r;
       },
       CommandResult::Rejected, "unknown command kind 99"},
      {"a boolean byte of 2",
       [](Commands& c) {
         auto r = c.req(CommandKind::EngineStart);
         r.confirm = 2;
         return r;
       },
       CommandResult::Rejected, "confirm is not a boolean"},
  };
  for (const auto& rc : cases) {
    SCOPED_TRACE(rc.what);
    Commands c({pmu(1)});
    const auto r = c.run(rc.make(c));
    EXPECT_EQ(r.result, rc.result) << r.reason;
    EXPECT_NE(r.reason.find(rc.reason), std::string::npos) << r.reason;
    c.h.run_for(100ms);
    EXPECT_TRUE(c.sent().empty()) << "a frame reached the bus";
  }
}

// pmuctl exits 2 (no such target) for a refusal that says the bus or the device is not there,
// 1 for any other (interface.md 3.2): says_no_such_target tells them apart on the service's
// own reasons.
TEST(Commands, ARefusalSaysWhenItsTargetIsNotThere) {
  struct Case {
    const char* what;
    std::string bus;
    std::uint16_t address;
    CommandKind kind;
    bool not_there;
  };
  const Case cases[] = {
      {"a bus not served", "can9", 1, CommandKind::EngineStop, true},
      {"a broadcast stop on a bus not served", "can9", 0xFFFF, CommandKind::EngineStop, true},
      {"a device not seen", "sim0", 7, CommandKind::EngineStop, true},
      {"a refusal by the policy", "sim0", 1, CommandKind::Reset, false},
  };
  for (const auto& tc : cases) {
    SCOPED_TRACE(tc.what);
    Commands c({pmu(1)});
    auto r = c.req(tc.kind, tc.address);
    r.bus = tc.bus;
    const auto reply = c.run(r);
    EXPECT_NE(reply.result, CommandResult::Completed) << reply.reason;
    EXPECT_EQ(says_no_such_target(reply.reason, tc.bus, tc.address), tc.not_there) << reply.reason;
  }
  // Another bus's or device's refusal is not this target's.
  EXPECT_FALSE(says_no_such_target(device_not_seen_reason(7, "sim0"), "sim0", 8));
  EXPECT_FALSE(says_no_such_target(bus_not_served_reason("can9", "sim0"), "can1", 1));
  EXPECT_FALSE(says_no_such_target("rate limit: more than 5 commands/s", "sim0", 1));
}

TEST(Commands, FeaturesTheFirmwareLacksAreUnsupported) {
  Commands c({pmu(1, codec::FirmwareVersion{1, 12})});
  auto m = c.req(CommandKind::RequestMeasurements);
  m.groups = 0x1F;
  auto r = c.run(m);
  EXPECT_EQ(r.result, CommandResult::Unsupported);
  EXPECT_EQ(r.reason, "measurement_request needs firmware 1.14 (device has 1.12)");
  r = c.run(set_param(c, "power_up_state", 0x41));
  EXPECT_EQ(r.result, CommandResult::Unsupported);
  EXPECT_TRUE(c.sent().empty());
}

TEST(Commands, DenyListRefusesEvenConfirmedCommandsButNeverEngineStop) {
  PolicyConfig p;
  p.deny.fill(true);
  p.deny[static_cast<std::size_t>(CommandKind::EngineStop)] = false;  // config refuses to deny it anyway
  Commands c({pmu(1)}, p);
  auto reset = c.req(CommandKind::Reset);
  reset.confirm = true;
  auto r = c.run(reset);
  EXPECT_EQ(r.result, CommandResult::Denied);
  EXPECT_EQ(r.reason, "reset is denied by the service's policy");
  EXPECT_EQ(c.run(c.req(CommandKind::EngineStop)).result, CommandResult::Completed);
}

// An engine stop to the broadcast address that names no bus goes out on every bus the
// service serves, with one reply; every other kind is refused at the boundary, frameless.
TEST(Commands, BroadcastStopWithoutABusGoesOutOnEveryBus) {
  Commands c({pmu(1)});
  auto stop = c.req(CommandKind::EngineStop, codec::kBroadcastAddress);
  stop.bus = "";
  const auto r = c.run(stop);
  EXPECT_EQ(r.result, CommandResult::Completed);
  EXPECT_EQ(r.reason, "stop sent to every PMU (broadcast) on sim0");
  EXPECT_EQ(c.sent(), (std::vector<std::string>{hex(pmu_frame(0x25, 0xFFFF, {}))}));
  c.h.clear_sent();
  auto get = c.req(CommandKind::GetSerial, codec::kBroadcastAddress);
  get.bus = "";
  EXPECT_EQ(c.run(get).result, CommandResult::Rejected);
  EXPECT_TRUE(c.sent().empty());
}

TEST(Commands, RateLimitRejectsTheExcessWithAReasonButNeverEngineStop) {
  PolicyConfig p;
  p.rate_per_second = 1;
  p.burst = 3;
  Commands c({pmu(1)}, p);
  for (int i = 0; i < 3; ++i) c.service.submit(c.req(CommandKind::GetSerial));
  c.service.submit(c.req(CommandKind::GetSerial));
  c.h.run_for(200ms);
  ASSERT_EQ(c.replies.size(), 4u);
  std::size_t limited = 0;
  for (const auto& r : c.replies) limited += r.reason.find("rate limit") != std::string::npos ? 1u : 0u;
  EXPECT_EQ(limited, 1u);
  EXPECT_EQ(c.run(c.req(CommandKind::EngineStop)).result, CommandResult::Completed);
  c.h.run_for(1100ms);  // a token comes back
  EXPECT_EQ(c.run(c.req(CommandKind::GetSerial)).result, CommandResult::Completed);
}

TEST(Commands, DuplicateRequestIdIsAnsweredAgainButExecutedOnce) {
  Commands c({pmu(1)});
  auto r = set_param(c, "payload_voltage", 20.0);
  c.service.submit(r);
  c.service.submit(r);  // while the first is running
  c.h.run_for(200ms);
  c.service.submit(r);  // after it ended
  c.h.run_for(100ms);
  ASSERT_EQ(c.replies.size(), 3u);
  for (const auto& reply : c.replies) {
    EXPECT_EQ(reply.request_id, r.request_id);
    EXPECT_EQ(reply.result, CommandResult::Completed);
  }
  EXPECT_EQ(c.sent(), (std::vector<std::string>{hex(pmu_frame(0x11, 1, {200})), hex(pmu_frame(0x11, 1, {}))}));
  EXPECT_EQ(c.service.counters().duplicates, 2u);
}

TEST(Commands, ReadBackThatDiffersIsFailed) {
  Commands c({pmu(1)});
  c.h.recording_bus().drop_data_of = 0x12;  // the set of V_S never reaches the unit
  const auto r = c.run(set_param(c, "servo_voltage", 9.0));
  EXPECT_EQ(r.result, CommandResult::Failed);
  EXPECT_EQ(r.reason, "device reports 6 after the set, not 9");
}

TEST(Commands, SilentDeviceTimesOutAfterBoundedRetries) {
  Timeouts t;
  t.retries = 2;
  t.reply = 100ms;
  Commands c({pmu(1)}, {}, t);
  c.h.pmus().with_model(1, [](sim::PmuModel& m) {
    auto f = m.faults();
    f.silent = true;
    m.set_faults(f);
  });
  const auto r = c.run(c.req(CommandKind::GetSerial));
  EXPECT_EQ(r.result, CommandResult::Timeout);
  EXPECT_EQ(r.reason, "device 1 did not answer the get after 3 tries");
  EXPECT_EQ(c.sent().size(), 3u);
  // A set whose read-back goes unanswered: the set is sent once (sets are not repeated),
  // the read-back get up to three times.
  c.h.clear_sent();
  EXPECT_EQ(c.run(set_param(c, "payload_voltage", 13.0)).result, CommandResult::Timeout);
  EXPECT_EQ(c.sent().size(), 4u);
}

TEST(Commands, LossyDeviceIsReachedThroughRetries) {
  Timeouts t;
  t.retries = 6;
  t.reply = 50ms;
  Commands c({pmu(1)}, {}, t);
  c.h.pmus().with_model(1, [](sim::PmuModel& m) {
    auto f = m.faults();
    f.loss_probability = 0.4;
    f.loss_seed = 7;
    m.set_faults(f);
  });
  c.h.clear_sent();
  int completed = 0;
  for (int i = 0; i < 20; ++i) completed += c.run(c.req(CommandKind::GetSerial)).result == CommandResult::Completed;
  EXPECT_EQ(completed, 20);
  EXPECT_GT(c.sent().size(), 20u) << "some answers were lost and the gets retried";
}

TEST(Commands, OneDeviceIsSerialisedTwoDevicesProceedInParallel) {
  auto slow = pmu(1);
  Commands c({slow, pmu(2)}, {}, {}, {device(1), device(2)});
  c.h.pmus().with_model(1, [](sim::PmuModel& m) {
    auto f = m.faults();
    f.delay = std::chrono::milliseconds(150);
    m.set_faults(f);
  });
  c.service.submit(c.req(CommandKind::GetSerial, 1));
  c.service.submit(c.req(CommandKind::GetFirmware, 1));
  c.service.submit(c.req(CommandKind::GetSerial, 2));
  c.h.run_for(20ms);
  // Device 1 has one get in flight (its second waits); device 2 was asked at the same time.
  EXPECT_EQ(c.sent(), (std::vector<std::string>{hex(pmu_frame(0x30, 1, {})), hex(pmu_frame(0x30, 2, {}))}));
  ASSERT_EQ(c.replies.size(), 1u);
  EXPECT_EQ(c.replies[0].address, 2);
  c.h.run_for(400ms);
  ASSERT_EQ(c.replies.size(), 3u);
  EXPECT_EQ(c.replies[1].kind, CommandKind::GetSerial);
  EXPECT_EQ(c.replies[2].kind, CommandKind::GetFirmware);
  EXPECT_EQ(c.sent().back(), hex(pmu_frame(0x31, 1, {})));
}

// docs/safety.md H4: an engine stop waits behind nothing the unit is asked: not behind the
// requests queued for it, nor behind the one in flight, however long that one waits for its
// answer. It goes out in the worker's next turn, with no time passing.
struct BusyCase {
  const char* what;
  std::function<void(Commands&)> busy;  // leaves a request in flight to unit 1
};

void with_faults(Commands& c, std::function<void(sim::Faults&)> change) {
  c.h.pmus().with_model(1, [&](sim::PmuModel& m) {
    auto f = m.faults();
    change(f);
    m.set_faults(f);
  });
}

TEST(Commands, EngineStopGoesOutAtOnceWhateverTheUnitIsAsked) {
  const BusyCase cases[] = {
      {"gets queued, the first answered late",
       [](Commands& c) {
         with_faults(c, [](sim::Faults& f) { f.delay = std::chrono::milliseconds(200); });
         for (int i = 0; i < 5; ++i) c.service.submit(c.req(CommandKind::GetSerial));
         c.h.run_for(50ms);
       }},
      {"a silent unit asked again (a get's retries)",
       [](Commands& c) {
         with_faults(c, [](sim::Faults& f) { f.silent = true; });
         c.service.submit(c.req(CommandKind::GetFirmware));
         c.h.run_for(300ms);  // past the first reply timeout: the second try is in flight
       }},
      {"a set waiting for its read-back",
       [](Commands& c) {
         with_faults(c, [](sim::Faults& f) { f.delay = std::chrono::milliseconds(200); });
         c.service.submit(set_param(c, "avionics_voltage", 24.0));
         c.h.run_for(50ms);
       }},
  };
  for (const auto& k : cases) {
    SCOPED_TRACE(k.what);
    Commands c({pmu(1)});
    k.busy(c);
    ASSERT_GT(c.h.worker().session(1)->queued(), 0u) << "the unit is busy";
    const auto replies = c.replies.size();
    c.h.clear_sent();
    auto stop = c.req(CommandKind::EngineStop);
    c.service.submit(stop);
    c.h.settle();  // the worker's next turn; no time passes
    EXPECT_EQ(c.sent(), (std::vector<std::string>{hex(pmu_frame(0x25, 1, {}))}));
    ASSERT_EQ(c.replies.size(), replies + 1);
    EXPECT_EQ(c.replies.back().request_id, stop.request_id);
    EXPECT_EQ(c.replies.back().result, CommandResult::Completed);
    EXPECT_EQ(c.replies.back().reason, "stop sent");
  }
}

TEST(Commands, EngineStopRunsBeforeCommandsPostedToTheWorkerBeforeIt) {
  Commands c({pmu(1), pmu(2)}, {}, {}, {device(1), device(2)});
  c.service.submit(c.req(CommandKind::GetSerial, 2));
  c.service.submit(c.req(CommandKind::GetFirmware, 1));
  c.service.submit(c.req(CommandKind::EngineStop, 1));
  c.h.worker().run_once(0ms);  // one turn runs what was posted
  const auto s = c.sent();
  ASSERT_FALSE(s.empty());
  EXPECT_EQ(s.front(), hex(pmu_frame(0x25, 1, {}))) << "docs/safety.md H4: the stop first";
}

TEST(Commands, BurstOf1000MixedCommandsFromTwoSendersGetsExactly1000Replies) {
  PolicyConfig p;
  p.rate_per_second = 0;  // this test is about delivery, not rate limits
  Commands c({pmu(1), pmu(2)}, p, {}, {device(1), device(2)});
  std::mt19937 rng(42);
  std::vector<CommandSample> all;
  const char* params[] = {"avionics_voltage", "payload_voltage", "servo_voltage", "battery_voltage"};
  for (int i = 0; i < 1000; ++i) {
    CommandSample r;
    r.request_id = std::string(i % 2 ? "ground-a-" : "ground-b-") + std::to_string(i);
    r.sender = i % 2 ? "ground-a" : "ground-b";
    r.bus = "sim0";
    r.address = static_cast<std::uint16_t>(1 + rng() % 2);
    switch (rng() % 6) {
      case 0:
        r.kind = wire(CommandKind::SetParameter);
        r.parameter = params[rng() % 4];
        r.value = 4.0 + static_cast<double>(rng() % 250) / 10.0;  // 4.0 .. 28.9 V: many out of range
        break;
      case 1:
        r.kind = wire(CommandKind::EnableOutputs);
        r.outputs = static_cast<std::uint8_t>(1u << (1 + rng() % 3));
        break;
      case 2:
        r.kind = wire(CommandKind::DisableOutputs);
        r.outputs = static_cast<std::uint8_t>(1u << (rng() % 4));  // avionics needs confirm
        break;
      case 3: r.kind = wire(CommandKind::GetSerial); break;
      case 4:
        r.kind = wire(CommandKind::Get);
        r.parameter = "outputs";
        break;
      default: r.kind = wire(CommandKind::RequestMeasurements); r.groups = static_cast<std::uint8_t>(1 + rng() % 31);
    }
    all.push_back(r);
  }
  for (const auto& r : all) c.service.submit(r);
  for (int i = 0; i < 3000 && c.replies.size() < 1000; ++i) c.h.run_for(10ms);
  ASSERT_EQ(c.replies.size(), 1000u);
  std::map<std::string, int> per_id;
  std::map<CommandResult, int> per_result;
  for (const auto& r : c.replies) {
    ++per_id[r.request_id];
    ++per_result[r.result];
  }
  EXPECT_EQ(per_id.size(), 1000u) << "none lost, none duplicated";
  EXPECT_GT(per_result[CommandResult::Completed], 300);
  EXPECT_GT(per_result[CommandResult::Rejected], 50);
  EXPECT_GT(per_result[CommandResult::Denied], 10);
  // The devices never saw an out-of-range frame: every set that went out is within the spec.
  for (const auto& f : c.h.sent_frames()) {
    const auto m = codec::decode(f);
    ASSERT_TRUE(m.ok());
    if (const auto* pv = std::get_if<codec::ParameterValue>(&m->payload)) {
      const auto& spec = codec::spec_of(pv->parameter);
      EXPECT_GE(pv->raw, spec.raw_min);
      EXPECT_LE(pv->raw, spec.raw_max);
    }
  }
  for (std::uint16_t a : {std::uint16_t{1}, std::uint16_t{2}}) {
    c.h.pmus().with_model(a, [](sim::PmuModel& m) { EXPECT_EQ(m.counters().rejected_sets, 0u); });
  }
}

}  // namespace
}  // namespace pmu::service::test

namespace pmu::service::test {
namespace {

TEST(Commands, RequestsThatExpireWhileQueuedAreNeverSent) {
  Commands c({pmu(1)});
  c.h.pmus().with_model(1, [](sim::PmuModel& m) {
    auto f = m.faults();
    f.delay = std::chrono::milliseconds(300);  // each answer takes 0.3 s
    m.set_faults(f);
  });
  for (int i = 0; i < 4; ++i) {
    auto r = set_param(c, "payload_voltage", 13.0 + i);
    r.expires_at = epoch_ns(c.h.clock().system_now() + 500ms);
    c.service.submit(r);
  }
  c.h.run_for(3000ms);
  ASSERT_EQ(c.replies.size(), 4u);
  std::size_t expired = 0;
  for (const auto& r : c.replies) expired += r.reason == "expired before it could be sent" ? 1u : 0u;
  EXPECT_GE(expired, 2u);
  // Only the sets that were still fresh went out.
  std::size_t sets = 0;
  for (const auto& f : c.h.sent_frames()) sets += f.length == 1 ? 1u : 0u;
  EXPECT_EQ(sets, 4u - expired);
}

TEST(Commands, ARequestWithoutIdStillGetsExactlyOneReply) {
  Commands c({pmu(1)});
  auto r = c.req(CommandKind::GetSerial);
  r.request_id.clear();
  c.service.submit(r);
  c.h.run_for(100ms);
  ASSERT_EQ(c.replies.size(), 1u);
  EXPECT_EQ(c.replies[0].result, CommandResult::Rejected);
  EXPECT_EQ(c.replies[0].reason, "request_id is empty");
  EXPECT_TRUE(c.sent().empty());
}

}  // namespace
}  // namespace pmu::service::test

#include <spdlog/sinks/ostream_sink.h>
#include <spdlog/spdlog.h>

#include <sstream>

namespace pmu::service::test {
namespace {

// Everything logged while it lives goes to `text()` instead of the console.
class CapturedLog {
 public:
  CapturedLog() : previous_(spdlog::default_logger()) {
    spdlog::set_default_logger(
        std::make_shared<spdlog::logger>("audit-test", std::make_shared<spdlog::sinks::ostream_sink_mt>(out_)));
  }
  ~CapturedLog() { spdlog::set_default_logger(previous_); }
  CapturedLog(const CapturedLog&) = delete;
  CapturedLog& operator=(const CapturedLog&) = delete;
  std::string text() const { return out_.str(); }

 private:
  std::ostringstream out_;
  std::shared_ptr<spdlog::logger> previous_;
};

TEST(Commands, EveryCommandAndItsResultIsInTheAuditTrail) {
  CapturedLog log;
  {
    Commands c({pmu(1)});
    auto ok = set_param(c, "avionics_voltage", 20.0);
    ok.sender = "ground-station-7";
    c.run(ok);
    auto denied = c.req(CommandKind::Reset);
    denied.sender = "ground-station-7";
    c.run(denied);
    // In a fleet the line names the vehicle too, as pmuctl names its devices.
    auto fleet = set_param(c, "avionics_voltage", 21.0);
    fleet.vehicle = "uav1";
    fleet.sender = "ground-station-7";
    c.run(fleet);
  }
  const std::string text = log.text();
  EXPECT_NE(text.find("audit: command t-3 from ground-station-7: set_parameter avionics_voltage=21 to uav1/sim0/1 -> "
                      "COMPLETED"),
            std::string::npos)
      << text;
  EXPECT_NE(
      text.find("audit: command t-1 from ground-station-7: set_parameter avionics_voltage=20 to sim0/1 -> COMPLETED"),
      std::string::npos)
      << text;
  EXPECT_NE(text.find("audit: command t-2 from ground-station-7: reset to sim0/1 -> DENIED: reset resets the PMU"),
            std::string::npos)
      << text;
}

// A client that asks again for a reply that was out for most of a second has a slow link:
// once two clients did, the service says once that a link profile exists (interface.md 7.3),
// and never when its config names the link.
TEST(Commands, ResendsLongAfterTheirReplySayOnceThatALinkProfileExists) {
  const std::string hint = "their link has a round trip or a loss a LAN does not have";
  for (const bool configured : {false, true}) {
    SCOPED_TRACE(configured ? "link configured" : "no link configured");
    CapturedLog log;
    std::uint64_t late = 0;
    {
      Commands c({pmu(1)});
      if (configured) c.service.link_configured();
      const auto resend_after = [&c](const char* sender, std::chrono::milliseconds out_for) {
        auto r = c.req(CommandKind::GetSerial);
        r.sender = sender;
        c.run(r);
        c.h.run_for(out_for);
        c.service.submit(r);  // answered again at once: the first one's reply
      };
      resend_after("a", 100ms);  // the service's own slowness, not the link's
      resend_after("b", 100ms);
      resend_after("a", 900ms);  // one client: possibly its reply reader matched late
      resend_after("a", 900ms);
      EXPECT_EQ(log.text().find(hint), std::string::npos) << log.text();
      resend_after("b", 800ms);  // a second client
      resend_after("c", 900ms);
      EXPECT_EQ(c.replies.size(), 12u) << "every resend answered again";
      late = c.service.counters().resends_after_reply;
    }
    const std::string text = log.text();
    EXPECT_EQ(late, 4u);
    const auto at = text.find(hint);
    if (configured) {
      EXPECT_EQ(at, std::string::npos) << text;
    } else {
      ASSERT_NE(at, std::string::npos) << text;
      EXPECT_EQ(text.find(hint, at + 1), std::string::npos) << "said once: " << text;
      EXPECT_NE(text.find("had published 0.8 s before"), std::string::npos) << text;
      EXPECT_NE(text.find("`link: {profile: radio}` here and `--link radio` on the ground"), std::string::npos) << text;
    }
  }
}

TEST(Commands, NetworkTextCannotForgeAuditLines) {
  CapturedLog log;
  {
    Commands c({pmu(1)});
    auto r = c.req(CommandKind::SetParameter);
    r.request_id = "x\n\x1b[2Jaudit: FORGED id";
    r.parameter = "volts\naudit: FORGED parameter";
    c.run(r);
    auto bus = c.req(CommandKind::GetSerial);
    bus.bus = "can\naudit: FORGED";
    c.run(bus);
  }
  std::istringstream lines(log.text());
  std::string line;
  int audit_lines = 0;
  while (std::getline(lines, line)) {
    // Every line is one the logger began (its pattern starts "[time]"): none was started by
    // a newline in a peer's text, and no terminal escape reaches the journal.
    EXPECT_EQ(line.rfind('[', 0), 0u) << line;
    EXPECT_EQ(line.find('\x1b'), std::string::npos) << line;
    audit_lines += line.find("audit: command") != std::string::npos;
  }
  EXPECT_EQ(audit_lines, 2) << log.text();
  EXPECT_NE(log.text().find("x\\x0A\\x1B[2Jaudit: FORGED id"), std::string::npos) << log.text();
}

}  // namespace
}  // namespace pmu::service::test

namespace pmu::service::test {
namespace {

// Request ids are unique per sender, not across senders (interface.md).
TEST(Commands, TheSameIdFromTwoSendersIsTwoCommands) {
  Commands c({pmu(1)});
  auto a = set_param(c, "avionics_voltage", 20.0);
  a.sender = "ground-a";
  auto b = set_param(c, "avionics_voltage", 16.5);
  b.sender = "ground-b";
  b.request_id = a.request_id;
  EXPECT_EQ(c.run(a).result, CommandResult::Completed);
  const auto r = c.run(b);
  EXPECT_EQ(r.result, CommandResult::Completed) << r.reason;
  EXPECT_DOUBLE_EQ(r.value, 16.5);
  EXPECT_EQ(sim_param(c, codec::Parameter::AvionicsVoltage), 165u);
}

TEST(Commands, AReusedIdWithOtherContentIsRejectedNotAnsweredWithTheOldReply) {
  Commands c({pmu(1)});
  auto first = set_param(c, "avionics_voltage", 20.0);
  EXPECT_EQ(c.run(first).result, CommandResult::Completed);
  c.h.clear_sent();
  auto reused = set_param(c, "avionics_voltage", 16.5);
  reused.request_id = first.request_id;
  const auto r = c.run(reused);
  EXPECT_EQ(r.result, CommandResult::Rejected);
  EXPECT_EQ(r.reason, "request id '" + first.request_id +
                          "' was already used by this sender for another command; not executed (use a new id)");
  c.h.run_for(100ms);
  EXPECT_TRUE(c.sent().empty());
  EXPECT_EQ(sim_param(c, codec::Parameter::AvionicsVoltage), 200u);
  EXPECT_EQ(c.service.counters().reused_ids, 1u);
  // The first command's answer is unchanged for a true resend.
  EXPECT_EQ(c.run(first).result, CommandResult::Completed);
}

TEST(Commands, AnExpiryFarInTheFutureIsHeldToTheCapAndExecuted) {
  Commands c({pmu(1)});
  for (std::uint64_t expires : {1ull << 63, ~0ull - 1, ~0ull}) {
    auto r = c.req(CommandKind::GetSerial);
    r.expires_at = expires;
    const auto reply = c.run(r);
    EXPECT_EQ(reply.result, CommandResult::Completed) << expires << ": " << reply.reason;
  }
}

TEST(Commands, FiftyThousandDistinctIdsKeepTheMemoryBounded) {
  PolicyConfig unlimited;
  unlimited.rate_per_second = 0;
  Commands c({pmu(1)}, unlimited);
  constexpr int kIds = 50000;
  for (int i = 0; i < kIds; ++i) {
    auto r = c.req(CommandKind::GetSerial);
    r.bus = "can9";  // answered at once: the test is about what is remembered
    c.service.submit(r);
    ASSERT_LE(c.service.remembered(), kRememberedRequests);
  }
  EXPECT_EQ(c.replies.size(), static_cast<std::size_t>(kIds));
  EXPECT_EQ(c.service.remembered(), kRememberedRequests);
}

}  // namespace
}  // namespace pmu::service::test
