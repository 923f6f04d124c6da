#pragma once
// What the liveliness test (liveliness_test.cpp) and its writer program (liveliness_writer.cpp)
// share: the topic, its type (an unkeyed 32-bit counter), the leases and the participant QoS.
//
// Every participant is UDPv4 only: the writers run as processes of their own and talk to the
// reader as two hosts would, over UDP (shared memory and Fast DDS's in-process delivery are
// paths two mission computers never take), and a writer killed with SIGKILL leaves no
// shared-memory port behind for later tests.
#include <fastdds/dds/domain/qos/DomainParticipantQos.hpp>
#include <fastdds/dds/topic/TopicDataType.hpp>
#include <fastdds/rtps/transport/UDPv4TransportDescriptor.h>

#include <cstdint>
#include <cstring>
#include <functional>
#include <memory>
#include <optional>
#include <string>

namespace pmu::test::liveliness_probe {

inline constexpr const char* kTopic = "liveliness_probe";
inline constexpr const char* kTypeName = "liveliness_probe::Counter";

// The writers' and the reader's liveliness lease, the period of Fast DDS's announcements for
// AUTOMATIC and MANUAL_BY_PARTICIPANT writers, and how often a writer writes (each write
// asserts its liveliness, whatever the kind).
inline constexpr int kLeaseMs = 1000;
inline constexpr int kAnnouncementMs = 100;
inline constexpr int kWritePeriodMs = 100;
// The liveliness lease is ten announcements and ten writes, so that a loaded machine does not
// make the live writer miss it (Fast DDS's own liveliness tests use 1 to 1.5 s).
//
// The participant lease: a killed writer's participant is dropped, and its writer unmatched,
// once this passes without a word from it; ten liveliness leases, so that a reader which
// tracks liveliness says the writer is not alive long before.
inline constexpr int kParticipantLeaseMs = 10000;
inline constexpr int kParticipantAnnouncementMs = 1000;

// The liveliness kind by its name on the writer program's command line.
inline std::optional<eprosima::fastdds::dds::LivelinessQosPolicyKind> kind_named(const std::string& name) {
  using namespace eprosima::fastdds::dds;
  if (name == "AUTOMATIC") return AUTOMATIC_LIVELINESS_QOS;
  if (name == "MANUAL_BY_PARTICIPANT") return MANUAL_BY_PARTICIPANT_LIVELINESS_QOS;
  if (name == "MANUAL_BY_TOPIC") return MANUAL_BY_TOPIC_LIVELINESS_QOS;
  return std::nullopt;
}

inline eprosima::fastrtps::Duration_t milliseconds(int ms) {
  return eprosima::fastrtps::Duration_t(ms / 1000, static_cast<std::uint32_t>(ms % 1000) * 1000000u);
}

// Fast DDS's defaults but: UDPv4 only, the participant lease above, the Writer Liveliness
// Protocol on (Fast DDS's default; a reader tracks no liveliness without it).
inline eprosima::fastdds::dds::DomainParticipantQos participant_qos(const std::string& name) {
  eprosima::fastdds::dds::DomainParticipantQos qos;
  qos.name(name);
  qos.transport().use_builtin_transports = false;
  qos.transport().user_transports.push_back(std::make_shared<eprosima::fastdds::rtps::UDPv4TransportDescriptor>());
  auto& builtin = qos.wire_protocol().builtin;
  builtin.use_WriterLivelinessProtocol = true;
  builtin.discovery_config.leaseDuration = milliseconds(kParticipantLeaseMs);
  builtin.discovery_config.leaseDuration_announcementperiod = milliseconds(kParticipantAnnouncementMs);
  return qos;
}

// A sample: one counter, CDR little-endian behind its encapsulation header.
class CounterType final : public eprosima::fastdds::dds::TopicDataType {
 public:
  CounterType() {
    setName(kTypeName);
    m_typeSize = 8;  // encapsulation header + uint32
    m_isGetKeyDefined = false;
  }
  bool serialize(void* data, eprosima::fastrtps::rtps::SerializedPayload_t* payload) override {
    const std::uint8_t header[4] = {0x00, 0x01, 0x00, 0x00};  // CDR_LE
    std::memcpy(payload->data, header, 4);
    std::memcpy(payload->data + 4, data, 4);
    payload->length = 8;
    return true;
  }
  bool deserialize(eprosima::fastrtps::rtps::SerializedPayload_t* payload, void* data) override {
    if (payload->length < 8) return false;
    std::memcpy(data, payload->data + 4, 4);
    return true;
  }
  std::function<std::uint32_t()> getSerializedSizeProvider(void*) override {
    return [] { return std::uint32_t{8}; };
  }
  void* createData() override { return new std::uint32_t(0); }
  void deleteData(void* data) override { delete static_cast<std::uint32_t*>(data); }
  bool getKey(void*, eprosima::fastrtps::rtps::InstanceHandle_t*, bool) override { return false; }
};

}  // namespace pmu::test::liveliness_probe
