// old_consumer_vN: a client built from contract vN's IDL alone (idl/versions/vN), as a ground
// station of that contract was built, so the tests see what such a client gets from today's
// pmu-service. PMU_OLD_CONTRACT (2, 3 or 4) picks the version; the generated types are vN's
// (pmu::Health up to v3, pmu::v4::Health from v4).
//
//   old_consumer_v3 --domain N [--seconds T] [--until decoded|discovered] [--linger S]
//                   [--command GET_SERIAL|GET [--parameter NAME]] [--bus sim0] [--address 1]
//     Reads pmu/health, pmu/voltages, pmu/config and pmu/status (and, once a probe is
//     answered, sends one command, waiting for its replies on pmu/command_reply); one JSON line per decoded sample, with every field, then
//     {"final":true,...}: the remote endpoints each endpoint matched and the type names of
//     those discovery reported per topic (whatever their type, so "matched none" can be told
//     from "not discovered yet"), and the `pmu-dds.contract` property of every participant
//     named pmu-service. Stops at T, or once the --until condition holds plus S seconds
//     (to see a late match or a duplicate reply).
//   old_consumer_v3 --domain N --serve-health [--vehicle NAME] [--seconds T]
//     A stand-in for a vN pmu-service: participant "pmu-service", pmu/health of one ONLINE PMU
//     (bus can0, address 1) in its vehicle's partition, until T or SIGTERM.
//
// QoS: deploy/qos.xml's profiles, from $PMU_QOS_FILE. Exit status 0, or 2 when DDS fails.
#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/domain/DomainParticipantListener.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/topic/Topic.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>
#include <unistd.h>

#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <mutex>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <thread>

#include "command.h"
#include "commandPubSubTypes.h"
#include "state.h"
#include "statePubSubTypes.h"
#include "telemetry.h"
#include "telemetryPubSubTypes.h"

using namespace eprosima::fastdds::dds;
using Json = nlohmann::json;
#if PMU_OLD_CONTRACT >= 4
namespace idl = pmu::v4;
#else
namespace idl = pmu;
#endif
using Clock = std::chrono::steady_clock;

