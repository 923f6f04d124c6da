// What eProsima's dynamic-type tools see of pmu-service (docs/interface.md 9.4, 9.3), with
// pmu-service as a separate process on its built-in simulated bus:
//
// - TypeObject: a participant with no generated code at all (this program links Fast DDS and
//   the test support only, neither pmu::idl nor pmu::dds) gets the type of pmu/voltages from
//   the type object the service's writer announces, builds a DataReader from it with Fast
//   DDS's DynamicTypes API, and decodes samples by the contract's field names. This is what
//   Fast DDS Monitor, PlotJuggler's Fast DDS plugin and DDS Record & Replay do. Without the
//   service's register_type_objects() no type is announced and the test fails (checked).
//   With config `dds_type_objects: true` only: without it no writer announces a type.
// - Statistics: with config `dds_statistics` the service's participant writes the listed Fast
//   DDS statistics topics (the writers appear in discovery) and no others; without it, none.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/domain/DomainParticipantListener.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/topic/Topic.hpp>
#include <fastdds/statistics/topic_names.hpp>
#include <fastrtps/types/DynamicData.h>
#include <fastrtps/types/DynamicDataFactory.h>
#include <fastrtps/types/DynamicPubSubType.h>
#include <fastrtps/types/DynamicType.h>
#include <fastrtps/types/DynamicTypeMember.h>
#include <fastrtps/types/MemberDescriptor.h>
#include <fstream>
#include <map>
#include <mutex>
#include <set>
#include <string>
#include <sys/wait.h>
#include <thread>
#include <unistd.h>
#include <vector>

#include "support/domain.hpp"
#include "support/process.hpp"
#include "support/wait.hpp"

namespace {

using namespace eprosima::fastdds::dds;
namespace types = eprosima::fastrtps::types;
namespace stats = eprosima::fastdds::statistics;
using eprosima::fastrtps::rtps::GuidPrefix_t;
using namespace std::chrono_literals;

// What discovery told this participant: the types announced per topic, and the writers.
class Discovery : public DomainParticipantListener {
 public:
  // Called by Fast DDS 2.9.1 (PDP::check_and_notify_type_discovery) for a remote endpoint
  // that announces a complete TypeObject, with the DynamicType built from it, when the type
  // is not registered with this participant.
  void on_type_discovery(DomainParticipant*, const eprosima::fastrtps::rtps::SampleIdentity&,
                         const eprosima::fastrtps::string_255& topic, const types::TypeIdentifier*,
                         const types::TypeObject*, types::DynamicType_ptr type) override {
    std::lock_guard<std::mutex> lock(mutex_);
    if (type) types_[topic.to_string()] = type;
  }

  void on_participant_discovery(DomainParticipant*,
                                eprosima::fastrtps::rtps::ParticipantDiscoveryInfo&& info) override {
    std::lock_guard<std::mutex> lock(mutex_);
    names_[info.info.m_guid.guidPrefix] = info.info.m_participantName.to_string();
  }

  void on_publisher_discovery(DomainParticipant*, eprosima::fastrtps::rtps::WriterDiscoveryInfo&& info) override {
    if (info.status != eprosima::fastrtps::rtps::WriterDiscoveryInfo::DISCOVERED_WRITER) return;
    std::lock_guard<std::mutex> lock(mutex_);
    writers_.emplace_back(info.info.guid().guidPrefix, info.info.topicName().to_string());
  }

  types::DynamicType_ptr type_of(const std::string& topic) {
    std::lock_guard<std::mutex> lock(mutex_);
    const auto it = types_.find(topic);
    return it == types_.end() ? types::DynamicType_ptr() : it->second;
  }

  std::set<std::string> topics_with_types() {
    std::lock_guard<std::mutex> lock(mutex_);
    std::set<std::string> topics;
    for (const auto& [topic, type] : types_) topics.insert(topic);
    return topics;
  }

  // The topics of the writers of the participant named `name`.
  std::set<std::string> writer_topics_of(const std::string& name) {
    std::lock_guard<std::mutex> lock(mutex_);
    std::set<std::string> topics;
    for (const auto& [prefix, topic] : writers_) {
      const auto it = names_.find(prefix);
      if (it != names_.end() && it->second == name) topics.insert(topic);
    }
    return topics;
  }

