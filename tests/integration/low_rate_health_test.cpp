// pmu/low_rate/health (interface.md 1.5): written when a device's state or bus state changes,
// and what `pmuctl watch --low-rate` reads a device's state from, so that pmu/health's sample a
// second does not cross a slow link for it.
#include <gtest/gtest.h>

#include <chrono>
#include <fastdds/dds/core/status/PublicationMatchedStatus.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <future>
#include <string>
#include <thread>

#include "pmu/dds/dds_context.hpp"
#include "pmu/endpoints/dds_publisher.hpp"
#include "pmu/idl/statePubSubTypes.h"
#include "pmu/idl/telemetryPubSubTypes.h"
#include "pmu/idl/topics.hpp"
#include "support/domain.hpp"
#include "support/process.hpp"
#include "support/wait.hpp"

// A namespace of its own: the unity builds put this file in one translation unit with the
// other integration tests, whose helpers have the same names.
namespace low_rate_health_test {
namespace {

using namespace eprosima::fastdds::dds;
using namespace std::chrono_literals;
using pmu::service::DdsPublisher;
using pmu::service::DeviceKey;
using pmu::service::HealthReport;
using pmu::service::HealthState;
using pmu::transport::BusState;

// Waits for a sample of `state` on the reader; returns its writer sequence number, or -1.
std::int64_t sequence_of_next(DataReader& r, pmu::v5::HealthState state) {
  std::int64_t sn = -1;
  pmu::v5::Health h;
  SampleInfo info;
  pmu::test::wait_until(
      [&] {
        while (r.take_next_sample(&h, &info) == ReturnCode_t::RETCODE_OK)
          if (info.valid_data && h.state() == state) {
            sn = static_cast<std::int64_t>(info.sample_identity.sequence_number().to64long());
            return true;
          }
        return false;
      },
      10s, 5ms);
  return sn;
}

TEST(DdsLowRateHealth, WrittenWhenTheStateOrBusStateChangesNotForTheFrameAgeOrCounters) {
  const int domain = pmu::test::exclusive_dds_domain();
  pmu::dds::DdsContext service_side(domain, "", "pmu-service-low-rate-health");
  DdsPublisher publisher(service_side, 3s, "uav1", 1000ms);
  pmu::dds::DdsContext client(domain, "", "low-rate-health-reader");
  DataReader& r = client.reader(client.topic(pmu::topics::kLowRateHealth, TypeSupport(new pmu::v5::HealthPubSubType())),
                                pmu::qos_profiles::kState);

  struct Step {
    HealthState state;
    BusState bus;
    double age;
    std::uint64_t frames;
    bool written;  // to pmu/low_rate/health
  };
  // The service's once-a-second reports of one PMU: the age and counters grow every time.
  const Step steps[] = {
      {HealthState::Online, BusState::Up, 0.1, 1, true},  // the first report
      {HealthState::Online, BusState::Up, 1.1, 3, false},
      {HealthState::Online, BusState::Up, 2.1, 5, false},
      {HealthState::Stale, BusState::Up, 3.0, 5, true},
      {HealthState::Offline, BusState::Up, 6.0, 5, true},
      {HealthState::Offline, BusState::Up, 7.0, 5, false},
      {HealthState::Offline, BusState::BusOff, 8.0, 5, true},  // the bus state alone
      {HealthState::Online, BusState::Up, 0.2, 6, true},
  };
  const DeviceKey key{"sim0", 1, pmu::service::DeviceKind::Pmu};
  std::int64_t written = 0;
  for (const auto& s : steps) {
    HealthReport h;
    h.state = s.state;
    h.bus_state = s.bus;
    h.last_frame_age = s.age;
    h.frames_received = s.frames;
    publisher.on_health(key, h);
    if (!s.written) continue;
    ++written;
    // The writer's sequence numbers count every sample written: one more than the changes
    // before it would be a repeat that crossed the link.
    const auto state = static_cast<pmu::v5::HealthState>(static_cast<int>(s.state));
    EXPECT_EQ(sequence_of_next(r, state), written) << "step " << written << ": " << pmu::service::to_string(s.state);
  }
}

// What a low-rate watch shows as a device's state: the service's pmu/low_rate/health, where
// pmu/health (here saying otherwise) is not read at all.
TEST(DdsLowRateHealth, PmuctlWatchLowRateShowsTheStateOfTheLowRateHealth) {
  const int domain = pmu::test::exclusive_dds_domain();
  pmu::dds::DdsContext service_side(domain, "", "pmu-service-low-rate-watch");
  auto state_writer = [&](const char* topic) -> DataWriter& {
    return service_side.writer(service_side.topic(topic, TypeSupport(new pmu::v5::HealthPubSubType())),
                               pmu::qos_profiles::kState);
  };
  DataWriter& full = state_writer(pmu::topics::kHealth);
  DataWriter& low = state_writer(pmu::topics::kLowRateHealth);
  DataWriter& volts = service_side.writer(
      service_side.topic(pmu::topics::kLowRateVoltages, TypeSupport(new pmu::v5::VoltagesPubSubType())),
      pmu::qos_profiles::kTelemetry);
  pmu::v5::Health h;
  h.bus("sim0");
  h.address(1);
  h.state(pmu::v5::ONLINE);
  ASSERT_TRUE(full.write(&h));
  h.state(pmu::v5::OFFLINE);
  ASSERT_TRUE(low.write(&h));

  auto watch = std::async(std::launch::async, [domain] {
    return pmu::test::run_capture(std::string(PMUCTL_PATH) + " --domain " + std::to_string(domain) +
                                  " --timeout 20 watch --low-rate --count 1");
  });
  // Telemetry once the watch holds the state it reads (acknowledged): the line's state is then
  // that topic's, whichever it is.
  auto holds = [](DataWriter& w) {
    PublicationMatchedStatus st;
    w.get_publication_matched_status(st);
    return st.current_count > 0 &&
           w.wait_for_acknowledgments(eprosima::fastrtps::Duration_t(0, 100000000)) == ReturnCode_t::RETCODE_OK;
  };
  pmu::v5::Voltages v;
  v.bus("sim0");
  v.address(1);
  v.avionics(12.0f);
  while (watch.wait_for(100ms) != std::future_status::ready)
    if (holds(low) || holds(full)) volts.write(&v);
  const auto r = watch.get();
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("sim0/1 low_rate/voltages OFFLINE"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("ONLINE"), std::string::npos) << r.out;
}

}  // namespace
}  // namespace low_rate_health_test
