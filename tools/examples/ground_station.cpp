// ground_station_example [--domain N] [--bus NAME] [--address N]
//
// A bench check the way a ground-station bridge would do it, written against interface.md
// alone: the generated types of idl/*.idl, the topic names and the QoS profiles of
// deploy/qos.xml. It reads the PMU's config, sets the avionics and payload voltages, cycles
// the payload output off and on, and reads the status. Every command gets exactly one final
// reply, correlated by request_id. Exit status 0 when every step COMPLETED.
//
// Build: it is the CMake target `ground_station_example` (links the generated pmu::idl and
// Fast DDS only; pmu/sysconf_dir.hpp only names where qos.xml is installed).
// Run: pmu-service --bus sim & ground_station_example
//
// DDS-Security: with PMU_SECURITY_DIR set (a folder made by deploy/security/make_pki.sh)
// it joins with the identity PMU_SECURITY_IDENTITY (default ground-station), through the
// standard DDS-Security participant properties below; nothing else changes.

#include <fastdds/dds/core/status/PublicationMatchedStatus.hpp>
#include <fastdds/dds/core/status/SubscriptionMatchedStatus.hpp>
#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/topic/Topic.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <thread>
#include <unistd.h>

#include "pmu/idl/command.h"
#include "pmu/idl/commandPubSubTypes.h"
#include "pmu/idl/state.h"
#include "pmu/idl/statePubSubTypes.h"
#include "pmu/idl/telemetry.h"
#include "pmu/sysconf_dir.hpp"
#include "pmu/idl/telemetryPubSubTypes.h"

using namespace eprosima::fastdds::dds;
using namespace std::chrono_literals;

namespace {

struct Link {
  DomainParticipant* participant = nullptr;
  DataWriter* commands = nullptr;
  DataReader* replies = nullptr;
  DataReader* config = nullptr;
  DataReader* status = nullptr;
  std::string bus = "sim0";
  unsigned short address = 1;
  int next = 0;
};

Topic* topic(DomainParticipant* p, const char* name, TypeSupport type) {
  type.register_type(p);
  return p->create_topic(name, type.get_type_name(), TOPIC_QOS_DEFAULT);
}

// Sends one command and waits for its final reply (IN_PROGRESS replies are shown, not final).
bool command(Link& l, pmu::v5::CommandKind kind, const char* what, const char* parameter = "", double value = 0,
             unsigned char outputs = 0) {
  pmu::v5::Command c;
  const std::string id = "ground-station-example-" + std::to_string(++l.next);
  c.request_id(id);
  c.bus(l.bus);
  c.address(l.address);
  c.kind(kind);
  c.parameter(parameter);
  c.value(value);
  c.outputs(outputs);
  const auto expires = std::chrono::system_clock::now() + 5s;
  c.expires_at(static_cast<unsigned long long>(
      std::chrono::duration_cast<std::chrono::nanoseconds>(expires.time_since_epoch()).count()));
  // Sent again with the same id while no reply came, once a second: the service answers a
  // resend and never executes it twice (interface.md 2.4). The first one can go unanswered:
  // this writer and reader having matched the service's says nothing of whether the service's
  // reply writer has matched this reader yet, and it sends no reader what it wrote before.
  const auto resend_until = std::chrono::steady_clock::now() + 5s;  // the request's expiry
  const auto deadline = resend_until + 1s;
  auto next_send = std::chrono::steady_clock::now();
  while (std::chrono::steady_clock::now() < deadline) {
    if (std::chrono::steady_clock::now() >= next_send && std::chrono::steady_clock::now() < resend_until) {
      l.commands->write(&c);
      next_send = std::chrono::steady_clock::now() + 1s;
    }
    pmu::v5::CommandReply r;
    SampleInfo info;
    while (l.replies->take_next_sample(&r, &info) == ReturnCode_t::RETCODE_OK) {
      if (!info.valid_data || r.request_id().to_string() != id || r.result() == pmu::v5::IN_PROGRESS) continue;
      const bool ok = r.result() == pmu::v5::COMPLETED;
      std::printf("%-36s %s%s%s\n", what, ok ? "COMPLETED" : "NOT COMPLETED", r.reason().size() ? ": " : "",
                  r.reason().c_str());
      return ok;
    }
    std::this_thread::sleep_for(5ms);
  }
  std::printf("%-36s no reply\n", what);
  return false;
}

template <class T>
bool latest(DataReader* r, T& out, std::chrono::milliseconds wait) {
  const auto deadline = std::chrono::steady_clock::now() + wait;
  bool got = false;
  while (std::chrono::steady_clock::now() < deadline && !got) {
    SampleInfo info;
    while (r->take_next_sample(&out, &info) == ReturnCode_t::RETCODE_OK) got = got || info.valid_data;
    if (!got) std::this_thread::sleep_for(10ms);
  }
  return got;
}

// DDS-Security's builtin plugins, configured by participant properties (file: URIs).
void add_security(DomainParticipantQos& qos, std::string dir, const std::string& identity) {
  if (dir.empty()) return;
  if (dir.front() != '/') {
    char cwd[4096];
    if (getcwd(cwd, sizeof cwd)) dir = std::string(cwd) + "/" + dir;
  }
  const std::string uri = "file://" + dir + "/";
  auto& p = qos.properties().properties();
  p.emplace_back("dds.sec.auth.plugin", "builtin.PKI-DH");
  p.emplace_back("dds.sec.auth.builtin.PKI-DH.identity_ca", uri + "identity_ca.pem");
  p.emplace_back("dds.sec.auth.builtin.PKI-DH.identity_certificate", uri + identity + "/cert.pem");
  p.emplace_back("dds.sec.auth.builtin.PKI-DH.private_key", uri + identity + "/key.pem");
  p.emplace_back("dds.sec.access.plugin", "builtin.Access-Permissions");
  p.emplace_back("dds.sec.access.builtin.Access-Permissions.permissions_ca", uri + "permissions_ca.pem");
  p.emplace_back("dds.sec.access.builtin.Access-Permissions.governance", uri + "governance.p7s");
  p.emplace_back("dds.sec.access.builtin.Access-Permissions.permissions", uri + identity + "/permissions.p7s");
  p.emplace_back("dds.sec.crypto.plugin", "builtin.AES-GCM-GMAC");
}

}  // namespace

