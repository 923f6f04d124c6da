#pragma once
// ZeroPadded<PubSub>: the generated PubSubType whose serialize() writes every byte of the
// sample, alignment padding included, as zeros where the CDR stream has no data.
//
// Fast-CDR aligns by moving past padding without writing it, and Fast DDS serializes into
// payloads it takes from a pool and reuses: a sample would otherwise carry in its padding
// bytes of an earlier, longer sample of the same writer (a string of pmu/readiness's
// reasons). Clearing the buffer makes a sample's bytes a function of its values alone: what
// a recorder keeps and a reader compares, and nothing of an earlier message leaks into a
// later one. The cost is one memset of the type's bound per write.
// Same name, size bound and key as PubSub, so it registers and matches as PubSub does.

#include <fastdds/dds/topic/TypeSupport.hpp>

#include <cstring>

namespace pmu::dds {

template <class PubSub>
class ZeroPadded final : public PubSub {
 public:
  bool serialize(void* data, eprosima::fastrtps::rtps::SerializedPayload_t* payload) override {
    std::memset(payload->data, 0, payload->max_size);
    return PubSub::serialize(data, payload);
  }
};

template <class PubSub>
eprosima::fastdds::dds::TypeSupport zero_padded() {
  return eprosima::fastdds::dds::TypeSupport(new ZeroPadded<PubSub>());
}

}  // namespace pmu::dds
