#pragma once
// Guarded<T>: a generated PubSubType whose deserialisation cannot throw into Fast DDS.
//
// fastddsgen's deserialize() catches only Fast CDR's NotEnoughMemoryException; a peer that
// sends a boolean byte of 2 makes Fast CDR throw BadParamException through it, into the
// thread that takes the sample (or, for a keyed topic whose writer sends no key hash, into
// Fast DDS's receive thread, which aborts the process). Readers of samples from the network
// use Guarded<pmu::XPubSubType> instead: a payload that does not deserialise is counted,
// the sample is reset to its default, and Fast DDS is told it failed (2.9 then drops it).
//
//   dds.reader(dds.topic(topics::kHealth, TypeSupport(new pmu::idl::Guarded<pmu::HealthPubSubType>())), ...)

#include <fastdds/dds/topic/TopicDataType.hpp>

#include <atomic>
#include <cstdint>

namespace pmu::idl {

template <class PubSubType>
class Guarded final : public PubSubType {
 public:
  bool deserialize(eprosima::fastrtps::rtps::SerializedPayload_t* payload, void* data) override {
    try {
      if (PubSubType::deserialize(payload, data)) return true;
    } catch (...) {  // whatever Fast CDR throws: the payload is not this type
    }
    *static_cast<typename PubSubType::type*>(data) = typename PubSubType::type();
    malformed_.fetch_add(1, std::memory_order_relaxed);
    return false;
  }

  // Payloads that did not deserialise, since this type was created.
  std::uint64_t malformed() const noexcept { return malformed_.load(std::memory_order_relaxed); }

 private:
  std::atomic<std::uint64_t> malformed_{0};
};

}  // namespace pmu::idl
