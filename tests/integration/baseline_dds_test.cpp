// pmu/baseline over real Fast DDS (interface.md 1.9): one instance per configured PMU with a
// baseline, a disposed one for a PMU without, and a reader that joins later gets both at once.
#include <gtest/gtest.h>

#include <chrono>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/InstanceState.hpp>
#include <map>
#include <set>

#include "pmu/dds/baseline_sample.hpp"
#include "pmu/dds/dds_context.hpp"
#include "pmu/endpoints/dds_publisher.hpp"
#include "pmu/idl/statePubSubTypes.h"
#include "pmu/idl/topics.hpp"
#include "support/domain.hpp"
#include "support/wait.hpp"

namespace pmu::service::baseline_dds_test {
namespace {

using namespace eprosima::fastdds::dds;
using namespace std::chrono_literals;

TEST(DdsBaseline, ALateJoinerGetsEachBaselineAndTheDisposalOfEveryOtherPmu) {
  BusConfig bus;
  bus.name = "can0";
  DeviceConfig with;
  with.address = 1;
  with.baseline_file = "baselines/pmu1.yaml";
  with.baseline = *baseline::read_config_file("device:\n  serial: 1001\nparameters:\n  avionics_voltage: 22.0\n");
  DeviceConfig without;
  without.address = 2;
  bus.devices = {with, without};

  dds::DdsContext service_side(pmu::test::exclusive_dds_domain(), "", "pmu-service-test");
  DdsPublisher publisher(service_side, 3s, "uav1");
  publisher.publish_baselines({bus});
  // A PMU the configuration does not name (found on the bus): none either.
  publisher.on_health(DeviceKey{"can0", 7, DeviceKind::Pmu}, HealthReport{});

  dds::DdsContext client(pmu::test::exclusive_dds_domain(), "", "reader-test");
  DataReader& reader = client.reader(client.topic(topics::kBaseline, TypeSupport(new pmu::v5::BaselinePubSubType())),
                                     qos_profiles::kState);
  std::map<std::uint16_t, pmu::v5::Baseline> got;
  std::set<InstanceHandle_t> disposed;
  pmu::v5::Baseline key;
  key.vehicle("uav1");
  key.bus("can0");
  key.address(2);
  InstanceHandle_t without_handle;
  ASSERT_TRUE(reader.type().get_key(&key, &without_handle));
  key.address(7);
  InstanceHandle_t found_handle;
  ASSERT_TRUE(reader.type().get_key(&key, &found_handle));
  // PMUs 2 and 7 have none, and say so: their instances are disposed, so a reader need not
  // wait to know.
  ASSERT_TRUE(pmu::test::wait_until(
      [&] {
        pmu::v5::Baseline b;
        SampleInfo info;
        while (reader.take_next_sample(&b, &info) == ReturnCode_t::RETCODE_OK)
          if (info.valid_data)
            got[b.address()] = b;
          else if (info.instance_state == NOT_ALIVE_DISPOSED_INSTANCE_STATE)
            disposed.insert(info.instance_handle);
        return got.count(1) && disposed.count(without_handle) && disposed.count(found_handle);
      },
      20s, 10ms))
      << got.size() << " baseline(s), " << disposed.size() << " disposed";
  EXPECT_EQ(got.size(), 1u) << "PMU 2 has no baseline";
  EXPECT_EQ(disposed.size(), 2u) << "PMU 1 has one";
  const auto& one = got.at(1);
  EXPECT_EQ(one.vehicle(), "uav1");
  EXPECT_EQ(one.bus(), "can0");
  EXPECT_EQ(one.file(), "baselines/pmu1.yaml") << "as configured";
  EXPECT_TRUE(one.has_serial());
  EXPECT_EQ(one.serial(), 1001);
  EXPECT_FALSE(one.has_min_firmware());
  EXPECT_EQ(one.present(), 1u);
  const auto back = config_file_of(one);
  EXPECT_EQ(back.settings.raw, with.baseline->settings.raw);
}

}  // namespace
}  // namespace pmu::service::baseline_dds_test
