// The command boundary (command.hpp): every possible pmu::v5::Command sample gives a typed
// request or one rejection reason, never a crash. Table-driven over the edges of each field:
// the kind's number, the booleans' bytes, every double class, the expiry from 0 to 2^64-1,
// string lengths at and past the IDL's bounds.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "command_sample.hpp"
#include "pmu/command/command.hpp"

namespace pmu::service {
namespace {

using namespace std::chrono_literals;

// A fixed "now" a little after 2023-11-14 (the wall clock) and an arbitrary steady clock.
const Now kNow{std::chrono::system_clock::time_point(std::chrono::seconds(1700000000)),
               std::chrono::steady_clock::time_point(std::chrono::hours(1000))};
constexpr std::uint64_t kNowNs = 1700000000ull * 1000000000ull;

CommandSample sample(CommandKind kind, const char* parameter = "", double value = 0) {
  return command_sample(kind, 0, parameter, value);
}

struct Rejected {
  const char* what;
  CommandSample s;
  const char* reason;  // the whole reason
};

TEST(Boundary, EverySampleThatCannotBeExecutedGetsItsReason) {
  const double inf = std::numeric_limits<double>::infinity();
  auto with = [](CommandSample s, auto&& change) {
    change(s);
    return s;
  };
  const Rejected cases[] = {
      {"empty id", with(sample(CommandKind::GetSerial), [](auto& s) { s.request_id.clear(); }), "request_id is empty"},
      {"id over 63 bytes", with(sample(CommandKind::GetSerial), [](auto& s) { s.request_id = std::string(64, 'x'); }),
       "request_id is 64 bytes long; at most 63 are allowed"},
      {"bus over 15 bytes", with(sample(CommandKind::GetSerial), [](auto& s) { s.bus = std::string(16, 'b'); }),
       "bus is 16 bytes long; at most 15 are allowed"},
      {"parameter over 31 bytes", sample(CommandKind::Get, "avionics_voltage_avionics_voltag"),
       "parameter is 32 bytes long; at most 31 are allowed"},
      {"kind 12", with(sample(CommandKind::Get), [](auto& s) { s.kind = 12; }), "unknown command kind 12"},
      {"kind 2^32-1", with(sample(CommandKind::Get), [](auto& s) { s.kind = 0xFFFFFFFFu; }),
       "unknown command kind 4294967295"},
      {"confirm byte 2", with(sample(CommandKind::Reset), [](auto& s) { s.confirm = 2; }),
       "confirm is not a boolean (byte 0x02; 0 or 1 expected)"},
      {"confirm byte 0xFF", with(sample(CommandKind::Reset), [](auto& s) { s.confirm = 0xFF; }),
       "confirm is not a boolean (byte 0xFF; 0 or 1 expected)"},
      {"enable byte 2", with(sample(CommandKind::SetGeneration), [](auto& s) { s.enable = 2; }),
       "enable is not a boolean (byte 0x02; 0 or 1 expected)"},
      {"NaN", sample(CommandKind::SetParameter, "avionics_voltage", std::nan("")),
       "avionics_voltage: value nan is not a number"},
      {"+Inf", sample(CommandKind::SetParameter, "avionics_voltage", inf),
       "avionics_voltage: value inf is not a number"},
      {"-Inf", sample(CommandKind::SetParameter, "payload_voltage", -inf),
       "payload_voltage: value -inf is not a number"},
      {"huge", sample(CommandKind::SetParameter, "avionics_voltage", 1e308),
       "value 1e+308 V out of range 12.0..24.0 V for avionics_voltage"},
      {"denormal voltage", sample(CommandKind::SetParameter, "avionics_voltage", 5e-324),
       "value 4.940656458e-324 V out of range 12.0..24.0 V for avionics_voltage"},
      {"unknown parameter, text escaped", sample(CommandKind::SetParameter, "volts\n\x1b[2J"),
       "unknown parameter 'volts\\x0A\\x1B[2J'"},
      {"get of a command packet", sample(CommandKind::Get, "reset"), "unknown parameter 'reset'"},
      {"undefined output bits", with(sample(CommandKind::SetOutputs), [](auto& s) { s.outputs = 0xF1; }),
       "unknown output bits 0xF0 (outputs are bits 0..3)"},
      {"disable nothing", sample(CommandKind::DisableOutputs), "no output named"},
      {"undefined group bits", with(sample(CommandKind::RequestMeasurements), [](auto& s) { s.groups = 0x21; }),
       "unknown measurement group bits 0x20 (groups are bits 0..4)"},
      {"broadcast get", with(sample(CommandKind::GetSerial), [](auto& s) { s.address = 0xFFFF; }),
       "broadcast (65535) is only accepted for engine_stop"},
      {"expires_at 1 ns after the epoch", with(sample(CommandKind::GetSerial), [](auto& s) { s.expires_at = 1; }),
       "expired 1699999999999 ms ago"},
      {"expires_at now", with(sample(CommandKind::GetSerial), [](auto& s) { s.expires_at = kNowNs; }),
       "expired 0 ms ago"},
      {"expired a second ago",
       with(sample(CommandKind::GetSerial), [](auto& s) { s.expires_at = kNowNs - 1000000000ull; }),
       "expired 1000 ms ago"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.what);
    const auto r = parse_command(c.s, kNow, Lifetimes{});
    ASSERT_FALSE(r.ok());
    EXPECT_EQ(r.error(), c.reason);
  }
}

TEST(Boundary, EveryExpiryFromNowTo2To64Minus1IsALiveRequestHeldToTheCap) {
  const Lifetimes lt{10s, 60s};
  struct ExpiryCase {
    std::uint64_t expires_at;
    std::chrono::nanoseconds lives;
  };
  const ExpiryCase cases[] = {
      {0, 10s},  // the default lifetime
      {kNowNs + 1, 1ns},
      {kNowNs + 5000000000ull, 5s},
      {kNowNs + 60000000000ull, 60s},
      {kNowNs + 60000000001ull, 60s},
      {(1ull << 63) - 1, 60s},
      {1ull << 63, 60s},  // killed the service before: chrono overflow
      {~0ull - 1, 60s},
      {~0ull, 60s},  // was "expired 1796027167570 ms ago"
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.expires_at);
    auto s = sample(CommandKind::GetSerial);
    s.expires_at = c.expires_at;
    const auto r = parse_command(s, kNow, lt);
    ASSERT_TRUE(r.ok()) << r.error();
    EXPECT_EQ(r->expires - kNow.steady, c.lives);
  }
}

TEST(Boundary, SetValuesAreCarriedInWireUnitsAsTheyWillBeSent) {
  struct SetCase {
    const char* parameter;
    double value;
    codec::Parameter p;
    std::uint32_t raw;
  };
  const SetCase cases[] = {
      {"avionics_voltage", 24.0, codec::Parameter::AvionicsVoltage, 240},
      {"avionics_voltage", 12.3f, codec::Parameter::AvionicsVoltage, 123},  // a float32 from DDS
      {"upper_temperature_limit", 0.0005, codec::Parameter::UpperTemperatureLimit, 0},
      {"upper_temperature_limit", -0.0009, codec::Parameter::UpperTemperatureLimit, 0},
      {"upper_temperature_limit", 5e-324, codec::Parameter::UpperTemperatureLimit, 0},
      {"power_up_state", -0.0004, codec::Parameter::PowerUpState, 0},
      {"power_up_state", 33.0, codec::Parameter::PowerUpState, 33},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(std::string(c.parameter) + " " + std::to_string(c.value));
    const auto r = parse_command(sample(CommandKind::SetParameter, c.parameter, c.value), kNow, Lifetimes{});
    ASSERT_TRUE(r.ok()) << r.error();
    const auto& set = std::get<action::SetParameter>(r->action);
    EXPECT_EQ(set.parameter, c.p);
    EXPECT_EQ(set.raw, c.raw);
  }
}

TEST(Boundary, EachKindBecomesItsOwnTypedAlternative) {
  for (std::uint32_t k = 0; k < kCommandKindCount; ++k) {
    auto s = sample(static_cast<CommandKind>(k), "outputs");
    s.outputs = 0x01;
    s.confirm = 1;
    if (k == static_cast<std::uint32_t>(CommandKind::SetParameter)) {
      s.parameter = "servo_voltage";
      s.value = 6.0;
    }
    const auto r = parse_command(s, kNow, Lifetimes{});
    ASSERT_TRUE(r.ok()) << k << ": " << r.error();
    EXPECT_EQ(static_cast<std::uint32_t>(r->kind()), k);
    EXPECT_TRUE(r->confirm);
  }
  // Zero groups on the wire asks for all five.
  const auto m = parse_command(sample(CommandKind::RequestMeasurements), kNow, Lifetimes{});
  ASSERT_TRUE(m.ok());
  EXPECT_EQ(std::get<action::RequestMeasurements>(m->action).groups, 0x1F);
  // Broadcast is for the safety stop only.
  auto stop = sample(CommandKind::EngineStop);
  stop.address = 0xFFFF;
  EXPECT_TRUE(parse_command(stop, kNow, Lifetimes{}).ok());
}

TEST(Boundary, PrintableEscapesEverythingThatCouldForgeOrGarbleALogLine) {
  EXPECT_EQ(printable("plain-id_42"), "plain-id_42");
  EXPECT_EQ(printable("a\nb"), "a\\x0Ab");
  EXPECT_EQ(printable("\x1b[2Jaudit: FORGED"), "\\x1B[2Jaudit: FORGED");
  EXPECT_EQ(printable("back\\slash"), "back\\\\slash");
  EXPECT_EQ(printable(std::string("nul\0byte", 8)), "nul\\x00byte");
  EXPECT_EQ(printable("\xc3\xa9"), "\\xC3\\xA9");  // UTF-8 is shown as bytes
  EXPECT_EQ(printable(std::string(100, 'x'), 10), "xxxxxxxxxx...");
}

TEST(Boundary, FingerprintTellsAResendFromAnotherCommand) {
  const auto a = sample(CommandKind::SetParameter, "avionics_voltage", 24.0);
  auto resend = a;
  resend.expires_at = 123;  // a fresh deadline: still the same command
  resend.sender = "someone";
  resend.request_id = "other";
  EXPECT_EQ(content_fingerprint(a), content_fingerprint(resend));
  for (auto change : std::initializer_list<void (*)(CommandSample&)>{
           [](CommandSample& s) { s.value = 16.5; }, [](CommandSample& s) { s.address = 2; },
           [](CommandSample& s) { s.bus = "can1"; }, [](CommandSample& s) { s.parameter = "payload_voltage"; },
           [](CommandSample& s) { s.kind = 0; }, [](CommandSample& s) { s.confirm = 1; },
           [](CommandSample& s) { s.outputs = 1; }, [](CommandSample& s) { s.enable = 1; },
           [](CommandSample& s) { s.groups = 1; }}) {
    auto other = a;
    change(other);
    EXPECT_NE(content_fingerprint(a), content_fingerprint(other));
  }
}

}  // namespace
}  // namespace pmu::service
