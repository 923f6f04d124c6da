#include "pmu/endpoints/command_cdr.hpp"

#include <fastcdr/Cdr.h>
#include <fastcdr/FastBuffer.h>

#include <algorithm>
#include <cstring>

namespace pmu::service {
namespace {

using eprosima::fastcdr::Cdr;
using eprosima::fastcdr::FastBuffer;
using eprosima::fastrtps::rtps::SerializedPayload_t;

// Field order and types of idl/command.idl; a boolean is one byte on the wire.
template <class Stream, class Sample>
void fields(Stream& cdr, Sample& s) {
  cdr& s.request_id& s.vehicle& s.bus& s.address& s.kind& s.parameter& s.value& s.outputs& s.enable& s.groups& s
      .expires_at& s.confirm;
}

struct In {
  Cdr& cdr;
  template <class T>
  In& operator&(T& v) {
    cdr >> v;
    return *this;
  }
};
struct Out {
  Cdr& cdr;
  template <class T>
  Out& operator&(const T& v) {
    cdr << v;
    return *this;
  }
};

}  // namespace

std::optional<CommandSample> read_command_cdr(const std::uint8_t* data, std::size_t size) noexcept {
  if (!data || size < 4) return std::nullopt;
  // Fast CDR reports a short buffer or a bad encapsulation by throwing; the boundary turns
  // that into "not a pmu::v5::Command", whatever the exception.
  try {
    std::vector<char> copy(reinterpret_cast<const char*>(data), reinterpret_cast<const char*>(data) + size);
    FastBuffer buffer(copy.data(), copy.size());
    Cdr cdr(buffer, Cdr::DEFAULT_ENDIAN, Cdr::DDS_CDR);
    cdr.read_encapsulation();
    CommandSample s;
    In in{cdr};
    fields(in, s);
    return s;
  } catch (...) {
    return std::nullopt;
  }
}

std::vector<std::uint8_t> write_command_cdr(const CommandSample& s) {
  std::vector<char> buf(64 + s.request_id.size() + s.vehicle.size() + s.bus.size() + s.parameter.size() + 64);
  FastBuffer buffer(buf.data(), buf.size());
  Cdr cdr(buffer, Cdr::LITTLE_ENDIANNESS, Cdr::DDS_CDR);
  cdr.serialize_encapsulation();
  Out out{cdr};
  fields(out, s);
  const auto n = cdr.getSerializedDataLength();
  return std::vector<std::uint8_t>(buf.begin(), buf.begin() + static_cast<std::ptrdiff_t>(n));
}

bool CommandSampleType::serialize(void* data, SerializedPayload_t* payload) {
  const auto* r = static_cast<const Received*>(data);
  if (!r->sample) return false;
  const auto bytes = write_command_cdr(*r->sample);
  if (bytes.size() > payload->max_size) return false;
  std::memcpy(payload->data, bytes.data(), bytes.size());
  payload->length = static_cast<std::uint32_t>(bytes.size());
  payload->encapsulation = CDR_LE;
  return true;
}

bool CommandSampleType::deserialize(SerializedPayload_t* payload, void* data) {
  auto* r = static_cast<Received*>(data);
  r->sample = read_command_cdr(payload->data, payload->length);
  if (!r->sample) malformed_.fetch_add(1, std::memory_order_relaxed);
  // Fast DDS 2.9 ignores this result on take (the sample comes back as valid data), hence
  // Received::sample: the reader drops a malformed one itself.
  return r->sample.has_value();
}

std::function<uint32_t()> CommandSampleType::getSerializedSizeProvider(void* data) {
  return [data]() -> uint32_t {
    const auto* r = static_cast<const Received*>(data);
    return r->sample ? static_cast<uint32_t>(write_command_cdr(*r->sample).size()) : 0u;
  };
}

bool CommandSampleType::getKey(void*, eprosima::fastrtps::rtps::InstanceHandle_t*, bool) { return false; }

void* CommandSampleType::createData() { return new Received(); }

void CommandSampleType::deleteData(void* data) { delete static_cast<Received*>(data); }

}  // namespace pmu::service