namespace {

volatile std::sig_atomic_t g_stop = 0;

// An enum as its IDL name, or as the raw number when it is none: a misread shows as what it is.
template <std::size_t N>
Json name_of(std::uint32_t v, const char* const (&names)[N]) {
  return v < N ? Json(names[v]) : Json(v);
}
const char* const kHealthStates[] = {"UNKNOWN", "ONLINE", "STALE", "OFFLINE"};
const char* const kBusStates[] = {"UP", "ERROR_WARNING", "ERROR_PASSIVE", "BUS_OFF", "DOWN"};
const char* const kCommandKinds[] = {"GET",
                                     "SET_PARAMETER",
                                     "SET_OUTPUTS",
                                     "ENABLE_OUTPUTS",
                                     "DISABLE_OUTPUTS",
                                     "SET_GENERATION",
                                     "REQUEST_MEASUREMENTS",
                                     "ENGINE_START",
                                     "ENGINE_STOP",
                                     "RESET",
                                     "GET_SERIAL",
                                     "GET_FIRMWARE"};
const char* const kResults[] = {"COMPLETED", "REJECTED", "DENIED", "UNSUPPORTED", "TIMEOUT", "FAILED", "IN_PROGRESS"};
#if PMU_OLD_CONTRACT >= 3
const char* const kDeviceKinds[] = {"KIND_PMU", "KIND_BATTERY", "KIND_MPPT"};
#endif

Json to_json(const idl::Health& h) {
  Json j{{"topic", "pmu/health"},
         {"vehicle", h.vehicle().to_string()},
         {"bus", h.bus().to_string()},
         {"address", h.address()}};
#if PMU_OLD_CONTRACT >= 3
  j["kind"] = name_of(h.kind(), kDeviceKinds);
#endif
  j["state"] = name_of(h.state(), kHealthStates);
  j["bus_state"] = name_of(h.bus_state(), kBusStates);
  j["last_frame_age"] = h.last_frame_age();
  j["frames_received"] = h.frames_received();
  j["frames_sent"] = h.frames_sent();
  j["decode_errors"] = h.decode_errors();
  j["bus_errors"] = h.bus_errors();
  j["rx_dropped"] = h.rx_dropped();
  j["timeouts"] = h.timeouts();
  j["reconnects"] = h.reconnects();
  j["publish_failures"] = h.publish_failures();
  return j;
}

Json to_json(const idl::Voltages& v) {
  return {{"topic", "pmu/voltages"},    {"vehicle", v.vehicle().to_string()},
          {"bus", v.bus().to_string()}, {"address", v.address()},
          {"avionics", v.avionics()},   {"output_28v", v.output_28v()},
          {"payload", v.payload()},     {"servo", v.servo()},
          {"battery_a", v.battery_a()}, {"battery_b", v.battery_b()},
          {"generator", v.generator()}};
}

Json to_json(const idl::Status& s) {
  return {{"topic", "pmu/status"},
          {"vehicle", s.vehicle().to_string()},
          {"bus", s.bus().to_string()},
          {"address", s.address()},
          {"generator_rpm", s.generator_rpm()},
          {"payload_on", s.payload_on()},
          {"generation_enabled", s.generation_enabled()}};
}

Json to_json(const idl::Config& c) {
  return {{"topic", "pmu/config"},
          {"vehicle", c.vehicle().to_string()},
          {"bus", c.bus().to_string()},
          {"address", c.address()},
          {"avionics_voltage", c.avionics_voltage()},
          {"payload_voltage", c.payload_voltage()},
          {"servo_voltage", c.servo_voltage()},
          {"battery_voltage", c.battery_voltage()},
          {"packet_period", c.packet_period()},
          {"packets_streamed", c.packets_streamed()},
          {"temperature_offset", c.temperature_offset()},
          {"upper_temperature_limit", c.upper_temperature_limit()},
          {"power_up_state", c.power_up_state()},
          {"cranking_time", c.cranking_time()},
          {"can_address", c.can_address()},
          {"outputs", c.outputs()},
          {"generation_enabled", c.generation_enabled()}};
}

Json to_json(const idl::CommandReply& r) {
  return {{"topic", "pmu/command_reply"},
          {"request_id", r.request_id().to_string()},
          {"vehicle", r.vehicle().to_string()},
          {"bus", r.bus().to_string()},
          {"address", r.address()},
          {"kind", name_of(r.kind(), kCommandKinds)},
          {"result", name_of(r.result(), kResults)},
          {"reason", r.reason().to_string()},
          {"has_value", r.has_value()},
          {"value", r.value()},
          {"value_text", r.value_text().to_string()}};
}

void print(const Json& j) {
  std::printf("%s\n", j.dump().c_str());
  std::fflush(stdout);
}

// Every remote writer and reader discovery reports, whatever its type: the type names per
// topic (a reader's topic is keyed "reader:TOPIC").
class Discovery : public DomainParticipantListener {
 public:
  void on_publisher_discovery(DomainParticipant*, eprosima::fastrtps::rtps::WriterDiscoveryInfo&& info) override {
    if (info.status == eprosima::fastrtps::rtps::WriterDiscoveryInfo::DISCOVERED_WRITER)
      add(info.info.topicName().to_string(), info.info.typeName().to_string());
  }
  void on_subscriber_discovery(DomainParticipant*, eprosima::fastrtps::rtps::ReaderDiscoveryInfo&& info) override {
    if (info.status == eprosima::fastrtps::rtps::ReaderDiscoveryInfo::DISCOVERED_READER)
      add("reader:" + info.info.topicName().to_string(), info.info.typeName().to_string());
  }
  // The participant property a pmu-service announces its contract in: what a tool of any
  // contract can read before it matches anything (the participant's own announcement).
  void on_participant_discovery(DomainParticipant*,
                                eprosima::fastrtps::rtps::ParticipantDiscoveryInfo&& info) override {
    if (info.status != eprosima::fastrtps::rtps::ParticipantDiscoveryInfo::DISCOVERED_PARTICIPANT ||
        info.info.m_participantName.to_string() != "pmu-service")
      return;
    std::string contract = "(none)";
    for (const auto& property : info.info.m_properties)
      if (property.first() == "pmu-dds.contract") contract = property.second();
    std::lock_guard<std::mutex> lock(mutex_);
    service_contracts_.insert(contract);
  }
  std::map<std::string, std::set<std::string>> types() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return types_;
  }
  std::set<std::string> service_contracts() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return service_contracts_;
  }

 private:
  void add(const std::string& topic, const std::string& type) {
    std::lock_guard<std::mutex> lock(mutex_);
    types_[topic].insert(type);
  }
  mutable std::mutex mutex_;
  std::map<std::string, std::set<std::string>> types_;
  std::set<std::string> service_contracts_;  // pmu-dds.contract of each pmu-service participant
};

struct Options {
  int domain = 0;
  double seconds = 10;
  std::string until;  // "", "decoded", "discovered"
  double linger = 1;
  std::string command;  // "", "GET_SERIAL", "GET"
  std::string parameter;
  std::string bus = "sim0";
  unsigned short address = 1;
  bool serve_health = false;
  std::string vehicle;
};

