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
      // Nothing known of the unit: its internal temperature may be anything up to 127 degC.
      {"T_U 80, temperature unknown", make(CommandKind::SetParameter, 0, "upper_temperature_limit", 80), true},
      {"T_U 128, temperature unknown", make(CommandKind::SetParameter, 0, "upper_temperature_limit", 128), false},
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
      // Without temperatures and status the alarms that read them go blind.
      {"PS voltages only", make(CommandKind::SetParameter, 0, "packets_streamed", 1), true},
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

DeviceUse streaming_or_not(bool streaming) {
  DeviceUse u;
  u.streaming = streaming;
  return u;
}

// The service asks a polled device for its packets: PS = 0 takes nothing from it.
TEST(Policy, StopStreamingOnlyForADeviceTheServiceListensTo) {
  const PolicyConfig p;
  const auto ps0 = make(CommandKind::SetParameter, 0, "packets_streamed", 0);
  const auto streaming = check_policy(ps0, p, streaming_or_not(true));
  EXPECT_EQ(streaming.result, CommandResult::Denied);
  EXPECT_EQ(streaming.reason,
            "set_parameter sets packets_streamed to 0: the PMU stops the telemetry this service listens for, and "
            "goes OFFLINE: it needs confirm (pmuctl --confirm); rule stop_streaming");
  EXPECT_TRUE(check_policy(ps0, p, streaming_or_not(false)).allowed());
  PolicyConfig off;
  off.confirm[static_cast<std::size_t>(ConfirmRule::StopStreaming)] = false;
  EXPECT_TRUE(check_policy(ps0, off, streaming_or_not(true)).allowed());
  EXPECT_EQ(
      parse_config("policy:\n  confirm: [stop_streaming]\nbuses:\n  - interface: can0\n    discover: true\n", "p.yaml")
          .policy.confirm,
      (std::array<bool, kConfirmRuleCount>{false, false, false, false, false, false, true, false}));
  EXPECT_EQ(parse_config("policy:\n  confirm: [blind_monitoring]\nbuses:\n  - interface: can0\n    discover: true\n",
                         "p.yaml")
                .policy.confirm,
            (std::array<bool, kConfirmRuleCount>{false, false, false, false, false, false, false, true}));
}

// A unit's internal temperature and what its rules read, as the dispatcher fills them.
DeviceUse at(std::optional<double> internal, bool streaming = true, std::uint8_t needed = kRulePackets) {
  DeviceUse u;
  u.streaming = streaming;
  u.packets_needed = needed;
  u.internal_temperature = internal;
  return u;
}

struct EffectCase {
  const char* what;
  CommandRequest request;
  DeviceUse device;
  std::optional<ConfirmRule> rule;
};

