#pragma once
// RawSampleType<PubSub>: a reader-side DDS type that keeps each sample's serialized payload
// (encapsulation header and CDR body) as it came, under the contract's type name, so
// `pmuctl record` forwards the bytes into the MCAP file without re-serialising them.
//
// It derives from the generated PubSubType for the name, the key flag and the size bound
// (so it matches the service's writers) and reads the key, when Fast DDS asks for it, with
// the generated code on a copy. Nothing escapes into Fast DDS's threads.

#include <fastdds/dds/topic/TopicDataType.hpp>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <functional>
#include <vector>

namespace pmu::tools {

struct RawSample {
  std::vector<std::uint8_t> bytes;
};

template <class PubSub>
class RawSampleType final : public PubSub {
 public:
  RawSampleType() { this->m_typeSize = std::max<std::uint32_t>(this->m_typeSize, 4096); }

  bool serialize(void*, eprosima::fastrtps::rtps::SerializedPayload_t*) override { return false; }  // readers only

  bool deserialize(eprosima::fastrtps::rtps::SerializedPayload_t* payload, void* data) override {
    static_cast<RawSample*>(data)->bytes.assign(payload->data, payload->data + payload->length);
    return true;
  }

  std::function<uint32_t()> getSerializedSizeProvider(void* data) override {
    return [data]() { return static_cast<uint32_t>(static_cast<RawSample*>(data)->bytes.size()); };
  }

  bool getKey(void* data, eprosima::fastrtps::rtps::InstanceHandle_t* handle, bool force_md5 = false) override {
    const auto& bytes = static_cast<RawSample*>(data)->bytes;
    try {
      eprosima::fastrtps::rtps::SerializedPayload_t copy(static_cast<std::uint32_t>(bytes.size()));
      std::memcpy(copy.data, bytes.data(), bytes.size());
      copy.length = static_cast<std::uint32_t>(bytes.size());
      typename PubSub::type sample;
      if (!PubSub::deserialize(&copy, &sample)) return false;
      return PubSub::getKey(&sample, handle, force_md5);
    } catch (...) {  // not this type after all: no key
      return false;
    }
  }

  void* createData() override { return new RawSample(); }
  void deleteData(void* data) override { delete static_cast<RawSample*>(data); }
};

}  // namespace pmu::tools
