#pragma once
// RemoteWriters: the partitions and type name every remote DataWriter announced in
// discovery, by the writer's GUID, and the remote participants by name. DdsContext installs it when it creates the participant, so no writer is
// missed: Fast DDS does not replay discovery to a listener set later, and a writer found in
// the moment between the participant's creation and such a listener would stay unknown.
// Fast DDS reports a writer (PDP::addWriterProxyData) before it pairs it with local readers,
// so a sample from a matched writer always finds its writer here.

#include <fastdds/dds/domain/DomainParticipantListener.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <map>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

namespace pmu::dds {

class RemoteWriters final : public eprosima::fastdds::dds::DomainParticipantListener {
 public:
  void on_publisher_discovery(eprosima::fastdds::dds::DomainParticipant*,
                              eprosima::fastrtps::rtps::WriterDiscoveryInfo&& info) override;

  // The partitions of the writer that wrote the sample `info` describes (its publication
  // handle, which Fast DDS sets from the writer on the wire, unlike the sample identity a
  // writer may choose); nullopt when discovery never reported that writer.
  std::optional<std::vector<std::string>> partitions_of(const eprosima::fastdds::dds::SampleInfo& info) const;

  struct Seen {
    std::vector<std::string> partitions;
    std::string type_name;  // as the writer announced it: its contract's name for the type
  };
  // Every remote writer of `topic` discovery reported, matched or not: a client reading one
  // vehicle still learns which vehicles' services are there, and one of another contract
  // (which it can never match) learns that they are there.
  std::vector<Seen> writers_of(const std::string& topic) const;

  // The topics of every remote writer of type `type_name` discovery reported, each once, in
  // name order: a reader of ROS 2 topics (pmuctl record, serve) finds a service's battery
  // topics, which are named for its devices.
  std::vector<std::string> topics_of_type(const std::string& type_name) const;

  void on_participant_discovery(eprosima::fastdds::dds::DomainParticipant*,
                                eprosima::fastrtps::rtps::ParticipantDiscoveryInfo&& info) override;

  // Remote participants named `name` (alive) none of whose writers of `topic` discovery has
  // reported yet: a participant's announcement is small and comes first, its endpoints'
  // follow, seconds later over a slow link.
  std::size_t participants_without_writer(const std::string& name, const std::string& topic) const;

 private:
  struct Writer {
    std::vector<std::string> partitions;
    std::string topic;
    std::string type_name;
    std::string participant;  // its GUID prefix as text
  };
  // Called from Fast DDS's discovery thread; read from any thread.
  mutable std::mutex mutex_;
  std::map<std::string, Writer> writers_;            // GUID text -> what it announced
  std::map<std::string, std::string> participants_;  // GUID prefix text -> participant name
};

}  // namespace pmu::dds
