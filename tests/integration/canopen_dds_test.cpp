// Batteries and MPPTs end to end over real Fast DDS (interface.md 1.4): the service's bus
// worker and publisher with a fake clock, frames built from the document's tables injected
// on the in-process bus by a node of the test's own, and readers written against the
// contract's types and QoS profiles (canopen_pmuctl_test.cpp: pmuctl reading the same).
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <fastdds/dds/core/status/SubscriptionMatchedStatus.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <functional>
#include <map>
#include <optional>
#include <set>
#include <thread>

#include "canopen_bus.hpp"
#include "pmu/dds/dds_context.hpp"
#include "pmu/endpoints/dds_publisher.hpp"
#include "pmu/idl/canopenPubSubTypes.h"
#include "pmu/idl/statePubSubTypes.h"
#include "pmu/idl/topics.hpp"
#include "support/domain.hpp"
#include "support/wait.hpp"

namespace pmu::service::test {
namespace {

using namespace eprosima::fastdds::dds;
using namespace std::chrono_literals;

template <class T>
bool wait_for(DataReader& r, T& out, SampleInfo& info, std::chrono::milliseconds timeout,
              const std::function<bool(const T&)>& wanted) {
  return pmu::test::wait_until(
      [&] {
        while (r.take_next_sample(&out, &info) == ReturnCode_t::RETCODE_OK)
          if (info.valid_data && wanted(out)) return true;
        return false;
      },
      timeout, 5ms);
}

TEST(DdsCanOpen, BatteryCellsAndMpptArriveWithTheirValuesAndFrameTimes) {
  dds::DdsContext service_side(pmu::test::exclusive_dds_domain(), "", "pmu-service-canopen");
  DdsPublisher publisher(service_side, 3s, "uav1");  // the vehicle key only; partitions: vehicle_test.cpp
  dds::DdsContext client(pmu::test::exclusive_dds_domain(), "", "reader-canopen");
  auto& battery_reader = client.reader(client.topic(topics::kBattery, TypeSupport(new pmu::v5::BatteryPubSubType())),
                                       qos_profiles::kTelemetry);
  auto& cells_reader =
      client.reader(client.topic(topics::kBatteryCells, TypeSupport(new pmu::v5::BatteryCellsPubSubType())),
                    qos_profiles::kTelemetry);
  auto& mppt_reader =
      client.reader(client.topic(topics::kMppt, TypeSupport(new pmu::v5::MpptPubSubType())), qos_profiles::kTelemetry);

  Harness h(bus_with_battery_and_mppt(), {pmu(1)}, Timeouts{}, &publisher);
  BusThread bus(h, document_frames());

  SampleInfo si;
  pmu::v5::Battery b;
  // Every value the node sends is in one sample once a round of frames has been assembled.
  ASSERT_TRUE(wait_for<pmu::v5::Battery>(battery_reader, b, si, 10s, [](const pmu::v5::Battery& x) {
    return !std::isnan(x.voltage()) && !std::isnan(x.power_level()) && !std::isnan(x.temperature_4()) &&
           (x.received() & (1u << 10)) != 0;
  }));
  EXPECT_EQ(b.vehicle().to_string(), "uav1");
  EXPECT_EQ(b.bus().to_string(), "sim0");
  EXPECT_EQ(b.node(), 2);
  EXPECT_FLOAT_EQ(b.voltage(), 48.123f);
  EXPECT_EQ(b.bms_state(), double{0x12345678u});
  EXPECT_FLOAT_EQ(b.temperature_1(), 20.0f);
  EXPECT_FLOAT_EQ(b.temperature_4(), 23.0f);
  EXPECT_FLOAT_EQ(b.power_level(), 77.0f);
  EXPECT_TRUE(std::isnan(b.current())) << "never sent: NaN, not 0";
  EXPECT_TRUE(std::isnan(b.time_to_go()));
  // voltage (0), bms_state (10), temperature_1..4 (11..14), power_level (15)
  EXPECT_EQ(b.received(), (1u << 0) | (1u << 10) | (0xFu << 11) | (1u << 15));
  // The frame's receive time on the fake bus clock (which starts at 1700000000 s).
  EXPECT_GE(si.source_timestamp.seconds(), 1700000000);
  EXPECT_LT(si.source_timestamp.seconds(), 1700000000 + 3600);

  pmu::v5::BatteryCells cells;
  ASSERT_TRUE(wait_for<pmu::v5::BatteryCells>(cells_reader, cells, si, 5s,
                                              [](const pmu::v5::BatteryCells& x) { return !x.cells().empty(); }));
  ASSERT_EQ(cells.cells().size(), 1u);
  EXPECT_EQ(cells.cells()[0].cell(), 5);
  EXPECT_FLOAT_EQ(cells.cells()[0].cell_voltage(), 3.301f);
  EXPECT_EQ(cells.node(), 2);

  pmu::v5::Mppt m;
  ASSERT_TRUE(wait_for<pmu::v5::Mppt>(mppt_reader, m, si, 5s, [](const pmu::v5::Mppt& x) {
    return !std::isnan(x.voltage_output_raw()) && !std::isnan(x.duty_cycle_panel_2()) && x.safety_enabled() == 1.0f;
  }));
  EXPECT_EQ(m.device(), 4);
  EXPECT_FLOAT_EQ(m.voltage_output_raw(), -100.0f);
  EXPECT_FLOAT_EQ(m.duty_cycle_panel_2(), 45.0f);
  EXPECT_TRUE(std::isnan(m.current_output_raw()));
  EXPECT_TRUE(std::isnan(m.pwm_enabled())) << "never sent: NaN, not off";
  // voltage_output_raw (0), safety_enabled (4), duty_cycle_panel_2 (13).
  EXPECT_EQ(m.received(), (1u << 0) | (1u << 4) | (1u << 13));
}

TEST(DdsCanOpen, HealthHasAnInstancePerDeviceKind) {
  dds::DdsContext service_side(pmu::test::exclusive_dds_domain(), "", "pmu-service-canopen-health");
  DdsPublisher publisher(service_side, 3s);
  dds::DdsContext client(pmu::test::exclusive_dds_domain(), "", "reader-canopen-health");
  auto& health =
      client.reader(client.topic(topics::kHealth, TypeSupport(new pmu::v5::HealthPubSubType())), qos_profiles::kState);
  BusConfig config = bus_with_battery_and_mppt();
  config.mppts.push_back(MpptConfig{2, 1000ms, {}});  // configured, never heard
  Harness h(config, {pmu(1)}, Timeouts{}, &publisher);
  BusThread bus(h, document_frames());

  std::map<std::pair<int, int>, pmu::v5::HealthState> seen;  // (kind, address) -> latest state
  pmu::v5::Health s;
  SampleInfo si;
  const bool all = pmu::test::wait_until(
      [&] {
        while (health.take_next_sample(&s, &si) == ReturnCode_t::RETCODE_OK)
          if (si.valid_data) seen[{static_cast<int>(s.kind()), s.address()}] = s.state();
        return seen.size() == 4 && seen[{pmu::v5::KIND_MPPT, 2}] == pmu::v5::OFFLINE;
      },
      20s, 5ms);
  ASSERT_TRUE(all) << seen.size() << " instances";
  // PMU 1, battery 2 and MPPT 4 share numbers' ranges: the kind keeps them apart.
  EXPECT_EQ((seen[{pmu::v5::KIND_PMU, 1}]), pmu::v5::ONLINE);
  EXPECT_EQ((seen[{pmu::v5::KIND_BATTERY, 2}]), pmu::v5::ONLINE);
  EXPECT_EQ((seen[{pmu::v5::KIND_MPPT, 4}]), pmu::v5::ONLINE);
  EXPECT_EQ((seen[{pmu::v5::KIND_MPPT, 2}]), pmu::v5::OFFLINE) << "configured but silent";
}

}  // namespace
}  // namespace pmu::service::test

