#include "pmuctl/record/raw_topic_readers.hpp"

#include <algorithm>
#include <cstdio>

#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>

#include "diagnostic_msgs/msg/DiagnosticArrayPubSubTypes.h"
#include "pmu/idl/alarmsPubSubTypes.h"
#include "pmu/idl/canopenPubSubTypes.h"
#include "pmu/idl/commandPubSubTypes.h"
#include "pmu/idl/energyPubSubTypes.h"
#include "pmu/idl/rolePubSubTypes.h"
#include "pmu/idl/statePubSubTypes.h"
#include "pmu/idl/telemetryPubSubTypes.h"
#include "sensor_msgs/msg/BatteryStatePubSubTypes.h"

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
  if (type_name == "pmu::v5::RoleHeartbeat") return TypeSupport(new RawSampleType<pmu::v5::RoleHeartbeatPubSubType>());
  if (type_name == "pmu::v5::RoleMove") return TypeSupport(new RawSampleType<pmu::v5::RoleMovePubSubType>());
  if (type_name == "pmu::v5::RoleMoveReply") return TypeSupport(new RawSampleType<pmu::v5::RoleMoveReplyPubSubType>());
  if (type_name == kRos2BatteryType) return TypeSupport(new RawSampleType<sensor_msgs::msg::BatteryStatePubSubType>());
  if (type_name == kRos2DiagnosticsType)
    return TypeSupport(new RawSampleType<diagnostic_msgs::msg::DiagnosticArrayPubSubType>());
  return TypeSupport(new RawSampleType<pmu::v5::CommandReplyPubSubType>());
}

void RawTopicReaders::open(pmu::dds::DdsContext& dds, const std::vector<const RecordedTopic*>& topics) {
  for (std::size_t i = 0; i < topics.size(); ++i) open_one(dds, *topics[i], i);
}

void RawTopicReaders::open_one(pmu::dds::DdsContext& dds, const RecordedTopic& topic, std::size_t index) {
  auto listener = std::make_unique<TopicListener>(sink_, index);
  auto& t = dds.topic(topic.topic, raw_type_support(topic.type_name));
  if (topic.ros2) {
    DataReaderQos q = DATAREADER_QOS_DEFAULT;
    q.reliability().kind = RELIABLE_RELIABILITY_QOS;
    q.durability().kind = TRANSIENT_LOCAL_DURABILITY_QOS;
    q.history().kind = KEEP_LAST_HISTORY_QOS;
    q.history().depth = 16;
    dds.default_partition_reader(t, q, listener.get());
  } else {
    dds.reader(t, topic.qos_profile, listener.get());
  }
  listeners_.push_back(std::move(listener));
}

bool forwarded_topics(const GlobalOptions& o, const std::vector<std::string>& names, const char* verb,
                      std::vector<const RecordedTopic*>& topics) {
  if (!o.bus.empty() || o.address) {
    // Selecting would mean reading the bytes pmuctl forwards unread; a vehicle is a partition.
    std::fprintf(stderr,
                 "pmuctl %s: forwards every device of the vehicle(s) it reads; --bus and --address do not "
                 "apply (--vehicle does)\n",
                 verb);
    return false;
  }
  std::string unknown;
  topics = select_topics(names, unknown);
  if (topics.empty()) std::fprintf(stderr, "pmuctl %s: %s\n", verb, unknown.c_str());
  return !topics.empty();
}

bool forwarded_topics(const GlobalOptions& o, const std::vector<std::string>& names, const char* verb,
                      std::vector<const RecordedTopic*>& topics, Ros2Selection& ros2) {
  std::vector<std::string> contract;
  for (const auto& n : names) {
    if (auto r = ros2_topic_named(n)) {
      if (std::none_of(ros2.named.begin(), ros2.named.end(),
                       [&](const auto& x) { return x.dds_topic == r->dds_topic; }))
        ros2.named.push_back(*r);
    } else {
      contract.push_back(n);
    }
  }
  ros2.discover = names.empty();
  // Only ROS 2 topics named: no contract topic, but --bus and --address refused alike.
  if (contract.empty() && !names.empty() && o.bus.empty() && !o.address) {
    topics.clear();
    return true;
  }
  return forwarded_topics(o, contract, verb, topics);
}

void Ros2Readers::update(pmu::dds::DdsContext& dds, RawTopicReaders& readers,
                         const std::function<std::size_t(const RecordedTopic&)>& add) {
  for (const auto& n : selection_.named) open(dds, readers, add, n);
  if (!selection_.discover) return;
  for (const char* type : {kRos2DiagnosticsType, kRos2BatteryType})
    for (const auto& topic : dds.remote_writers().topics_of_type(type)) {
      const auto name = ros2_topic_named(topic);
      if (!name || std::string_view(name->type_name) != type) continue;  // not a topic of the service's
      if (vehicle_ && !ros2_topic_of_vehicle(topic, *vehicle_)) continue;
      open(dds, readers, add, *name);
    }
}

void Ros2Readers::open(pmu::dds::DdsContext& dds, RawTopicReaders& readers,
                       const std::function<std::size_t(const RecordedTopic&)>& add, const Ros2TopicName& name) {
  if (!opened_.insert(name.dds_topic).second) return;
  const RecordedTopic* t = topics_.get(name);
  try {
    readers.open_one(dds, *t, add(*t));
  } catch (const pmu::dds::DdsError& e) {
    std::fprintf(stderr, "pmuctl %s: %s: %s\n", verb_, t->channel_name(), e.what());
  }
}

}  // namespace pmu::tools
