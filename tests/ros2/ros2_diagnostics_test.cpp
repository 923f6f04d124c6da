// /diagnostics from Ros2Publisher (docs/interface.md 11.3) for a latched subscriber (ROS 2's
// TRANSIENT_LOCAL profile) that joins late: the one message the writer keeps holds every
// device's current status, as ROS 2's diagnostic_updater publishes its statuses in one array;
// a device that is gone leaves it. The array is written at once on a change a reader sees,
// else at most once a second of the publisher's clock.
#include <gtest/gtest.h>

#include <chrono>
#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/topic/Topic.hpp>
#include <map>
#include <string>

#include "diagnostic_msgs/msg/DiagnosticArrayPubSubTypes.h"
#include "pmu/dds/dds_context.hpp"
#include "pmu/endpoints/ros2_publisher.hpp"
#include "support/ros2_reader_qos.hpp"
#include "support/domain.hpp"
#include "support/wait.hpp"

namespace {

using namespace eprosima::fastdds::dds;
using namespace std::chrono_literals;
using pmu::service::DeviceKey;
using pmu::service::DeviceKind;
using pmu::service::HealthReport;
using pmu::service::HealthState;
namespace Ds = diagnostic_msgs::msg::DiagnosticStatus_Constants;

// A ROS 2 node's latched subscriber of /diagnostics, joining when made.
class LateSubscriber {
 public:
  explicit LateSubscriber(int domain) {
    participant_ = DomainParticipantFactory::get_instance()->create_participant(static_cast<DomainId_t>(domain),
                                                                                PARTICIPANT_QOS_DEFAULT);
    if (!participant_) return;
    TypeSupport type(new diagnostic_msgs::msg::DiagnosticArrayPubSubType());
    type.register_type(participant_);
    Topic* topic = participant_->create_topic("rt/diagnostics", type.get_type_name(), TOPIC_QOS_DEFAULT);
    Subscriber* subscriber = participant_->create_subscriber(SUBSCRIBER_QOS_DEFAULT);
    if (topic && subscriber)
      reader_ = subscriber->create_datareader(
          topic, pmu::test::ros2_reader_qos(RELIABLE_RELIABILITY_QOS, TRANSIENT_LOCAL_DURABILITY_QOS));
  }
  ~LateSubscriber() {
    if (!participant_) return;
    participant_->delete_contained_entities();
    DomainParticipantFactory::get_instance()->delete_participant(participant_);
  }
  LateSubscriber(const LateSubscriber&) = delete;
  LateSubscriber& operator=(const LateSubscriber&) = delete;

  // The first message it gets: the one the writer kept. Level of each status by name.
  std::map<std::string, std::uint8_t> first() {
    std::map<std::string, std::uint8_t> out;
    const auto array = kept();
    for (const auto& s : array.status()) out[s.name()] = s.level();
    return out;
  }
  // The message the writer kept; empty if none came.
  diagnostic_msgs::msg::DiagnosticArray kept() {
    diagnostic_msgs::msg::DiagnosticArray array;
    if (!reader_) return array;
    SampleInfo info;
    if (!pmu::test::wait_until(
            [&] { return reader_->take_next_sample(&array, &info) == ReturnCode_t::RETCODE_OK && info.valid_data; },
            10s))
      array.status().clear();
    return array;
  }

 private:
  DomainParticipant* participant_ = nullptr;
  DataReader* reader_ = nullptr;
};

std::string value_of(const diagnostic_msgs::msg::DiagnosticArray& array, const std::string& key) {
  for (const auto& s : array.status())
    for (const auto& kv : s.values())
      if (kv.key() == key) return kv.value();
  return "<absent>";
}

HealthReport health(HealthState state) {
  HealthReport h;
  h.state = state;
  h.last_frame_age = state == HealthState::Online ? 0.1 : 30;
  return h;
}

TEST(Ros2Diagnostics, ALateLatchedSubscriberGetsEveryDevicesStatusAtOnce) {
  const int domain = pmu::test::exclusive_dds_domain();
  pmu::dds::DdsContext service_side(domain, "", "pmu-service-ros2");
  pmu::dds::Ros2Settings settings;
  settings.enabled = true;
  const pmu::transport::ManualClock clock;
  pmu::service::Ros2Publisher publisher(service_side, settings, "uav1", {}, clock);
  const DeviceKey pmu{"can0", 1, DeviceKind::Pmu};
  const DeviceKey bms{"can0", 2, DeviceKind::Battery};
  const DeviceKey mppt{"can1", 3, DeviceKind::Mppt};
  publisher.on_health(pmu, health(HealthState::Online));
  publisher.on_health(bms, health(HealthState::Offline));
  publisher.on_health(mppt, health(HealthState::Online));
  publisher.on_health(pmu, health(HealthState::Stale));  // the newest report of each device counts

  const std::map<std::string, std::uint8_t> all{
      {"uav1/can0/pmu_1", Ds::STALE}, {"uav1/can0/bms_2", Ds::ERROR}, {"uav1/can1/mppt_3", Ds::OK}};
  EXPECT_EQ(LateSubscriber(domain).first(), all);

  publisher.on_gone(pmu);
  const std::map<std::string, std::uint8_t> without_pmu{{"uav1/can0/bms_2", Ds::ERROR}, {"uav1/can1/mppt_3", Ds::OK}};
  EXPECT_EQ(LateSubscriber(domain).first(), without_pmu);
}

// A report that changes nothing a reader sees (only its counters) within a second of the
// array before it is not written: the kept array is still that one. A second on, it is.
TEST(Ros2Diagnostics, AnUnchangedReportIsWrittenAtMostOnceASecond) {
  const int domain = pmu::test::exclusive_dds_domain();
  pmu::dds::DdsContext service_side(domain, "", "pmu-service-ros2");
  pmu::dds::Ros2Settings settings;
  settings.enabled = true;
  pmu::transport::ManualClock clock;
  pmu::service::Ros2Publisher publisher(service_side, settings, "uav1", {}, clock);
  const DeviceKey pmu{"can0", 1, DeviceKind::Pmu};
  HealthReport report = health(HealthState::Online);
  report.frames_received = 10;
  publisher.on_health(pmu, report);
  clock.advance(500ms);
  report.frames_received = 20;
  publisher.on_health(pmu, report);
  EXPECT_EQ(value_of(LateSubscriber(domain).kept(), "frames_received"), "10");

  clock.advance(500ms);
  report.frames_received = 30;
  publisher.on_health(pmu, report);
  EXPECT_EQ(value_of(LateSubscriber(domain).kept(), "frames_received"), "30");

  clock.advance(100ms);
  publisher.on_health(pmu, health(HealthState::Stale));
  EXPECT_EQ(LateSubscriber(domain).first(), (std::map<std::string, std::uint8_t>{{"uav1/can0/pmu_1", Ds::STALE}}))
      << "a change of level is written at once";
}

}  // namespace
