#pragma once
// Readers of contract topics that hand on each sample's serialized bytes unread, with its DDS
// source timestamp: what `pmuctl record` writes into MCAP files and `pmuctl serve` forwards
// to Foxglove clients (docs/interface.md sections 9.1 and 9.2). The same topics, types and QoS
// profiles for both, so a live view and a recording show the same channels.
//
// The sink runs on Fast DDS's listener threads: it must not block (record takes a mutex held
// only for a memory copy; serve queues the bytes for its server thread).

#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>

#include "pmu/dds/dds_context.hpp"
#include "pmuctl/record/mcap_topics.hpp"
#include "pmuctl/record/raw_sample_type.hpp"
#include "pmuctl/record/ros2_topics.hpp"
#include "pmuctl/verbs/state_verbs.hpp"

namespace pmu::tools {

// What a reader knows of a sample besides its bytes.
struct RawSampleInfo {
  std::size_t topic = 0;                    // index into the list given to RawTopicReaders::open
  std::uint64_t time_ns = 0;                // the DDS source timestamp, ns since the Unix epoch
  std::array<std::uint8_t, 16> instance{};  // the DDS instance (the sample's keys: one device)
};
// The sink may take (move from) `sample.bytes`.
using RawSampleSink = std::function<void(const RawSampleInfo& info, RawSample& sample)>;

// A RawSampleType for the contract's DDS type name ("pmu::v5::Voltages") or ROS 2's
// (ros2_topics.hpp); the name must be one of recorded_topics()'s or those two.
eprosima::fastdds::dds::TypeSupport raw_type_support(const std::string& type_name);

// The listeners of readers feeding `sink`. Declare it before the DdsContext whose readers use
// them: Fast DDS may call a listener until the participant is gone.
class RawTopicReaders {
 public:
  explicit RawTopicReaders(RawSampleSink sink) : sink_(std::move(sink)) {}
  // One reader per topic on `dds`, each with the topic's QoS profile; `topic` in the sink is
  // the index into `topics`. Throws DdsError (start-up) like DdsContext::reader.
  void open(pmu::dds::DdsContext& dds, const std::vector<const RecordedTopic*>& topics);
  // One more reader, whose samples the sink gets as topic `index`. A ROS 2 topic is read in
  // the default partition as a latched ROS 2 subscriber reads it (RELIABLE, TRANSIENT_LOCAL:
  // the service's last message at once). Throws DdsError like DdsContext::reader.
  void open_one(pmu::dds::DdsContext& dds, const RecordedTopic& topic, std::size_t index);
  RawTopicReaders(const RawTopicReaders&) = delete;  // the listeners refer to sink_
  RawTopicReaders& operator=(const RawTopicReaders&) = delete;

 private:
  RawSampleSink sink_;
  std::vector<std::unique_ptr<eprosima::fastdds::dds::DataReaderListener>> listeners_;
};

// The topics a verb that forwards every device's bytes unread (record, serve) reads:
// select_topics() of the --topic names. False, after printing what is wrong
// ("pmuctl serve: --topic x is not a topic of the contract (...)"), for an unknown topic or
// --bus/--address (they would mean reading the bytes); the verb then exits 2.
bool forwarded_topics(const GlobalOptions& o, const std::vector<std::string>& names, const char* verb,
                      std::vector<const RecordedTopic*>& topics);

// The ROS 2 topics (ros2_topics.hpp) a verb that forwards bytes unread carries besides.
struct Ros2Selection {
  std::vector<Ros2TopicName> named;  // --topic /diagnostics, --topic /uav1/can0/pmu_1/battery_a, ...
  bool discover = false;             // no --topic: every ROS 2 topic of the service discovery finds
};
// forwarded_topics() where `names` may also name ROS 2 topics: those go to `ros2`, the others
// to `topics`. Without names: the default topics, and every ROS 2 topic found.
bool forwarded_topics(const GlobalOptions& o, const std::vector<std::string>& names, const char* verb,
                      std::vector<const RecordedTopic*>& topics, Ros2Selection& ros2);

// Opens a reader of each ROS 2 topic of the selection not yet open, as a verb's main thread
// calls it once a second: the named ones, and those discovery has found since (battery topics
// of --vehicle's vehicle only, when it names one). `add` gives the sink's index of a topic
// (the verb adds its channel there, before any message can come). A reader refused (DDS-Security)
// is said on stderr once and not asked for again.
class Ros2Readers {
 public:
  Ros2Readers(Ros2Selection selection, std::optional<std::string> vehicle, const char* verb)
      : selection_(std::move(selection)), vehicle_(std::move(vehicle)), verb_(verb) {}
  void update(pmu::dds::DdsContext& dds, RawTopicReaders& readers,
              const std::function<std::size_t(const RecordedTopic&)>& add);

 private:
  void open(pmu::dds::DdsContext& dds, RawTopicReaders& readers,
            const std::function<std::size_t(const RecordedTopic&)>& add, const Ros2TopicName& name);
  Ros2Selection selection_;
  std::optional<std::string> vehicle_;
  const char* verb_;
  Ros2Topics topics_;
  std::set<std::string> opened_;  // DDS topic names, also those refused
};

}  // namespace pmu::tools
