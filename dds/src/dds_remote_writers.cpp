#include "pmu/dds/dds_remote_writers.hpp"

#include <fastdds/rtps/common/InstanceHandle.h>

#include <set>
#include <sstream>

namespace pmu::dds {
namespace {

template <class Id>
std::string text_of(const Id& id) {
  std::ostringstream out;
  out << id;
  return out.str();
}

}  // namespace

void RemoteWriters::on_publisher_discovery(eprosima::fastdds::dds::DomainParticipant*,
                                           eprosima::fastrtps::rtps::WriterDiscoveryInfo&& info) {
  using Status = eprosima::fastrtps::rtps::WriterDiscoveryInfo::DISCOVERY_STATUS;
  const auto guid = text_of(info.info.guid());
  std::lock_guard<std::mutex> lock(mutex_);
  if (info.status == Status::REMOVED_WRITER)
    writers_.erase(guid);
  else
    writers_[guid] = Writer{info.info.m_qos.m_partition.names(), info.info.topicName().to_string(),
                            info.info.typeName().to_string(), text_of(info.info.guid().guidPrefix)};
}

void RemoteWriters::on_participant_discovery(eprosima::fastdds::dds::DomainParticipant*,
                                             eprosima::fastrtps::rtps::ParticipantDiscoveryInfo&& info) {
  using Status = eprosima::fastrtps::rtps::ParticipantDiscoveryInfo::DISCOVERY_STATUS;
  const auto prefix = text_of(info.info.m_guid.guidPrefix);
  std::lock_guard<std::mutex> lock(mutex_);
  switch (info.status) {
    case Status::DISCOVERED_PARTICIPANT:
    case Status::CHANGED_QOS_PARTICIPANT: participants_[prefix] = info.info.m_participantName.to_string(); break;
    case Status::REMOVED_PARTICIPANT:
    case Status::DROPPED_PARTICIPANT: participants_.erase(prefix); break;
  }
}

std::size_t RemoteWriters::participants_without_writer(const std::string& name, const std::string& topic) const {
  std::lock_guard<std::mutex> lock(mutex_);
  std::size_t n = 0;
  for (const auto& [prefix, participant_name] : participants_) {
    if (participant_name != name) continue;
    bool writes = false;
    for (const auto& [guid, w] : writers_) writes = writes || (w.topic == topic && w.participant == prefix);
    if (!writes) ++n;
  }
  return n;
}

std::optional<std::vector<std::string>> RemoteWriters::partitions_of(
    const eprosima::fastdds::dds::SampleInfo& info) const {
  const auto guid = text_of(eprosima::fastrtps::rtps::iHandle2GUID(info.publication_handle));
  std::lock_guard<std::mutex> lock(mutex_);
  const auto it = writers_.find(guid);
  if (it == writers_.end()) return std::nullopt;
  return it->second.partitions;
}

std::vector<RemoteWriters::Seen> RemoteWriters::writers_of(const std::string& topic) const {
  std::vector<Seen> out;
  std::lock_guard<std::mutex> lock(mutex_);
  for (const auto& [guid, w] : writers_)
    if (w.topic == topic) out.push_back(Seen{w.partitions, w.type_name});
  return out;
}

std::vector<std::string> RemoteWriters::topics_of_type(const std::string& type_name) const {
  std::set<std::string> topics;
  std::lock_guard<std::mutex> lock(mutex_);
  for (const auto& [guid, w] : writers_)
    if (w.type_name == type_name) topics.insert(w.topic);
  return {topics.begin(), topics.end()};
}

}  // namespace pmu::dds