int main(int argc, char** argv) {
  int domain = 0;
  Link l;
  for (int i = 1; i + 1 < argc; i += 2) {
    if (!std::strcmp(argv[i], "--domain")) domain = std::atoi(argv[i + 1]);
    if (!std::strcmp(argv[i], "--bus")) l.bus = argv[i + 1];
    if (!std::strcmp(argv[i], "--address")) l.address = static_cast<unsigned short>(std::atoi(argv[i + 1]));
  }
  // The contract's QoS profiles, loaded by name.
  const char* qos = std::getenv("PMU_QOS_FILE");
  auto* factory = DomainParticipantFactory::get_instance();
  if (factory->load_XML_profiles_file(qos ? qos : PMU_SYSCONFDIR "/qos.xml") != ReturnCode_t::RETCODE_OK) {
    std::fprintf(stderr, "cannot load the QoS profiles (set PMU_QOS_FILE to deploy/qos.xml)\n");
    return 2;
  }
  DomainParticipantQos pqos = PARTICIPANT_QOS_DEFAULT;
  const char* security_dir = std::getenv("PMU_SECURITY_DIR");
  const char* identity = std::getenv("PMU_SECURITY_IDENTITY");
  add_security(pqos, security_dir ? security_dir : "", identity && *identity ? identity : "ground-station");
  l.participant = factory->create_participant(static_cast<DomainId_t>(domain), pqos);
  if (!l.participant) {
    std::fprintf(stderr, "cannot create the DDS participant%s\n",
                 security_dir && *security_dir ? " (check the DDS-Security files in PMU_SECURITY_DIR)" : "");
    return 2;
  }
  Publisher* pub = l.participant->create_publisher(PUBLISHER_QOS_DEFAULT);
  Subscriber* sub = l.participant->create_subscriber(SUBSCRIBER_QOS_DEFAULT);
  l.commands = pub->create_datawriter_with_profile(
      topic(l.participant, "pmu/command", TypeSupport(new pmu::v5::CommandPubSubType())), "command");
  l.replies = sub->create_datareader_with_profile(
      topic(l.participant, "pmu/command_reply", TypeSupport(new pmu::v5::CommandReplyPubSubType())), "command");
  l.config = sub->create_datareader_with_profile(
      topic(l.participant, "pmu/config", TypeSupport(new pmu::v5::ConfigPubSubType())), "state");
  l.status = sub->create_datareader_with_profile(
      topic(l.participant, "pmu/status", TypeSupport(new pmu::v5::StatusPubSubType())), "telemetry");
  if (!l.commands || !l.replies || !l.config || !l.status) {
    // With DDS-Security: this identity's permissions do not allow one of them.
    std::fprintf(stderr, "cannot create the command writer and the readers (DDS-Security permissions?)\n");
    l.participant->delete_contained_entities();
    factory->delete_participant(l.participant);
    return 2;
  }

  // Wait until the service's command reader and reply writer are matched.
  for (int i = 0; i < 500; ++i) {
    PublicationMatchedStatus p;
    SubscriptionMatchedStatus s;
    l.commands->get_publication_matched_status(p);
    l.replies->get_subscription_matched_status(s);
    if (p.current_count > 0 && s.current_count > 0) break;
    std::this_thread::sleep_for(10ms);
  }

  bool ok = true;
  pmu::v5::Config cfg;
  if (latest(l.config, cfg, 3000ms))
    std::printf("config: avionics %.1f V, payload %.1f V, servo %.1f V, outputs 0x%02X\n", cfg.avionics_voltage(),
                cfg.payload_voltage(), cfg.servo_voltage(), cfg.outputs());
  else
    ok = false, std::printf("config: not received\n");
  ok &= command(l, pmu::v5::SET_PARAMETER, "set avionics_voltage 24.0 V", "avionics_voltage", 24.0);
  ok &= command(l, pmu::v5::SET_PARAMETER, "set payload_voltage 18.0 V", "payload_voltage", 18.0);
  ok &= command(l, pmu::v5::DISABLE_OUTPUTS, "payload output off", "", 0, 0x02);
  ok &= command(l, pmu::v5::ENABLE_OUTPUTS, "payload output on", "", 0, 0x02);
  pmu::v5::Status st;
  if (latest(l.status, st, 3000ms))
    // NaN: the PMU has no reading (interface.md section 1.1); printf prints it as "nan".
    std::printf("status: generator %.0f rpm, payload %s, avionics %s\n", static_cast<double>(st.generator_rpm()),
                st.payload_on() ? "on" : "off", st.avionics_servo_on() ? "on" : "off");
  else
    ok = false, std::printf("status: not received\n");

  l.participant->delete_contained_entities();
  factory->delete_participant(l.participant);
  return ok ? 0 : 1;
}
