#pragma once
// pmu::v5::Command's bytes on the wire, read without trusting them.
//
// The generated deserialisation (fastddsgen) lets Fast CDR's exceptions escape into Fast
// DDS's threads (a boolean byte of 2 aborts the process) and coerces what it cannot hold (an
// enum value, an over-long string). The service's command reader uses CommandSampleType
// instead: it reads each field as it is on the wire (booleans as bytes, the kind as a
// number, strings whole) into a CommandSample for parse_command, and marks a payload that is
// not a pmu::v5::Command at all (too short, unknown encapsulation) as malformed, to be counted
// and dropped. Nothing here throws.

#include <fastdds/dds/topic/TopicDataType.hpp>

#include <atomic>
#include <cstdint>
#include <optional>
#include <vector>

#include "pmu/command/command.hpp"
#include "pmu/idl/commandPubSubTypes.h"

namespace pmu::service {

// The CDR payload (encapsulation header and body, idl/command.idl's field order) read into a
// sample; nullopt when it is not one. `sender` stays empty.
std::optional<CommandSample> read_command_cdr(const std::uint8_t* data, std::size_t size) noexcept;
// The payload for a sample, booleans written as the bytes they hold (so tests can send what a
// hostile peer would). Little-endian CDR.
std::vector<std::uint8_t> write_command_cdr(const CommandSample& s);

// The DDS type "pmu::v5::Command" for readers (and test writers) that work on CommandSamples.
// Reads into a Received; take_next_sample(&received, &info).
class CommandSampleType final : public pmu::v5::CommandPubSubType {
 public:
  struct Received {
    std::optional<CommandSample> sample;  // nullopt: malformed, count and drop
  };

  // Room for strings past the IDL's bounds, so they reach parse_command and get a reason.
  static constexpr std::uint32_t kMaxPayload = 4096;
  CommandSampleType() { m_typeSize = kMaxPayload; }

  bool serialize(void* data, eprosima::fastrtps::rtps::SerializedPayload_t* payload) override;
  bool deserialize(eprosima::fastrtps::rtps::SerializedPayload_t* payload, void* data) override;
  std::function<uint32_t()> getSerializedSizeProvider(void* data) override;
  bool getKey(void* data, eprosima::fastrtps::rtps::InstanceHandle_t* handle, bool force_md5 = false) override;
  void* createData() override;
  void deleteData(void* data) override;

  // Payloads that were not a pmu::v5::Command, since start.
  std::uint64_t malformed() const noexcept { return malformed_.load(std::memory_order_relaxed); }

 private:
  std::atomic<std::uint64_t> malformed_{0};
};

}  // namespace pmu::service
