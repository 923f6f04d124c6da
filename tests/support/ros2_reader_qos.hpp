#pragma once
// A reader's QoS as a ROS 2 subscriber's: KEEP_LAST 10 with the reliability and durability
// of the profile (rmw's default: RELIABLE, VOLATILE; sensor data: BEST_EFFORT; latched:
// TRANSIENT_LOCAL). For the tests that read pmu-dds as a ROS 2 node does.
#include <fastdds/dds/subscriber/qos/DataReaderQos.hpp>

namespace pmu::test {

inline eprosima::fastdds::dds::DataReaderQos ros2_reader_qos(
    eprosima::fastdds::dds::ReliabilityQosPolicyKind reliability,
    eprosima::fastdds::dds::DurabilityQosPolicyKind durability) {
  eprosima::fastdds::dds::DataReaderQos q = eprosima::fastdds::dds::DATAREADER_QOS_DEFAULT;
  q.reliability().kind = reliability;
  q.durability().kind = durability;
  q.history().kind = eprosima::fastdds::dds::KEEP_LAST_HISTORY_QOS;
  q.history().depth = 10;
  return q;
}

}  // namespace pmu::test