// The rules judged by effect: what the set does with the values the unit has now (v1.9 5.14:
// T_U at or below the internal temperature shuts it down; table 13: PS selects what is
// streamed). docs/safety.md H2, H3, H6.
TEST(Policy, RulesJudgedByWhatTheSetDoesToTheUnitNow) {
  const auto tu = [](double v) { return make(CommandKind::SetParameter, 0, "upper_temperature_limit", v); };
  const auto ps = [](double v) { return make(CommandKind::SetParameter, 0, "packets_streamed", v); };
  using G = std::uint8_t;
  constexpr G V = codec::group_bit::Voltages, C = codec::group_bit::Currents, E = codec::group_bit::BatteryEnergy,
              T = codec::group_bit::Temperatures, S = codec::group_bit::Status;
  const EffectCase cases[] = {
      {"T_U 1 at 35 degC", tu(1), at(35), ConfirmRule::ThermalShutdown},
      {"T_U 35 at 35 degC", tu(35), at(35), ConfirmRule::ThermalShutdown},
      {"T_U 36 at 35 degC", tu(36), at(35), std::nullopt},
      {"T_U 90 at 95 degC", tu(90), at(95), ConfirmRule::ThermalShutdown},
      {"T_U 85 at 35 degC", tu(85), at(35), std::nullopt},
      {"T_U 0 at -20 degC", tu(0), at(-20), ConfirmRule::ThermalShutdown},
      {"T_U 1 at -20 degC", tu(1), at(-20), std::nullopt},
      {"T_U 255 at 127 degC", tu(255), at(127), std::nullopt},
      {"T_U 1, temperature unknown", tu(1), at(std::nullopt), ConfirmRule::ThermalShutdown},
      {"T_U 127, temperature unknown", tu(127), at(std::nullopt), ConfirmRule::ThermalShutdown},
      {"T_U 128, temperature unknown", tu(128), at(std::nullopt), std::nullopt},
      {"T_U 255, temperature unknown", tu(255), at(std::nullopt), std::nullopt},
      {"PS voltages, streaming", ps(V), at(35), ConfirmRule::BlindMonitoring},
      {"PS without status, streaming", ps(V | C | E | T), at(35), ConfirmRule::BlindMonitoring},
      {"PS without temperatures, streaming", ps(V | S), at(35), ConfirmRule::BlindMonitoring},
      {"PS what the rules read", ps(V | T | S), at(35), std::nullopt},
      {"PS everything", ps(V | C | E | T | S), at(35), std::nullopt},
      {"PS voltages, polled", ps(V), at(35, false), std::nullopt},
      {"PS 0, streaming", ps(0), at(35), ConfirmRule::StopStreaming},
      {"PS 0, polled", ps(0), at(35, false), std::nullopt},
      // Set-points within their ranges switch nothing off, whatever their bits look like.
      {"V_B 25.2 V", make(CommandKind::SetParameter, 0, "battery_voltage", 25.2), at(35), std::nullopt},
      {"V_S 5.0 V", make(CommandKind::SetParameter, 0, "servo_voltage", 5.0), at(std::nullopt), std::nullopt},
      // A unit whose temperature alarms are all off needs no temperatures.
      {"PS without temperatures, none needed", ps(V | S), at(35, true, V | S), std::nullopt},
      {"PS without status, status needed", ps(V | T), at(35, true, S), ConfirmRule::BlindMonitoring},
  };
  PolicyConfig p;
  for (const auto& c : cases) {
    SCOPED_TRACE(c.what);
    EXPECT_EQ(confirm_rule_for(c.request, c.device), c.rule);
    const auto v = check_policy(c.request, p, c.device);
    EXPECT_EQ(v.allowed(), !c.rule) << v.reason;
    if (c.rule) {
      EXPECT_NE(v.reason.find("rule " + std::string(to_string(*c.rule))), std::string::npos) << v.reason;
      CommandRequest confirmed = c.request;
      confirmed.confirm = true;
      EXPECT_TRUE(check_policy(confirmed, p, c.device).allowed());
      PolicyConfig off;
      off.confirm[static_cast<std::size_t>(*c.rule)] = false;
      EXPECT_TRUE(check_policy(c.request, off, c.device).allowed()) << "the rule can be switched off";
    }
  }
}

// The DENIED reason says the values the rule was judged on.
TEST(Policy, AReasonJudgedByEffectNamesTheValues) {
  const PolicyConfig p;
  const auto tu1 = make(CommandKind::SetParameter, 0, "upper_temperature_limit", 1);
  EXPECT_EQ(check_policy(tu1, p, at(35)).reason,
            "set_parameter sets the upper temperature limit to 1 degC, at or below the unit's internal temperature "
            "35 degC: it forces thermal shutdown, which stops charging: it needs confirm (pmuctl --confirm); rule "
            "thermal_shutdown");
  EXPECT_EQ(check_policy(tu1, p, at(std::nullopt)).reason,
            "set_parameter sets the upper temperature limit to 1 degC while the unit's internal temperature is unknown "
            "(safe from 128 degC): it may force thermal shutdown, which stops charging: it needs confirm (pmuctl "
            "--confirm); rule thermal_shutdown");
  EXPECT_EQ(check_policy(make(CommandKind::SetParameter, 0, "packets_streamed", 1), p, at(35)).reason,
            "set_parameter drops temperatures, status from packets_streamed: the readiness and alarm rules that read "
            "them go blind: it needs confirm (pmuctl --confirm); rule blind_monitoring");
}

// DeviceUse's worst case is what the alarm table's PMU rows read.
TEST(Policy, TheRulePacketsAreWhatTheAlarmTableReads) {
  EXPECT_EQ(alarms::packets_read(alarms::DeviceSettings{}), kRulePackets);
  alarms::DeviceSettings no_temperatures;
  for (const auto c : {alarms::Code::InternalOverTemperature, alarms::Code::StarterOverTemperature,
                       alarms::Code::GeneratorOverTemperature, alarms::Code::BatteryAOverTemperature,
                       alarms::Code::BatteryBOverTemperature})
    no_temperatures[c].enabled = false;
  EXPECT_EQ(alarms::packets_read(no_temperatures), codec::group_bit::Voltages | codec::group_bit::Status);
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
  EXPECT_THROW((void)parse_config("policy:\n  confirm: [everything]\nbuses:\n  - interface: can0\n    discover: true\n",
                                  "p.yaml"),
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
