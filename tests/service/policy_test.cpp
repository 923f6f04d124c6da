// The safety policy on its own: which requests need confirm, deny lists, the rate limiter,
// and the config keys that set them.
#include <gtest/gtest.h>

#include "command_sample.hpp"
#include "pmu/command/policy.hpp"
#include "pmu/config/config.hpp"

namespace pmu::service {
namespace {

// A request as the boundary makes it from a sample with these fields.
CommandRequest make(CommandKind k, std::uint8_t outputs = 0, const char* param = "", double value = 0) {
  const auto r = parse_command(command_sample(k, outputs, param, value), Now{}, Lifetimes{});
  EXPECT_TRUE(r.ok()) << r.error();
  return r.ok() ? *r : CommandRequest{};
}

struct Case {
  const char* what;
  CommandRequest request;
  bool needs_confirm;
};

TEST(Policy, ConfirmRulesByDefault) {
  const Case cases[] = {
      {"disable avionics", make(CommandKind::DisableOutputs, 0x01), true},
      {"disable avionics and payload", make(CommandKind::DisableOutputs, 0x03), true},
      {"disable payload", make(CommandKind::DisableOutputs, 0x02), false},
      {"set outputs keeping avionics", make(CommandKind::SetOutputs, 0x0F), false},
      {"set outputs dropping avionics", make(CommandKind::SetOutputs, 0x0E), true},
      {"enable anything", make(CommandKind::EnableOutputs, 0x0F), false},
      {"reset", make(CommandKind::Reset), true},
      {"engine start", make(CommandKind::EngineStart), true},
      {"engine stop", make(CommandKind::EngineStop), false},
      {"can address", make(CommandKind::SetParameter, 0, "can_address", 3), true},
      {"T_U 0", make(CommandKind::SetParameter, 0, "upper_temperature_limit", 0), true},
      {"T_U 80", make(CommandKind::SetParameter, 0, "upper_temperature_limit", 80), false},
      // Judged on what the wire will carry: these round to 0.
      {"T_U 0.0005", make(CommandKind::SetParameter, 0, "upper_temperature_limit", 0.0005), true},
      {"T_U -0.0009", make(CommandKind::SetParameter, 0, "upper_temperature_limit", -0.0009), true},
      {"S0 -0.0004", make(CommandKind::SetParameter, 0, "power_up_state", -0.0004), true},
      {"S0 0.0004 + avionics", make(CommandKind::SetParameter, 0, "power_up_state", 1.0004), false},
      {"S0 with avionics", make(CommandKind::SetParameter, 0, "power_up_state", 0x21), false},
      {"S0 without avionics", make(CommandKind::SetParameter, 0, "power_up_state", 0x20), true},
      {"a voltage", make(CommandKind::SetParameter, 0, "avionics_voltage", 24), false},
      // PS = 0 silences a streaming PMU (v1.9 table 13: PS selects the packets streamed).
      {"PS 0", make(CommandKind::SetParameter, 0, "packets_streamed", 0), true},
      {"PS 0.0004", make(CommandKind::SetParameter, 0, "packets_streamed", 0.0004), true},
      {"PS voltages only", make(CommandKind::SetParameter, 0, "packets_streamed", 1), false},
      {"PS every packet", make(CommandKind::SetParameter, 0, "packets_streamed", 0x1F), false},
      {"PP 0.1 s", make(CommandKind::SetParameter, 0, "packet_period", 0.1), false},
      {"generation off", make(CommandKind::SetGeneration), false},
  };
  const PolicyConfig p;
  for (const auto& c : cases) {
    SCOPED_TRACE(c.what);
    const auto v = check_policy(c.request, p);
    EXPECT_EQ(v.allowed(), !c.needs_confirm);
    if (c.needs_confirm) {
      EXPECT_EQ(v.result, CommandResult::Denied);
      CommandRequest confirmed = c.request;
      confirmed.confirm = true;
      EXPECT_TRUE(check_policy(confirmed, p).allowed());
    }
  }
}

// The service asks a polled device for its packets: PS = 0 takes nothing from it.
TEST(Policy, StopStreamingOnlyForADeviceTheServiceListensTo) {
  const PolicyConfig p;
  const auto ps0 = make(CommandKind::SetParameter, 0, "packets_streamed", 0);
  const auto streaming = check_policy(ps0, p, DeviceUse{true});
  EXPECT_EQ(streaming.result, CommandResult::Denied);
  EXPECT_EQ(streaming.reason,
            "set_parameter sets packets_streamed to 0: the PMU stops the telemetry this service listens for, and "
            "goes OFFLINE: it needs confirm (pmuctl --confirm); rule stop_streaming");
  EXPECT_TRUE(check_policy(ps0, p, DeviceUse{false}).allowed());
  PolicyConfig off;
  off.confirm[static_cast<std::size_t>(ConfirmRule::StopStreaming)] = false;
  EXPECT_TRUE(check_policy(ps0, off, DeviceUse{true}).allowed());
  EXPECT_EQ(parse_config("policy:\n  confirm: [stop_streaming]\nbuses:\n  - interface: can0\n    discover: true\n",
                         "p.yaml")
                .policy.confirm,
            (std::array<bool, kConfirmRuleCount>{false, false, false, false, false, false, true}));
}

TEST(Policy, RulesCanBeSwitchedOffAndKindsDenied) {
  const Config c = parse_config(R"(policy:
  confirm: [reset]
  deny: [engine_start, set_parameter]
  rate_limit: 5
  burst: 2
  command_lifetime: 2.5
buses:
  - interface: can0
    discover: true
)",
                                "p.yaml");
  EXPECT_TRUE(check_policy(make(CommandKind::DisableOutputs, 0x01), c.policy).allowed());
  EXPECT_FALSE(check_policy(make(CommandKind::Reset), c.policy).allowed());
  auto start = make(CommandKind::EngineStart);
  start.confirm = true;
  EXPECT_EQ(check_policy(start, c.policy).reason, "engine_start is denied by the service's policy");
  EXPECT_FALSE(check_policy(make(CommandKind::SetParameter, 0, "avionics_voltage", 24), c.policy).allowed());
  EXPECT_TRUE(check_policy(make(CommandKind::EngineStop), c.policy).allowed());
  EXPECT_DOUBLE_EQ(c.policy.rate_per_second, 5);
  EXPECT_EQ(c.policy.lifetimes.default_lifetime, std::chrono::milliseconds(2500));
}

TEST(Policy, EngineStopCannotBeDeniedByConfig) {
  try {
    (void)parse_config("policy:\n  deny: [engine_stop]\nbuses:\n  - interface: can0\n    discover: true\n", "p.yaml");
    ADD_FAILURE() << "accepted";
  } catch (const ConfigError& e) {
    EXPECT_EQ(std::string(e.what()), "p.yaml:2: engine_stop cannot be denied: it is the safety stop");
  }
  EXPECT_THROW((void)parse_config("policy:\n  confirm: [everything]\nbuses:\n  - interface: can0\n    discover: true\n", "p.yaml"),
               ConfigError);
}

TEST(Policy, LifetimesAndTheirCap) {
  const auto parse = [](const std::string& policy) {
    return parse_config("policy:\n" + policy + "buses:\n  - interface: can0\n    discover: true\n", "p.yaml");
  };
  const auto defaults = parse("  rate_limit: 20\n").policy.lifetimes;
  EXPECT_EQ(defaults.default_lifetime, std::chrono::seconds(10));
  EXPECT_EQ(defaults.max_lifetime, std::chrono::seconds(60));
  EXPECT_EQ(parse("  max_command_lifetime: 5\n  command_lifetime: 2\n").policy.lifetimes.max_lifetime,
            std::chrono::seconds(5));
  // Raising only the default lifetime raises the cap with it.
  EXPECT_EQ(parse("  command_lifetime: 120\n").policy.lifetimes.max_lifetime, std::chrono::seconds(120));
  try {
    (void)parse("  command_lifetime: 20\n  max_command_lifetime: 5\n");
    ADD_FAILURE() << "accepted";
  } catch (const ConfigError& e) {
    EXPECT_EQ(std::string(e.what()), "p.yaml:3: max_command_lifetime must be at least command_lifetime");
  }
}

TEST(Policy, RateLimiterIsATokenBucket) {
  RateLimiter r(2, 3);  // 2/s, burst 3
  const auto t0 = std::chrono::steady_clock::time_point{} + std::chrono::seconds(100);
  EXPECT_TRUE(r.allow(t0));
  EXPECT_TRUE(r.allow(t0));
  EXPECT_TRUE(r.allow(t0));
  EXPECT_FALSE(r.allow(t0));
  EXPECT_FALSE(r.allow(t0 + std::chrono::milliseconds(400)));
  EXPECT_TRUE(r.allow(t0 + std::chrono::milliseconds(600)));  // 1.2 tokens refilled, 1 used
  RateLimiter unlimited(0, 1);
  for (int i = 0; i < 100; ++i) EXPECT_TRUE(unlimited.allow(t0));
}

}  // namespace
}  // namespace pmu::service
