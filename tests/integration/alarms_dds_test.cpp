// pmu/alarms over real Fast DDS: the publisher's samples as interface.md 1.6 defines them,
// and a reader that joins late gets every alarm's current state at once.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <map>

#include "pmu/dds/dds_context.hpp"
#include "pmu/endpoints/dds_publisher.hpp"
#include "pmu/idl/alarmsPubSubTypes.h"
#include "pmu/idl/topics.hpp"
#include "support/domain.hpp"
#include "support/wait.hpp"

namespace pmu::service::test {
namespace {

using namespace eprosima::fastdds::dds;
using namespace std::chrono_literals;

AlarmReport report(alarms::Code code, alarms::AlarmState state, double value, std::chrono::seconds since,
                   alarms::DeviceKind source = alarms::DeviceKind::Pmu, std::uint16_t device = 1) {
  AlarmReport a;
  a.bus = "sim0";
  a.source = source;
  a.device = device;
  a.code = code;
  a.severity = alarms::spec_of(code).severity;
  a.state = state;
  a.value = value;
  a.limit = alarms::spec_of(code).limit;
  a.since = std::chrono::system_clock::time_point(since);
  a.message = std::string(alarms::spec_of(code).subject) + " test";
  return a;
}

TEST(DdsAlarms, ALateJoinerGetsEveryAlarmInItsLatestStateWithItsFields) {
  dds::DdsContext service_side(pmu::test::exclusive_dds_domain(), "", "pmu-service-test");
  DdsPublisher publisher(service_side, 3s, "uav1");
  using S = alarms::AlarmState;
  publisher.on_alarm(report(alarms::Code::ThermalShutdown, S::ActiveUnacknowledged, 1, 1000s));
  publisher.on_alarm(report(alarms::Code::BatteryALowVoltage, S::ActiveUnacknowledged, 20.1, 1001s));
  publisher.on_alarm(report(alarms::Code::ThermalShutdown, S::ClearedUnacknowledged, 0, 1002s));
  publisher.on_alarm(
      report(alarms::Code::BusErrorPassive, S::ActiveUnacknowledged, 1, 1003s, alarms::DeviceKind::Bus, 0));

  dds::DdsContext client(pmu::test::exclusive_dds_domain(), "", "reader-test");
  DataReader& reader =
      client.reader(client.topic(topics::kAlarms, TypeSupport(new pmu::v5::AlarmPubSubType())), qos_profiles::kAlarms);
  std::map<std::string, pmu::v5::Alarm> latest;
  ASSERT_TRUE(pmu::test::wait_until(
      [&] {
        pmu::v5::Alarm a;
        SampleInfo info;
        while (reader.take_next_sample(&a, &info) == ReturnCode_t::RETCODE_OK)
          if (info.valid_data) latest[a.code().to_string()] = a;
        return latest.size() == 3 && latest["thermal_shutdown"].state() == pmu::v5::ALARM_CLEARED_UNACKNOWLEDGED;
      },
      20s, 10ms))
      << latest.size() << " alarms";

  const auto& thermal = latest["thermal_shutdown"];
  EXPECT_EQ(thermal.vehicle(), "uav1");
  EXPECT_EQ(thermal.bus(), "sim0");
  EXPECT_EQ(thermal.device(), 1);
  EXPECT_EQ(thermal.kind(), pmu::v5::SOURCE_PMU);
  EXPECT_EQ(thermal.severity(), pmu::v5::SEVERITY_CRITICAL);
  EXPECT_TRUE(std::isnan(thermal.value())) << "a flag has no value";
  EXPECT_TRUE(std::isnan(thermal.limit()));
  EXPECT_EQ(thermal.since(), 1002000000000ull);
  EXPECT_EQ(thermal.message(), "thermal shutdown test");

  const auto& low = latest["battery_a_low_voltage"];
  EXPECT_EQ(low.state(), pmu::v5::ALARM_ACTIVE_UNACKNOWLEDGED);
  EXPECT_EQ(low.severity(), pmu::v5::SEVERITY_WARNING);
  EXPECT_FLOAT_EQ(low.value(), 20.1f);
  EXPECT_FLOAT_EQ(low.limit(), static_cast<float>(alarms::spec_of(alarms::Code::BatteryALowVoltage).limit));

  const auto& bus = latest["bus_error_passive"];
  EXPECT_EQ(bus.kind(), pmu::v5::SOURCE_BUS);
  EXPECT_EQ(bus.device(), 0);
}

}  // namespace
}  // namespace pmu::service::test