namespace pmu::service::test {
namespace {

// A service with no battery or MPPT does not offer their topics (so permissions made before
// they existed still let it start): a reader of pmu/battery finds no writer, while the same
// service's pmu/health writer is found.
TEST(DdsCanOpen, AServiceWithoutBatteriesOrMpptsDoesNotOfferTheirTopics) {
  dds::DdsContext service_side(pmu::test::exclusive_dds_domain(), "", "pmu-service-no-canopen");
  DdsPublisher publisher(service_side, 3s, "", {}, std::nullopt);
  dds::DdsContext client(pmu::test::exclusive_dds_domain(), "", "reader-no-canopen");
  auto& battery = client.reader(client.topic(topics::kBattery, TypeSupport(new pmu::v5::BatteryPubSubType())),
                                qos_profiles::kTelemetry);
  auto& mppt =
      client.reader(client.topic(topics::kMppt, TypeSupport(new pmu::v5::MpptPubSubType())), qos_profiles::kTelemetry);
  auto& health =
      client.reader(client.topic(topics::kHealth, TypeSupport(new pmu::v5::HealthPubSubType())), qos_profiles::kState);
  auto matched = [](DataReader& r) {
    SubscriptionMatchedStatus st;
    r.get_subscription_matched_status(st);
    return st.current_count;
  };
  ASSERT_TRUE(pmu::test::wait_until([&] { return matched(health) > 0; }, 10s, 10ms));
  std::this_thread::sleep_for(500ms);  // discovery of the other writers, had there been any
  EXPECT_EQ(matched(battery), 0);
  EXPECT_EQ(matched(mppt), 0);
}

}  // namespace
}  // namespace pmu::service::test
