// The bytes the service's writers put on the wire are a function of the sample's values: the
// CDR alignment padding is zeros, also when the writer's buffer held a longer sample before
// (Fast DDS reuses payloads). pmu/readiness over real Fast DDS: long reasons, then short ones
// whose strings end where the long ones' characters were; each sample received as bytes
// (RawSampleType) equals the same values serialized into a zeroed buffer.
#include <gtest/gtest.h>

#include <chrono>
#include <cstring>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <string>
#include <vector>

#include "../../tools/pmuctl/record/raw_sample_type.hpp"
#include "pmu/dds/dds_context.hpp"
#include "pmu/endpoints/dds_publisher.hpp"
#include "pmu/idl/alarmsPubSubTypes.h"
#include "pmu/idl/topics.hpp"
#include "support/domain.hpp"
#include "support/wait.hpp"

namespace pmu::service::sample_bytes_test {
namespace {

using namespace eprosima::fastdds::dds;
using namespace std::chrono_literals;
using pmu::tools::RawSample;
using pmu::tools::RawSampleType;

ReadinessReport readiness(const std::string& code, const std::string& bus, const std::string& message,
                          std::size_t reasons) {
  ReadinessReport r;
  r.ready = false;
  for (std::size_t i = 0; i < reasons; ++i) {
    ReadinessReason x;
    x.code = code;
    x.bus = bus;
    x.device = static_cast<std::uint16_t>(i + 1);
    x.message = message;
    x.description = message;
    r.reasons.push_back(x);
  }
  return r;
}

// The bytes of `raw`'s values serialized into a buffer of zeros: what the sample must be.
std::vector<std::uint8_t> canonical(const RawSample& raw) {
  pmu::v5::ReadinessPubSubType type;
  eprosima::fastrtps::rtps::SerializedPayload_t in(static_cast<std::uint32_t>(raw.bytes.size()));
  std::memcpy(in.data, raw.bytes.data(), raw.bytes.size());
  in.length = static_cast<std::uint32_t>(raw.bytes.size());
  pmu::v5::Readiness sample;
  if (!type.deserialize(&in, &sample)) return {};
  eprosima::fastrtps::rtps::SerializedPayload_t out(type.m_typeSize);
  std::memset(out.data, 0, out.max_size);
  if (!type.serialize(&sample, &out)) return {};
  return {out.data, out.data + out.length};
}

TEST(SampleBytes, ReadinessPaddingIsZerosAfterALongerSample) {
  dds::DdsContext service_side(pmu::test::exclusive_dds_domain(), "", "pmu-service-test");
  DdsPublisher publisher(service_side, 3s, "uav1");
  dds::DdsContext client(pmu::test::exclusive_dds_domain(), "", "reader-test");
  DataReader& reader =
      client.reader(client.topic(topics::kReadiness, TypeSupport(new RawSampleType<pmu::v5::ReadinessPubSubType>())),
                    qos_profiles::kState);

  const auto long_one =
      readiness("battery_a_critical_voltage", "can_long_name", "battery A voltage critical: 18.2 V", 3);
  const auto short_one = readiness("ab", "c", "m", 3);
  // Long, long, short, short: whichever buffer the pool hands out, a short sample is
  // serialized into one that held a long one.
  const ReadinessReport* order[] = {&long_one, &long_one, &short_one, &short_one, &long_one, &short_one};
  std::size_t short_seen = 0;
  for (const auto* r : order) {
    publisher.on_readiness(*r);
    RawSample raw;
    ASSERT_TRUE(pmu::test::wait_until(
        [&] {
          SampleInfo info;
          while (reader.take_next_sample(&raw, &info) == ReturnCode_t::RETCODE_OK)
            if (info.valid_data) return true;
          return false;
        },
        20s, 10ms));
    const auto expected = canonical(raw);
    ASSERT_FALSE(expected.empty()) << "the sample does not deserialize";
    EXPECT_EQ(raw.bytes, expected) << "padding bytes that are not zero (" << r->reasons[0].code << ")";
    if (r == &short_one) ++short_seen;
  }
  EXPECT_EQ(short_seen, 3u);
}

}  // namespace
}  // namespace pmu::service::sample_bytes_test
