// A client's pmu::v5::Command (dds/command_sample): every action put into a sample is the
// action the service's boundary reads back from it, so pmuctl and pmu-mavlink send what their
// confirm rules were judged on.
#include "pmu/dds/command_sample.hpp"

#include <gtest/gtest.h>

#include "pmu/codec/messages.hpp"

namespace pmu::dds {
namespace command_sample_test {  // named: the unity build joins this file with others of its target
namespace {

namespace act = service::action;

service::CommandSample sample_of(const pmu::v5::Command& c) {
  service::CommandSample s;
  s.request_id = "test-1";
  s.bus = "can0";
  s.address = 1;
  s.kind = static_cast<std::uint32_t>(c.kind());
  s.parameter = c.parameter().to_string();
  s.value = c.value();
  s.outputs = c.outputs();
  s.enable = c.enable() ? 1 : 0;
  s.groups = c.groups();
  return s;
}

TEST(CommandSample, EveryActionIsReadBackAsItself) {
  const service::CommandAction actions[] = {
      act::Get{codec::PacketId::Temperatures},
      act::Get{codec::PacketId::CrankingTime},
      act::SetParameter{codec::Parameter::AvionicsVoltage, 240},
      act::SetParameter{codec::Parameter::PacketPeriod, 1},
      act::SetParameter{codec::Parameter::UpperTemperatureLimit, 0},
      act::SetParameter{codec::Parameter::PowerUpState, 0x13},
      act::SetParameter{codec::Parameter::CanAddress, 65534},
      act::SetOutputs{0},
      act::EnableOutputs{codec::output_bit::Payload},
      act::DisableOutputs{codec::output_bit::AvionicsServo | codec::output_bit::ChargerB},
      act::SetGeneration{true},
      act::SetGeneration{false},
      act::RequestMeasurements{codec::group_bit::Voltages},
      act::EngineStart{},
      act::EngineStop{},
      act::Reset{},
      act::GetSerial{},
      act::GetFirmware{},
  };
  const service::Now now{std::chrono::system_clock::now(), std::chrono::steady_clock::now()};
  for (const auto& a : actions) {
    service::CommandRequest want;
    want.bus = "can0";
    want.address = 1;
    want.action = a;
    SCOPED_TRACE(service::describe(want));
    pmu::v5::Command c;
    put_action(a, c);
    const auto got = service::parse_command(sample_of(c), now, service::Lifetimes{});
    ASSERT_TRUE(got) << got.error();
    EXPECT_EQ(got->action.index(), a.index());
    EXPECT_EQ(service::describe(*got), service::describe(want));
  }
}

TEST(CommandSample, ResultsAndTheirNames) {
  EXPECT_STREQ(result_name(pmu::v5::COMPLETED), "COMPLETED");
  EXPECT_STREQ(result_name(pmu::v5::IN_PROGRESS), "IN_PROGRESS");
  EXPECT_EQ(command_result(pmu::v5::DENIED), service::CommandResult::Denied);
  // A newer service's result this client does not know: not done, as far as it can tell.
  EXPECT_EQ(command_result(static_cast<pmu::v5::CommandResult>(42)), service::CommandResult::Failed);
}

TEST(CommandSample, RequestIdsNameTheProgramHostAndProcessWithinTheContractsBound) {
  const auto prefix = request_id_prefix("pmu-mavlink", 16);
  EXPECT_EQ(prefix.rfind("pmu-mavlink-", 0), 0U);
  EXPECT_EQ(prefix.back(), '-');
  // pmu-mavlink's ids: the prefix and a 20-digit number at most.
  EXPECT_LE(prefix.size() + 20, service::kMaxRequestIdLength);
  const auto id = request_id("pmuctl");
  EXPECT_EQ(id.rfind(request_id_prefix("pmuctl"), 0), 0U);
  EXPECT_LE(id.size(), service::kMaxRequestIdLength);
  EXPECT_NE(id, request_id("pmuctl"));
}

}  // namespace
}  // namespace command_sample_test
}  // namespace pmu::dds
