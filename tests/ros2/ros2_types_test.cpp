// ROS 2's types as ros2/ generates them. A ROS 2 node (rmw_fastrtps) matches a topic on its
// DDS type name, so each must be rmw_fastrtps's <pkg>::msg::dds_::<Name>_; a ROS 2 topic has no
// instances, so none has a key; and a sample's bytes are the plain CDR of the .msg's fields in
// their order, which is what a ROS 2 reader decodes.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <fastdds/dds/topic/TypeSupport.hpp>
#include <fastdds/rtps/common/InstanceHandle.h>
#include <fastdds/rtps/common/SerializedPayload.h>
#include <string>
#include <vector>

#include "builtin_interfaces/msg/TimePubSubTypes.h"
#include "diagnostic_msgs/msg/DiagnosticArrayPubSubTypes.h"
#include "diagnostic_msgs/msg/DiagnosticStatusPubSubTypes.h"
#include "diagnostic_msgs/msg/KeyValuePubSubTypes.h"
#include "sensor_msgs/msg/BatteryStatePubSubTypes.h"
#include "std_msgs/msg/HeaderPubSubTypes.h"

namespace {

using eprosima::fastdds::dds::TypeSupport;
using eprosima::fastrtps::rtps::InstanceHandle_t;
using eprosima::fastrtps::rtps::SerializedPayload_t;

struct Generated {
  TypeSupport type;
  std::string ros2_name;
};

std::vector<Generated> generated_types() {
  return {
      {TypeSupport(new builtin_interfaces::msg::TimePubSubType()), "builtin_interfaces::msg::dds_::Time_"},
      {TypeSupport(new std_msgs::msg::HeaderPubSubType()), "std_msgs::msg::dds_::Header_"},
      {TypeSupport(new diagnostic_msgs::msg::KeyValuePubSubType()), "diagnostic_msgs::msg::dds_::KeyValue_"},
      {TypeSupport(new diagnostic_msgs::msg::DiagnosticStatusPubSubType()),
       "diagnostic_msgs::msg::dds_::DiagnosticStatus_"},
      {TypeSupport(new diagnostic_msgs::msg::DiagnosticArrayPubSubType()),
       "diagnostic_msgs::msg::dds_::DiagnosticArray_"},
      {TypeSupport(new sensor_msgs::msg::BatteryStatePubSubType()), "sensor_msgs::msg::dds_::BatteryState_"},
  };
}

TEST(Ros2Types, TypeNamesAreRmwFastrtpsNames) {
  for (const auto& generated : generated_types()) {
    EXPECT_EQ(generated.type.get_type_name(), generated.ros2_name);
  }
}

TEST(Ros2Types, NoTypeHasAKey) {
  for (const auto& generated : generated_types()) {
    EXPECT_FALSE(generated.type->m_isGetKeyDefined) << generated.ros2_name;
  }
  sensor_msgs::msg::BatteryState battery;
  battery.location("can0/battery2");
  InstanceHandle_t handle;
  EXPECT_FALSE(TypeSupport(new sensor_msgs::msg::BatteryStatePubSubType())->getKey(&battery, &handle));
  EXPECT_FALSE(handle.isDefined());
}

template <class T>
T read_le(const SerializedPayload_t& payload, std::size_t offset) {
  T value{};
  EXPECT_LE(offset + sizeof(T), payload.length) << "offset " << offset;
  if (offset + sizeof(T) <= payload.length) std::memcpy(&value, payload.data + offset, sizeof(T));
  return value;
}

std::string read_cdr_string(const SerializedPayload_t& payload, std::size_t offset) {
  const auto length = read_le<std::uint32_t>(payload, offset);  // with the terminating NUL
  if (length == 0 || offset + 4 + length > payload.length) return "<bad string>";
  return std::string(reinterpret_cast<const char*>(payload.data) + offset + 4, length - 1);
}

SerializedPayload_t serialize(TypeSupport& type, void* sample) {
  SerializedPayload_t payload(type->getSerializedSizeProvider(sample)());
  EXPECT_TRUE(type->serialize(sample, &payload));
  return payload;
}

// Offsets count from the start of the payload: a 4-byte encapsulation header, then the CDR
// stream, whose alignment counts from its own start (payload offset 4).
constexpr std::size_t kData = 4;

TEST(Ros2Types, BatteryStateIsTheCdrOfItsMsgFieldsInOrder) {
  sensor_msgs::msg::BatteryState battery;
  battery.header().stamp().sec(1700000000);
  battery.header().stamp().nanosec(500000000);
  battery.header().frame_id("bat");
  battery.voltage(48.5f);
  battery.temperature(21.0f);
  battery.current(-3.25f);
  battery.charge(10.0f);
  battery.capacity(20.0f);
  battery.design_capacity(22.0f);
  battery.percentage(0.5f);
  battery.power_supply_status(sensor_msgs::msg::BatteryState_Constants::POWER_SUPPLY_STATUS_DISCHARGING);
  battery.power_supply_health(sensor_msgs::msg::BatteryState_Constants::POWER_SUPPLY_HEALTH_GOOD);
  battery.power_supply_technology(sensor_msgs::msg::BatteryState_Constants::POWER_SUPPLY_TECHNOLOGY_LIFE);
  battery.present(true);
  battery.cell_voltage({3.25f, 3.5f});
  battery.cell_temperature({});
  battery.location("can0/2");
  battery.serial_number("");

  TypeSupport type(new sensor_msgs::msg::BatteryStatePubSubType());
  const SerializedPayload_t payload = serialize(type, &battery);

  EXPECT_EQ(payload.data[0], 0x00);  // CDR, little endian: what rmw_fastrtps writes on x86 and arm64
  EXPECT_EQ(payload.data[1], 0x01);
  // header: stamp (int32 sec, uint32 nanosec), frame_id: 4 + "bat\0"
  EXPECT_EQ(read_le<std::int32_t>(payload, kData + 0), 1700000000);
  EXPECT_EQ(read_le<std::uint32_t>(payload, kData + 4), 500000000u);
  EXPECT_EQ(read_cdr_string(payload, kData + 8), "bat");
  // seven float32 from stream offset 16 (8 + 4 + 4, already aligned)
  EXPECT_EQ(read_le<float>(payload, kData + 16), 48.5f);
  EXPECT_EQ(read_le<float>(payload, kData + 20), 21.0f);
  EXPECT_EQ(read_le<float>(payload, kData + 24), -3.25f);
  EXPECT_EQ(read_le<float>(payload, kData + 28), 10.0f);
  EXPECT_EQ(read_le<float>(payload, kData + 32), 20.0f);
  EXPECT_EQ(read_le<float>(payload, kData + 36), 22.0f);
  EXPECT_EQ(read_le<float>(payload, kData + 40), 0.5f);
  // three uint8 and a bool, one byte each
  EXPECT_EQ(read_le<std::uint8_t>(payload, kData + 44), 2);
  EXPECT_EQ(read_le<std::uint8_t>(payload, kData + 45), 1);
  EXPECT_EQ(read_le<std::uint8_t>(payload, kData + 46), 4);
  EXPECT_EQ(read_le<std::uint8_t>(payload, kData + 47), 1);
  // cell_voltage: uint32 count, then the floats; cell_temperature: empty
  EXPECT_EQ(read_le<std::uint32_t>(payload, kData + 48), 2u);
  EXPECT_EQ(read_le<float>(payload, kData + 52), 3.25f);
  EXPECT_EQ(read_le<float>(payload, kData + 56), 3.5f);
  EXPECT_EQ(read_le<std::uint32_t>(payload, kData + 60), 0u);
  // location, then serial_number ("" is a length of 1: the NUL), aligned to 4
  EXPECT_EQ(read_cdr_string(payload, kData + 64), "can0/2");
  EXPECT_EQ(read_cdr_string(payload, kData + 76), "");
  EXPECT_EQ(payload.length, kData + 81);

  sensor_msgs::msg::BatteryState back;
  SerializedPayload_t copy(payload.length);
  copy.copy(&payload, false);
  ASSERT_TRUE(type->deserialize(&copy, &back));
  EXPECT_EQ(back, battery);
}

TEST(Ros2Types, DiagnosticArrayIsTheCdrOfItsMsgFieldsInOrder) {
  diagnostic_msgs::msg::DiagnosticArray array;
  array.header().stamp().sec(7);
  array.header().frame_id("");
  diagnostic_msgs::msg::DiagnosticStatus status;
  status.level(diagnostic_msgs::msg::DiagnosticStatus_Constants::WARN);
  status.name("pmu: can0/1");
  status.message("hot");
  status.hardware_id("SN1");
  diagnostic_msgs::msg::KeyValue value;
  value.key("temperature");
  value.value("75");
  status.values({value});
  array.status({status});

  TypeSupport type(new diagnostic_msgs::msg::DiagnosticArrayPubSubType());
  const SerializedPayload_t payload = serialize(type, &array);

  EXPECT_EQ(read_le<std::int32_t>(payload, kData + 0), 7);
  EXPECT_EQ(read_cdr_string(payload, kData + 8), "");
  // status: count at 16 (13 aligned to 4), then the one status: level (byte), name at 24
  EXPECT_EQ(read_le<std::uint32_t>(payload, kData + 16), 1u);
  EXPECT_EQ(read_le<std::uint8_t>(payload, kData + 20), 1);
  EXPECT_EQ(read_cdr_string(payload, kData + 24), "pmu: can0/1");
  EXPECT_EQ(read_cdr_string(payload, kData + 40), "hot");
  EXPECT_EQ(read_cdr_string(payload, kData + 48), "SN1");
  EXPECT_EQ(read_le<std::uint32_t>(payload, kData + 56), 1u);
  EXPECT_EQ(read_cdr_string(payload, kData + 60), "temperature");
  EXPECT_EQ(read_cdr_string(payload, kData + 76), "75");
  EXPECT_EQ(payload.length, kData + 83);
}

}  // namespace