Topic* topic(DomainParticipant* p, const char* name, TypeSupport type) {
  type.register_type(p);
  return p->create_topic(name, type.get_type_name(), TOPIC_QOS_DEFAULT);
}

int serve_health(DomainParticipant* p, const Options& o) {
  PublisherQos pq = PUBLISHER_QOS_DEFAULT;
  if (!o.vehicle.empty()) pq.partition().push_back(o.vehicle.c_str());
  Publisher* pub = p->create_publisher(pq);
  DataWriter* w = pub ? pub->create_datawriter_with_profile(
                            topic(p, "pmu/health", TypeSupport(new idl::HealthPubSubType())), "state")
                      : nullptr;
  if (!w) return 2;
  idl::Health h;
  h.vehicle(o.vehicle);
  h.bus("can0");
  h.address(1);
  h.state(idl::ONLINE);
  h.bus_state(idl::UP);
  h.last_frame_age(0.1f);
  h.frames_received(100);
  w->write(&h);
  const auto end = Clock::now() + std::chrono::duration<double>(o.seconds);
  while (!g_stop && Clock::now() < end) std::this_thread::sleep_for(std::chrono::milliseconds(20));
  return 0;
}

template <class T>
int take_all(DataReader* r) {
  int n = 0;
  T s;
  SampleInfo info;
  while (r->take_next_sample(&s, &info) == ReturnCode_t::RETCODE_OK)
    if (info.valid_data) print(to_json(s)), ++n;
  return n;
}

int consume(DomainParticipant* p, const Options& o, const Discovery& discovery) {
  Subscriber* sub = p->create_subscriber(SUBSCRIBER_QOS_DEFAULT);
  Publisher* pub = p->create_publisher(PUBLISHER_QOS_DEFAULT);
  if (!sub || !pub) return 2;
  std::map<std::string, DataReader*> readers{
      {"pmu/health",
       sub->create_datareader_with_profile(topic(p, "pmu/health", TypeSupport(new idl::HealthPubSubType())), "state")},
      {"pmu/config",
       sub->create_datareader_with_profile(topic(p, "pmu/config", TypeSupport(new idl::ConfigPubSubType())), "state")},
      {"pmu/voltages", sub->create_datareader_with_profile(
                           topic(p, "pmu/voltages", TypeSupport(new idl::VoltagesPubSubType())), "telemetry")},
      {"pmu/status", sub->create_datareader_with_profile(
                         topic(p, "pmu/status", TypeSupport(new idl::StatusPubSubType())), "telemetry")}};
  DataWriter* commands = nullptr;
  if (!o.command.empty()) {
    readers["pmu/command_reply"] = sub->create_datareader_with_profile(
        topic(p, "pmu/command_reply", TypeSupport(new idl::CommandReplyPubSubType())), "command");
    commands = pub->create_datawriter_with_profile(topic(p, "pmu/command", TypeSupport(new idl::CommandPubSubType())),
                                                   "command");
    if (!commands) return 2;
  }
  for (const auto& [name, r] : readers)
    if (!r) return 2;

  const std::string request_id = "old-consumer-v" + std::to_string(PMU_OLD_CONTRACT) + "-" + std::to_string(getpid());
  bool sent = false;
  int replies = 0;  // final replies to our request
  // A probe, resent once a second until answered, before the request: the service's reply
  // writer may not have matched this reader yet when this side has matched it, and it would
  // not send what it wrote before (interface.md 2.4). After an answer, the request is sent
  // once and its replies are counted exactly.
  const std::string probe_id = request_id + "-probe";
  bool probe_answered = false;
  auto next_probe = Clock::now();
  std::map<std::string, int> samples;
  const auto end = Clock::now() + std::chrono::duration<double>(o.seconds);
  auto stop_at = end;
  while (!g_stop && Clock::now() < std::min(end, stop_at)) {
    samples["pmu/health"] += take_all<idl::Health>(readers["pmu/health"]);
    samples["pmu/config"] += take_all<idl::Config>(readers["pmu/config"]);
    samples["pmu/voltages"] += take_all<idl::Voltages>(readers["pmu/voltages"]);
    samples["pmu/status"] += take_all<idl::Status>(readers["pmu/status"]);
    if (commands) {
      idl::CommandReply r;
      SampleInfo info;
      while (readers["pmu/command_reply"]->take_next_sample(&r, &info) == ReturnCode_t::RETCODE_OK) {
        if (info.valid_data && r.request_id().to_string() == probe_id) probe_answered = true;
        if (!info.valid_data || r.request_id().to_string() != request_id) continue;
        print(to_json(r));
        if (r.result() != idl::IN_PROGRESS) ++replies;
      }
      PublicationMatchedStatus pm;
      SubscriptionMatchedStatus sm;
      commands->get_publication_matched_status(pm);
      readers["pmu/command_reply"]->get_subscription_matched_status(sm);
      if (!probe_answered && pm.current_count > 0 && sm.current_count > 0 && Clock::now() >= next_probe) {
        idl::Command probe;
        probe.request_id(probe_id);
        probe.bus(o.bus);
        probe.address(o.address);
        probe.kind(idl::GET_SERIAL);
        (void)commands->write(&probe);
        next_probe = Clock::now() + std::chrono::seconds(1);
      }
      if (!sent && probe_answered) {
        idl::Command c;
        c.request_id(request_id);
        c.bus(o.bus);
        c.address(o.address);
        c.kind(o.command == "GET" ? idl::GET : idl::GET_SERIAL);
        c.parameter(o.parameter);
        sent = commands->write(&c);
      }
    }
    if (stop_at == end) {
      bool done = !o.until.empty();
      if (o.until == "decoded") {
        for (const auto& [name, r] : readers)
          if (name != "pmu/command_reply") done = done && samples[name] > 0;
        done = done && (!commands || replies > 0);
      } else if (o.until == "discovered") {
        const auto types = discovery.types();
        for (const auto& [name, r] : readers) done = done && types.count(name);
        done = done && (!commands || types.count("reader:pmu/command"));
      }
      if (done)
        stop_at = Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(o.linger));
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }

  Json matched, discovered;
  for (const auto& [name, r] : readers) {
    SubscriptionMatchedStatus s;
    r->get_subscription_matched_status(s);
    matched[name] = s.total_count;  // ever matched: a match lost again still counts
  }
  if (commands) {
    PublicationMatchedStatus s;
    commands->get_publication_matched_status(s);
    matched["pmu/command"] = s.total_count;
  }
  for (const auto& [name, types] : discovery.types()) discovered[name] = types;
  print({{"final", true},
         {"contract", PMU_OLD_CONTRACT},
         {"matched", matched},
         {"discovered", discovered},
         {"service_contracts", discovery.service_contracts()},
         {"samples", samples},
         {"command_sent", sent},
         {"replies", replies},
         {"request_id", request_id}});
  return 0;
}

