// A BatteryState writer with the QoS the service's ROS 2 writers have (ros2_writer_qos:
// RELIABLE, TRANSIENT_LOCAL, KEEP_LAST 1) matches a reader with ROS 2's default QoS (rclcpp's
// rmw_qos_profile_default: RELIABLE, VOLATILE, KEEP_LAST 10) on a ROS 2 topic name, and the
// reader gets the sample; a TRANSIENT_LOCAL reader that joins later (`ros2 topic echo` with
// that durability) gets the last sample at once.
#include <gtest/gtest.h>

#include <chrono>
#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/topic/Topic.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>

#include "pmu/endpoints/ros2_publisher.hpp"
#include "support/ros2_reader_qos.hpp"
#include "sensor_msgs/msg/BatteryStatePubSubTypes.h"
#include "support/domain.hpp"
#include "support/wait.hpp"

namespace {

using namespace eprosima::fastdds::dds;
using namespace std::chrono_literals;

constexpr const char* kTopic = "rt/test/battery_state";

sensor_msgs::msg::BatteryState sample(float voltage) {
  sensor_msgs::msg::BatteryState battery;
  battery.header().stamp().sec(1700000000);
  battery.header().frame_id("can0/battery2");
  battery.voltage(voltage);
  battery.percentage(0.77f);
  battery.present(true);
  battery.cell_voltage({3.3f, 3.31f});
  battery.location("can0/2");
  return battery;
}

class Participant {
 public:
  Participant() {
    participant_ = DomainParticipantFactory::get_instance()->create_participant(
        static_cast<DomainId_t>(pmu::test::exclusive_dds_domain()), PARTICIPANT_QOS_DEFAULT);
    if (!participant_) return;
    TypeSupport type(new sensor_msgs::msg::BatteryStatePubSubType());
    type.register_type(participant_);
    topic_ = participant_->create_topic(kTopic, type.get_type_name(), TOPIC_QOS_DEFAULT);
    publisher_ = participant_->create_publisher(PUBLISHER_QOS_DEFAULT);
    subscriber_ = participant_->create_subscriber(SUBSCRIBER_QOS_DEFAULT);
  }
  ~Participant() {
    if (!participant_) return;
    // Readers first: a reliable writer deleted while a reader is matched can hang on Fast DDS
    // 2.9 (dds/src/dds_context.cpp says why).
    subscriber_->delete_contained_entities();
    participant_->delete_contained_entities();
    DomainParticipantFactory::get_instance()->delete_participant(participant_);
  }
  Participant(const Participant&) = delete;
  Participant& operator=(const Participant&) = delete;

  bool ready() const { return participant_ && topic_ && publisher_ && subscriber_; }
  DataWriter* writer(const DataWriterQos& qos) { return publisher_->create_datawriter(topic_, qos); }
  DataReader* reader(const DataReaderQos& qos) { return subscriber_->create_datareader(topic_, qos); }

 private:
  DomainParticipant* participant_ = nullptr;
  Topic* topic_ = nullptr;
  Publisher* publisher_ = nullptr;
  Subscriber* subscriber_ = nullptr;
};

bool take_one(DataReader& reader, sensor_msgs::msg::BatteryState& out) {
  SampleInfo info;
  return pmu::test::wait_until(
      [&] { return reader.take_next_sample(&out, &info) == ReturnCode_t::RETCODE_OK && info.valid_data; }, 10s);
}

TEST(Ros2Qos, StateWriterMatchesRos2DefaultReader) {
  Participant dds;
  ASSERT_TRUE(dds.ready());
  DataWriter* writer = dds.writer(pmu::service::ros2_writer_qos());
  DataReader* reader = dds.reader(pmu::test::ros2_reader_qos(RELIABLE_RELIABILITY_QOS, VOLATILE_DURABILITY_QOS));
  ASSERT_NE(writer, nullptr);
  ASSERT_NE(reader, nullptr);

  PublicationMatchedStatus matched;
  ASSERT_TRUE(pmu::test::wait_until(
      [&] {
        return writer->get_publication_matched_status(matched) == ReturnCode_t::RETCODE_OK &&
               matched.current_count == 1;
      },
      10s))
      << "the ROS 2 default reader did not match";
  OfferedIncompatibleQosStatus incompatible;
  ASSERT_EQ(writer->get_offered_incompatible_qos_status(incompatible), ReturnCode_t::RETCODE_OK);
  EXPECT_EQ(incompatible.total_count, 0);

  auto written = sample(48.25f);
  ASSERT_TRUE(writer->write(&written));
  sensor_msgs::msg::BatteryState read;
  ASSERT_TRUE(take_one(*reader, read)) << "no sample";
  EXPECT_EQ(read, written);
}

TEST(Ros2Qos, LateTransientLocalReaderGetsTheLastSample) {
  Participant dds;
  ASSERT_TRUE(dds.ready());
  DataWriter* writer = dds.writer(pmu::service::ros2_writer_qos());
  ASSERT_NE(writer, nullptr);
  auto first = sample(48.0f);
  auto last = sample(47.5f);
  ASSERT_TRUE(writer->write(&first));
  ASSERT_TRUE(writer->write(&last));

  DataReader* reader = dds.reader(pmu::test::ros2_reader_qos(RELIABLE_RELIABILITY_QOS, TRANSIENT_LOCAL_DURABILITY_QOS));
  ASSERT_NE(reader, nullptr);
  sensor_msgs::msg::BatteryState read;
  ASSERT_TRUE(take_one(*reader, read)) << "no sample";
  EXPECT_EQ(read, last);  // KEEP_LAST 1: the writer kept only the last
  SampleInfo info;
  EXPECT_NE(reader->take_next_sample(&read, &info), ReturnCode_t::RETCODE_OK);
}

}  // namespace
