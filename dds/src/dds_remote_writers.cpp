#include "pmu/dds/dds_remote_writers.hpp"

#include <fastdds/rtps/common/InstanceHandle.h>

#include <sstream>

namespace pmu::dds {
namespace {

std::string text_of(const eprosima::fastrtps::rtps::GUID_t& guid) {
  std::ostringstream out;
  out << guid;
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
    writers_[guid] = Writer{info.info.m_qos.m_partition.names(), info.info.topicName().to_string()};
}

std::optional<std::vector<std::string>> RemoteWriters::partitions_of(
    const eprosima::fastdds::dds::SampleInfo& info) const {
  const auto guid = text_of(eprosima::fastrtps::rtps::iHandle2GUID(info.publication_handle));
  std::lock_guard<std::mutex> lock(mutex_);
  const auto it = writers_.find(guid);
  if (it == writers_.end()) return std::nullopt;
  return it->second.partitions;
}

std::vector<std::vector<std::string>> RemoteWriters::partitions_writing(const std::string& topic) const {
  std::vector<std::vector<std::string>> out;
  std::lock_guard<std::mutex> lock(mutex_);
  for (const auto& [guid, w] : writers_)
    if (w.topic == topic) out.push_back(w.partitions);
  return out;
}

}  // namespace pmu::dds
