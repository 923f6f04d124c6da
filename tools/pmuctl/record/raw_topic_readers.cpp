#include "pmuctl/record/raw_topic_readers.hpp"

#include <cstdio>

#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>

#include "pmu/idl/alarmsPubSubTypes.h"
#include "pmu/idl/canopenPubSubTypes.h"
#include "pmu/idl/commandPubSubTypes.h"
#include "pmu/idl/energyPubSubTypes.h"
#include "pmu/idl/statePubSubTypes.h"
#include "pmu/idl/telemetryPubSubTypes.h"

namespace pmu::tools {
namespace {

using namespace eprosima::fastdds::dds;

class TopicListener final : public DataReaderListener {
 public:
  TopicListener(const RawSampleSink& sink, std::size_t topic) : sink_(sink), topic_(topic) {}
  void on_data_available(DataReader* reader) override {
    RawSample sample;
    SampleInfo info;
    while (reader->take_next_sample(&sample, &info) == ReturnCode_t::RETCODE_OK) {
      if (!info.valid_data) continue;
      const auto& t = info.source_timestamp;
      RawSampleInfo raw;
      raw.topic = topic_;
      raw.time_ns = static_cast<std::uint64_t>(t.seconds()) * std::uint64_t{1000000000} + t.nanosec();
      for (std::size_t i = 0; i < raw.instance.size(); ++i) raw.instance[i] = info.instance_handle.value[i];
      sink_(raw, sample);
    }
  }

 private:
  const RawSampleSink& sink_;
  std::size_t topic_;
};

}  // namespace

TypeSupport raw_type_support(const std::string& type_name) {
  if (type_name == "pmu::v5::Voltages") return TypeSupport(new RawSampleType<pmu::v5::VoltagesPubSubType>());
  if (type_name == "pmu::v5::Currents") return TypeSupport(new RawSampleType<pmu::v5::CurrentsPubSubType>());
  if (type_name == "pmu::v5::BatteryEnergy") return TypeSupport(new RawSampleType<pmu::v5::BatteryEnergyPubSubType>());
  if (type_name == "pmu::v5::Temperatures") return TypeSupport(new RawSampleType<pmu::v5::TemperaturesPubSubType>());
  if (type_name == "pmu::v5::Status") return TypeSupport(new RawSampleType<pmu::v5::StatusPubSubType>());
  if (type_name == "pmu::v5::Config") return TypeSupport(new RawSampleType<pmu::v5::ConfigPubSubType>());
  if (type_name == "pmu::v5::DeviceInfo") return TypeSupport(new RawSampleType<pmu::v5::DeviceInfoPubSubType>());
  if (type_name == "pmu::v5::Health") return TypeSupport(new RawSampleType<pmu::v5::HealthPubSubType>());
  if (type_name == "pmu::v5::Battery") return TypeSupport(new RawSampleType<pmu::v5::BatteryPubSubType>());
  if (type_name == "pmu::v5::BatteryCells") return TypeSupport(new RawSampleType<pmu::v5::BatteryCellsPubSubType>());
  if (type_name == "pmu::v5::Mppt") return TypeSupport(new RawSampleType<pmu::v5::MpptPubSubType>());
  if (type_name == "pmu::v5::Alarm") return TypeSupport(new RawSampleType<pmu::v5::AlarmPubSubType>());
  if (type_name == "pmu::v5::Readiness") return TypeSupport(new RawSampleType<pmu::v5::ReadinessPubSubType>());
  if (type_name == "pmu::v5::Energy") return TypeSupport(new RawSampleType<pmu::v5::EnergyPubSubType>());
  if (type_name == "pmu::v5::BmsEnergy") return TypeSupport(new RawSampleType<pmu::v5::BmsEnergyPubSubType>());
  if (type_name == "pmu::v5::Baseline") return TypeSupport(new RawSampleType<pmu::v5::BaselinePubSubType>());
  if (type_name == "pmu::v5::Command") return TypeSupport(new RawSampleType<pmu::v5::CommandPubSubType>());
  if (type_name == "pmu::v5::AlarmAck") return TypeSupport(new RawSampleType<pmu::v5::AlarmAckPubSubType>());
  if (type_name == "pmu::v5::AlarmAckReply") return TypeSupport(new RawSampleType<pmu::v5::AlarmAckReplyPubSubType>());
  return TypeSupport(new RawSampleType<pmu::v5::CommandReplyPubSubType>());
}

void RawTopicReaders::open(pmu::dds::DdsContext& dds, const std::vector<const RecordedTopic*>& topics) {
  for (std::size_t i = 0; i < topics.size(); ++i) {
    listeners_.push_back(std::make_unique<TopicListener>(sink_, i));
    dds.reader(dds.topic(topics[i]->topic, raw_type_support(topics[i]->type_name)), topics[i]->qos_profile,
               listeners_.back().get());
  }
}

bool forwarded_topics(const GlobalOptions& o, const std::vector<std::string>& names, const char* verb,
                      std::vector<const RecordedTopic*>& topics) {
  if (!o.bus.empty() || o.address) {
    // Selecting would mean reading the bytes pmuctl forwards unread; a vehicle is a partition.
    std::fprintf(stderr, "pmuctl %s: forwards every device of the vehicle(s) it reads; --bus and --address do not "
                         "apply (--vehicle does)\n", verb);
    return false;
  }
  std::string unknown;
  topics = select_topics(names, unknown);
  if (topics.empty()) std::fprintf(stderr, "pmuctl %s: %s\n", verb, unknown.c_str());
  return !topics.empty();
}

}  // namespace pmu::tools