 private:
  std::mutex mutex_;
  std::map<std::string, types::DynamicType_ptr> types_;
  std::map<GuidPrefix_t, std::string> names_;
  std::vector<std::pair<GuidPrefix_t, std::string>> writers_;
};

// A participant as the tools create one: no types of its own, the type lookup service's
// client on (how they ask for a type they only know the identifier of).
class ToolParticipant {
 public:
  explicit ToolParticipant(int domain) {
    DomainParticipantQos qos;
    qos.name("dynamic-type-tool");
    qos.wire_protocol().builtin.typelookup_config.use_client = true;
    participant_ =
        DomainParticipantFactory::get_instance()->create_participant(static_cast<DomainId_t>(domain), qos, &discovery_);
  }
  ~ToolParticipant() {
    if (!participant_) return;
    participant_->delete_contained_entities();
    DomainParticipantFactory::get_instance()->delete_participant(participant_);
  }
  ToolParticipant(const ToolParticipant&) = delete;
  ToolParticipant& operator=(const ToolParticipant&) = delete;

  DomainParticipant* get() { return participant_; }
  Discovery& discovery() { return discovery_; }

 private:
  Discovery discovery_;  // outlives the participant
  DomainParticipant* participant_ = nullptr;
};

// A temporary config file for pmu-service.
struct ConfigFile {
  explicit ConfigFile(const std::string& text)
      : path("/tmp/pmu-type-object-test-" + std::to_string(::getpid()) + ".yaml") {
    std::ofstream(path) << text;
  }
  ~ConfigFile() { std::remove(path.c_str()); }
  std::string path;
};

// One simulated PMU at address 1 on bus sim0 streaming every packet every 0.5 s, as
// `--bus sim` without a config, and a simulated battery and MPPT (so pmu/battery_cells is
// announced too); `extra` adds top-level keys.
std::string sim_config(const std::string& extra) {
  return extra +
         "buses:\n"
         "  - interface: sim\n"
         "    name: sim0\n"
         "    devices:\n"
         "      - address: 1\n"
         "        period: 0.5\n"
         "    batteries: [{node: 2, period: 0.5}]\n"
         "    mppts: [{device: 0, period: 0.5}]\n";
}

pmu::test::Child start_service(int domain, const ConfigFile& config) {
  pmu::test::ChildOptions o;
  // Fast DDS also reads FASTDDS_STATISTICS by itself: only the config may decide here.
  o.env = {"FASTDDS_STATISTICS="};
  return pmu::test::Child(
      {PMU_SERVICE_PATH, "--config", config.path, "--domain", std::to_string(domain), "--log-level", "warn"}, o);
}

// pmu-service on its simulated power system (sim_config with `extra`) and, on the same
// domain, a participant of a tool that knows none of our types.
struct ServiceAndTool {
  explicit ServiceAndTool(const std::string& extra)
      : domain(pmu::test::exclusive_dds_domain()),
        config(sim_config(extra)),
        service(start_service(domain, config)),
        tool(domain) {}
  int domain;
  ConfigFile config;
  pmu::test::Child service;
  ToolParticipant tool;
};

// Waits until the service's writers of `topics` have all been discovered (they come one by
// one, in no fixed order), and returns the topics of its writers discovered by then.
std::set<std::string> service_writer_topics(ToolParticipant& tool,
                                            const std::vector<std::string>& topics = {"pmu/voltages", "pmu/health",
                                                                                      "pmu/command_reply"}) {
  std::set<std::string> found;
  EXPECT_TRUE(pmu::test::wait_until(
      [&] {
        found = tool.discovery().writer_topics_of("pmu-service");
        return std::all_of(topics.begin(), topics.end(), [&](const auto& t) { return found.count(t) > 0; });
      },
      30s))
      << "of pmu-service's writers only these were discovered: " << ::testing::PrintToString(found);
  return found;
}

// The contract's fields of pmu::v5::Voltages in order (interface.md 1.3): keys first.
const std::vector<std::string> kVoltagesFields = {"vehicle", "bus",   "address",   "avionics",  "output_28v",
                                                  "payload", "servo", "battery_a", "battery_b", "generator"};

TEST(TypeObject, ReaderBuiltFromTheDiscoveredTypeDecodesVoltages) {
  ServiceAndTool run("dds_type_objects: true\n");
  auto& tool = run.tool;
  ASSERT_NE(tool.get(), nullptr);

  types::DynamicType_ptr type;
  ASSERT_TRUE(pmu::test::wait_until([&] { return (type = tool.discovery().type_of("pmu/voltages")) != nullptr; }, 30s))
      << "pmu-service's pmu/voltages writer announced no complete type object";
  ASSERT_TRUE(run.service.running());

  // Type objects only of the self-contained types (dds_type_objects.hpp): a Fast DDS 2.9.1
  // participant that does not know our types, like this one, would drop the enum members of
  // Health, Command and CommandReply and crash on BatteryCells' sequence of BatteryCell.
  const std::set<std::string> self_contained = {"pmu/voltages",
                                                "pmu/currents",
                                                "pmu/battery_energy",
                                                "pmu/temperatures",
                                                "pmu/status",
                                                "pmu/low_rate/voltages",
                                                "pmu/low_rate/currents",
                                                "pmu/low_rate/battery_energy",
                                                "pmu/low_rate/temperatures",
                                                "pmu/low_rate/status",
                                                "pmu/config",
                                                "pmu/info",
                                                "pmu/battery",
                                                "pmu/mppt",
                                                "pmu/baseline",
                                                "pmu/bms_energy"};
  std::set<std::string> with_types;
  EXPECT_TRUE(pmu::test::wait_until(
      [&] { return (with_types = tool.discovery().topics_with_types()) == self_contained; }, 30s));
  // The writers without a type are announced too, and may come after the typed ones.
  (void)service_writer_topics(tool, {"pmu/health", "pmu/battery_cells", "pmu/command_reply"});
  EXPECT_EQ(tool.discovery().topics_with_types(), self_contained);

  // The type as the tools show it: its name, the contract's field names in order, the keys.
  EXPECT_EQ(type->get_name(), "pmu::v5::Voltages");
  std::map<types::MemberId, types::DynamicTypeMember*> members;
  type->get_all_members(members);
  std::vector<std::string> names;
  std::set<std::string> keys;
  for (const auto& [id, member] : members) {
    names.push_back(member->get_name());
    if (member->get_descriptor()->annotation_is_key()) keys.insert(member->get_name());
  }
  EXPECT_EQ(names, kVoltagesFields);
  EXPECT_EQ(keys, (std::set<std::string>{"vehicle", "bus", "address"}));
  EXPECT_TRUE(type->has_children());

  // A reader of that type alone: no generated code anywhere in this program.
  TypeSupport support(new types::DynamicPubSubType(type));
  ASSERT_EQ(support.register_type(tool.get()), ReturnCode_t::RETCODE_OK);
  Topic* topic = tool.get()->create_topic("pmu/voltages", support.get_type_name(), TOPIC_QOS_DEFAULT);
  ASSERT_NE(topic, nullptr);
  Subscriber* subscriber = tool.get()->create_subscriber(SUBSCRIBER_QOS_DEFAULT);
  ASSERT_NE(subscriber, nullptr);
  DataReader* reader = subscriber->create_datareader(topic, DATAREADER_QOS_DEFAULT);  // best effort, volatile
  ASSERT_NE(reader, nullptr);

  types::DynamicData_ptr data(types::DynamicDataFactory::get_instance()->create_data(type));
  ASSERT_TRUE(data);
  bool got = false;
  ASSERT_TRUE(pmu::test::wait_until(
      [&] {
        SampleInfo info;
        while (reader->take_next_sample(data.get(), &info) == ReturnCode_t::RETCODE_OK)
          if (info.valid_data) got = true;
        return got;
      },
      30s))
      << "no pmu/voltages sample reached the dynamic reader";

  auto id = [&](const char* name) { return data->get_member_id_by_name(name); };
  // Keys: the unnamed vehicle, the bus and the simulated PMU's address.
  EXPECT_EQ(data->get_string_value(id("vehicle")), "");
  EXPECT_EQ(data->get_string_value(id("bus")), "sim0");
  EXPECT_EQ(data->get_uint16_value(id("address")), 1);
  // Values: the simulator's (sim/include/pmu/sim/config.hpp: battery A 22.2 V, generator
  // 48 V while it supplies; sim/src/stored_parameters.cpp: avionics set-point 12.0 V).
  EXPECT_NEAR(data->get_float32_value(id("battery_a")), 22.2, 0.5);
  for (const char* field : {"avionics", "output_28v", "payload", "servo", "battery_b"}) {
    const float v = data->get_float32_value(id(field));
    EXPECT_TRUE(std::isfinite(v) && v >= 0.0f && v <= 30.0f) << field << " = " << v;
  }
  const float generator = data->get_float32_value(id("generator"));
  EXPECT_TRUE(generator == 0.0f || std::fabs(generator - 48.0f) < 1.0f) << "generator = " << generator;
  const float avionics = data->get_float32_value(id("avionics"));
  EXPECT_TRUE(avionics == 0.0f || std::fabs(avionics - 12.0f) < 0.5f) << "avionics = " << avionics;
}

std::set<std::string> statistics_topics(const std::set<std::string>& topics) {
  std::set<std::string> s;
  for (const auto& t : topics)
    if (t.rfind("_fastdds_statistics_", 0) == 0) s.insert(t);
  return s;
}

// The default: the service's writers are all discovered, none with a type object.
TEST(TypeObject, NoneAnnouncedWithoutTheConfigKey) {
  ServiceAndTool run("");
  auto& tool = run.tool;
  ASSERT_NE(tool.get(), nullptr);
  (void)service_writer_topics(tool, {"pmu/voltages", "pmu/health", "pmu/battery", "pmu/battery_cells", "pmu/mppt",
                                     "pmu/config", "pmu/info", "pmu/command_reply"});
  ASSERT_TRUE(run.service.running());
  EXPECT_TRUE(tool.discovery().topics_with_types().empty());
  EXPECT_EQ(tool.discovery().type_of("pmu/voltages"), nullptr);
}

TEST(Statistics, ConfiguredTopicsAreWrittenAndNoOthers) {
  ServiceAndTool run(std::string("dds_statistics: [") + stats::HISTORY_LATENCY_TOPIC + ", " +
                     stats::PUBLICATION_THROUGHPUT_TOPIC + "]\n");
  auto& tool = run.tool;
  ASSERT_NE(tool.get(), nullptr);

  const std::set<std::string> wanted = {stats::HISTORY_LATENCY_TOPIC, stats::PUBLICATION_THROUGHPUT_TOPIC};
  std::set<std::string> seen;
  EXPECT_TRUE(pmu::test::wait_until(
      [&] { return (seen = statistics_topics(tool.discovery().writer_topics_of("pmu-service"))) == wanted; }, 30s));
  (void)service_writer_topics(tool);
  std::this_thread::sleep_for(1s);  // anything else would have been announced with the rest
  EXPECT_EQ(statistics_topics(tool.discovery().writer_topics_of("pmu-service")), wanted);
  // Fast DDS deletes its statistics writers with the participant: a clean stop.
  const auto status = run.service.stop(10s);
  ASSERT_TRUE(status.has_value()) << "pmu-service had to be killed";
  EXPECT_TRUE(WIFEXITED(*status) && WEXITSTATUS(*status) == 0) << "wait status " << *status;
}

TEST(Statistics, NoneWithoutTheConfigKey) {
  ServiceAndTool run("");
  auto& tool = run.tool;
  ASSERT_NE(tool.get(), nullptr);

  (void)service_writer_topics(tool);
  std::this_thread::sleep_for(1s);
  EXPECT_EQ(statistics_topics(tool.discovery().writer_topics_of("pmu-service")), std::set<std::string>{});
}

}  // namespace