bool parse(int argc, char** argv, Options& o) {
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const char* v = i + 1 < argc ? argv[i + 1] : nullptr;
    if (a == "--serve-health") {
      o.serve_health = true;
      continue;
    }
    if (!v) return false;
    ++i;
    if (a == "--domain")
      o.domain = std::atoi(v);
    else if (a == "--seconds")
      o.seconds = std::atof(v);
    else if (a == "--until")
      o.until = v;
    else if (a == "--linger")
      o.linger = std::atof(v);
    else if (a == "--command")
      o.command = v;
    else if (a == "--parameter")
      o.parameter = v;
    else if (a == "--bus")
      o.bus = v;
    else if (a == "--address")
      o.address = static_cast<unsigned short>(std::atoi(v));
    else if (a == "--vehicle")
      o.vehicle = v;
    else
      return false;
  }
  return o.until.empty() || o.until == "decoded" || o.until == "discovered";
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  if (!parse(argc, argv, o)) {
    std::fprintf(stderr, "usage: see the top of tests/contract/consumers/old_consumer/old_consumer.cpp\n");
    return 2;
  }
  // SIGTERM ends the loop, so the participant is deleted and leaves no shared-memory ports.
  std::signal(SIGTERM, [](int) { g_stop = 1; });
  std::signal(SIGINT, [](int) { g_stop = 1; });
  auto* factory = DomainParticipantFactory::get_instance();
  const char* qos = std::getenv("PMU_QOS_FILE");
  if (!qos || factory->load_XML_profiles_file(qos) != ReturnCode_t::RETCODE_OK) {
    std::fprintf(stderr, "old_consumer: cannot load the QoS profiles of $PMU_QOS_FILE\n");
    return 2;
  }
  DomainParticipantQos pqos = PARTICIPANT_QOS_DEFAULT;
  pqos.name(o.serve_health ? "pmu-service" : "old-consumer-v" + std::to_string(PMU_OLD_CONTRACT));
  Discovery discovery;
  DomainParticipant* p = factory->create_participant(static_cast<DomainId_t>(o.domain), pqos, &discovery);
  if (!p) return 2;
  const int rc = o.serve_health ? serve_health(p, o) : consume(p, o, discovery);
  p->delete_contained_entities();
  factory->delete_participant(p);
  return rc;
}
