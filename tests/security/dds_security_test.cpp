// DDS-Security against the real Fast DDS 2.9.1 library (Debian's, HAVE_SECURITY=1), with a
// PKI made at test time by deploy/security/make_pki.sh and the bad variants of
// make_variants.sh. The service side is the real thing in-process (bus worker, command
// service, DDS publisher and command endpoint on a simulated PMU); clients are separate
// participants. Every participant here uses UDP only and intraprocess delivery is off, so
// all traffic crosses the loopback interface like between two hosts.
//
// Each test runs in its own process (gtest_discover_tests) on a DDS domain of its own and
// with a PKI of its own (pki_fixture.hpp). Label `security-integration` (tests/security/
// CMakeLists.txt says why).
#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <linux/if_ether.h>
#include <linux/if_packet.h>
#include <poll.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <cctype>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fastdds/dds/core/status/PublicationMatchedStatus.hpp>
#include <fastdds/dds/core/status/SubscriptionMatchedStatus.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fstream>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <set>
#include <sstream>
#include <thread>

#include "support/pki_fixture.hpp"
#include "pmu/config/config.hpp"
#include "pmu/dds_settings/vehicle.hpp"
#include "pmu/dds/dds_context.hpp"
#include "pmu/dispatch/command_service.hpp"
#include "pmu/endpoints/dds_commands.hpp"
#include "pmu/endpoints/dds_publisher.hpp"
#include "pmu/idl/alarmsPubSubTypes.h"
#include "pmu/idl/commandPubSubTypes.h"
#include "pmu/idl/statePubSubTypes.h"
#include "pmu/idl/telemetryPubSubTypes.h"
#include "pmu/idl/topics.hpp"
#include "pmu/security/security_files.hpp"
#include "pmu/session/bus_worker.hpp"
#include "pmu/sim/bus_runner.hpp"
#include "pmu/transport/sim_bus.hpp"
#include "support/answered.hpp"
#include "support/in_process_service.hpp"
#include "support/process.hpp"
#include "support/wait.hpp"

namespace pmu::service {
namespace {

using namespace eprosima::fastdds::dds;
using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;
using dds::SecurityFiles;
using security_test::allowed;
using security_test::Pki;
using security_test::sh;
using security_test::write_config;

// ---- the service, in-process ------------------------------------------------------------

constexpr std::uint8_t kPayload = 0x02;  // output bit 1

// Over UDP only: the wire capture looks at loopback.
struct ServiceUnderTest : pmu::test::InProcessService {
  // `bus_name` is the DDS key of every sample (also something to look for on the wire);
  // `vehicle` the service's vehicle, and so its partition (vehicle.hpp).
  ServiceUnderTest(int domain, const SecurityFiles& files, const std::string& bus_name = "sim0",
                   const std::string& vehicle = "")
      : InProcessService(domain, options(files, bus_name, vehicle)) {}
  static Options options(const SecurityFiles& files, const std::string& bus_name, const std::string& vehicle) {
    Options o;
    o.vehicle = vehicle;
    o.bus_name = bus_name;
    o.security = files;
    o.transport = dds::Transport::UdpOnly;
    return o;
  }
};

// ---- clients -------------------------------------------------------------------------------

struct Client {
  Client(int domain, const SecurityFiles& files, const std::string& name, const dds::Partitions& partitions = {})
      : dds(domain, "", name, files, dds::Transport::UdpOnly, {}, partitions) {}
  DataReader& voltages() {
    if (!voltages_)
      voltages_ = &dds.reader(dds.topic(topics::kVoltages, TypeSupport(new pmu::v5::VoltagesPubSubType())),
                              qos_profiles::kTelemetry);
    return *voltages_;
  }
  DataReader& config() {
    if (!config_)
      config_ =
          &dds.reader(dds.topic(topics::kConfig, TypeSupport(new pmu::v5::ConfigPubSubType())), qos_profiles::kState);
    return *config_;
  }
  DataWriter& commands() {
    if (!commands_)
      commands_ = &dds.writer(dds.topic(topics::kCommand, TypeSupport(new pmu::v5::CommandPubSubType())),
                              qos_profiles::kCommand);
    return *commands_;
  }
  DataReader& replies() {
    if (!replies_)
      replies_ = &dds.reader(dds.topic(topics::kCommandReply, TypeSupport(new pmu::v5::CommandReplyPubSubType())),
                             qos_profiles::kCommand);
    return *replies_;
  }
  int commands_matched() {
    PublicationMatchedStatus s;
    commands().get_publication_matched_status(s);
    return s.total_count;
  }
  dds::DdsContext dds;

 private:
  DataReader* voltages_ = nullptr;
  DataReader* config_ = nullptr;
  DataWriter* commands_ = nullptr;
  DataReader* replies_ = nullptr;
};

template <class T>
int take_all(DataReader& r) {
  T sample;
  SampleInfo info;
  int n = 0;
  while (r.take_next_sample(&sample, &info) == ReturnCode_t::RETCODE_OK) n += info.valid_data ? 1 : 0;
  return n;
}

template <class T>
bool wait_sample(DataReader& r, std::chrono::milliseconds timeout) {
  return pmu::test::wait_until([&] { return take_all<T>(r) > 0; }, timeout, 20ms);
}

pmu::v5::Command command(const std::string& id, const std::string& bus = "sim0", const std::string& vehicle = "") {
  pmu::v5::Command c;
  c.request_id(id);
  c.vehicle(vehicle);
  c.bus(bus);
  c.address(1);
  c.kind(pmu::v5::DISABLE_OUTPUTS);  // switch the payload off
  c.outputs(kPayload);
  const auto expires = std::chrono::system_clock::now() + 10s;
  c.expires_at(static_cast<unsigned long long>(
      std::chrono::duration_cast<std::chrono::nanoseconds>(expires.time_since_epoch()).count()));
  return c;
}

std::optional<pmu::v5::CommandReply> wait_reply(DataReader& r, const std::string& id,
                                                std::chrono::milliseconds timeout) {
  std::optional<pmu::v5::CommandReply> found;
  pmu::test::wait_until(
      [&] {
        pmu::v5::CommandReply reply;
        SampleInfo info;
        while (r.take_next_sample(&reply, &info) == ReturnCode_t::RETCODE_OK)
          if (info.valid_data && reply.request_id().to_string() == id && reply.result() != pmu::v5::IN_PROGRESS) {
            found = reply;
            return true;
          }
        return false;
      },
      timeout);
  return found;
}

// Sends `c`, and again with the same id once a second while no final reply came, as pmuctl
// does (support/answered.hpp says why this side's match is not enough): its final reply.
std::optional<pmu::v5::CommandReply> send_until_answered(Client& gs, pmu::v5::Command c, std::chrono::seconds within) {
  std::optional<pmu::v5::CommandReply> reply;
  const std::string id = c.request_id().to_string();
  (void)pmu::test::until_answered([&] { EXPECT_TRUE(gs.commands().write(&c)); },
                                  [&] { return (reply = wait_reply(gs.replies(), id, 0ms)).has_value(); }, within);
  return reply;
}

// Like pmuctl: wait until the service's command reader and reply writer are matched.
bool wait_command_link(Client& gs, std::chrono::milliseconds timeout) {
  return pmu::test::wait_until(
      [&] {
        PublicationMatchedStatus p;
        SubscriptionMatchedStatus s;
        gs.commands().get_publication_matched_status(p);
        gs.replies().get_subscription_matched_status(s);
        return p.current_count > 0 && s.current_count > 0;
      },
      timeout);
}

// The good ground station commands: the reply comes, and the PMU did it.
void expect_ground_station_commands(ServiceUnderTest& svc, Client& gs, const std::string& id,
                                    const std::string& vehicle = "") {
  const bool linked = wait_command_link(gs, 10s);
  PublicationMatchedStatus writer;
  SubscriptionMatchedStatus reader;
  gs.commands().get_publication_matched_status(writer);
  gs.replies().get_subscription_matched_status(reader);
  // Both 0: the two participants never completed secure discovery, which is what Fast DDS
  // 2.9.1's matching race does without pmu/dds/security_match_guard.hpp.
  ASSERT_TRUE(linked) << "the ground station's command writer and reply reader never matched (writer matched "
                      << writer.current_count << " readers, reply reader " << reader.current_count << " writers)";
  const auto reply = send_until_answered(gs, command(id, "sim0", vehicle), 10s);
  ASSERT_TRUE(reply.has_value()) << "no reply to " << id;
  EXPECT_EQ(reply->result(), pmu::v5::COMPLETED) << reply->reason();
  EXPECT_EQ(svc.outputs() & kPayload, 0) << "the payload output is still on";
}

// What an intruder achieved in 4 s of listening to telemetry and sending commands (switch
// the payload off), next to a legitimate reader.
struct Intrusion {
  int good_samples = 0;        // telemetry the legitimate reader got meanwhile
  int stolen_samples = 0;      // telemetry the intruder got
  int writer_matches = 0;      // the intruder's command writer matched the service's reader
  std::uint64_t received = 0;  // commands the command service received
  bool outputs_changed = false;
  bool pmu_handled_something = false;
};

Intrusion intrude(ServiceUnderTest& svc, Client& intruder, Client& good) {
  Intrusion r;
  DataReader& stolen = intruder.voltages();
  DataWriter& writer = intruder.commands();
  EXPECT_TRUE(wait_sample<pmu::v5::Voltages>(good.voltages(), 20s)) << "the legitimate reader got no telemetry: "
                                                                       "the service is not reachable at all";
  EXPECT_TRUE(wait_sample<pmu::v5::Config>(good.config(), 10s)) << "no pmu/config: the service's start-up is not done";
  // Meant to let time pass (kept as it was): the intruder's discovery and handshake attempts
  // run before the "before" figures are taken; there is nothing to wait for, since it must
  // NOT match.
  std::this_thread::sleep_for(300ms);
  const std::uint64_t handled_before = svc.handled();
  const std::uint8_t outputs_before = svc.outputs();
  EXPECT_NE(outputs_before & kPayload, 0) << "the payload must be on for the test to mean anything";
  r.stolen_samples = take_all<pmu::v5::Voltages>(stolen);
  for (int i = 0; i < 20; ++i) {
    pmu::v5::Command c = command("intruder-" + std::to_string(i));
    writer.write(&c);
    // Meant to let time pass: 20 x 200 ms = the 4 s of intrusion; nothing must happen in them.
    std::this_thread::sleep_for(200ms);
    r.stolen_samples += take_all<pmu::v5::Voltages>(stolen);
    r.good_samples += take_all<pmu::v5::Voltages>(good.voltages());
  }
  r.writer_matches = intruder.commands_matched();
  r.received = svc.commands.counters().received;
  r.outputs_changed = svc.outputs() != outputs_before;
  r.pmu_handled_something = svc.handled() != handled_before;
  return r;
}

// Nothing may reach the intruder and nothing it sends may reach the service or the PMU,
// while the legitimate reader receives telemetry all along.
void expect_shut_out(ServiceUnderTest& svc, Client& intruder, Client& good) {
  const Intrusion r = intrude(svc, intruder, good);
  EXPECT_GE(r.good_samples, 4) << "the legitimate reader should have received telemetry meanwhile";
  EXPECT_EQ(r.stolen_samples, 0) << "the intruder received telemetry";
  EXPECT_EQ(r.writer_matches, 0) << "the intruder's command writer matched the service's reader";
  EXPECT_EQ(r.received, 0u) << "a command from the intruder reached the command service";
  EXPECT_FALSE(r.outputs_changed) << "the PMU's outputs changed";
  EXPECT_FALSE(r.pmu_handled_something) << "the PMU handled a request meanwhile";
}

// ---- the contract's permissions, entity by entity -------------------------------------------

struct TopicInfo {
  const char* name;
  std::function<TypeSupport()> type;
  const char* profile;
};

const TopicInfo kTopics[] = {
    {topics::kVoltages, [] { return TypeSupport(new pmu::v5::VoltagesPubSubType()); }, qos_profiles::kTelemetry},
    {topics::kCurrents, [] { return TypeSupport(new pmu::v5::CurrentsPubSubType()); }, qos_profiles::kTelemetry},
    {topics::kBatteryEnergy, [] { return TypeSupport(new pmu::v5::BatteryEnergyPubSubType()); },
     qos_profiles::kTelemetry},
    {topics::kTemperatures, [] { return TypeSupport(new pmu::v5::TemperaturesPubSubType()); },
     qos_profiles::kTelemetry},
    {topics::kStatus, [] { return TypeSupport(new pmu::v5::StatusPubSubType()); }, qos_profiles::kTelemetry},
    {topics::kConfig, [] { return TypeSupport(new pmu::v5::ConfigPubSubType()); }, qos_profiles::kState},
    {topics::kInfo, [] { return TypeSupport(new pmu::v5::DeviceInfoPubSubType()); }, qos_profiles::kState},
    {topics::kHealth, [] { return TypeSupport(new pmu::v5::HealthPubSubType()); }, qos_profiles::kState},
    {topics::kCommand, [] { return TypeSupport(new pmu::v5::CommandPubSubType()); }, qos_profiles::kCommand},
    {topics::kCommandReply, [] { return TypeSupport(new pmu::v5::CommandReplyPubSubType()); }, qos_profiles::kCommand},
    {topics::kAlarmAck, [] { return TypeSupport(new pmu::v5::AlarmAckPubSubType()); }, qos_profiles::kCommand},
    {topics::kAlarmAckReply, [] { return TypeSupport(new pmu::v5::AlarmAckReplyPubSubType()); },
     qos_profiles::kCommand},
};

TEST(Permissions, EveryIdentityMayCreateExactlyTheWritersAndReadersTheContractAllows) {
  for (const char* identity : {"pmu-service", "ground-station", "mission-computer"}) {
    dds::DdsContext p(pmu::test::exclusive_dds_domain(), "", std::string("matrix-") + identity,
                      Pki::get().files(identity), dds::Transport::UdpOnly);
    for (const auto& t : kTopics) {
      Topic& topic = p.topic(t.name, t.type());
      for (const bool publish : {true, false}) {
        bool created = true;
        try {
          if (publish)
            p.writer(topic, t.profile);
          else
            p.reader(topic, t.profile);
        } catch (const dds::DdsError&) {
          created = false;
        }
        EXPECT_EQ(created, allowed(identity, t.name, publish))
            << identity << (publish ? " publish " : " subscribe ") << t.name << ": Fast DDS "
            << (created ? "allowed" : "refused") << " it";
      }
    }
  }
}

// The governance document says what the issue asks.
// ---- the right identities work ------------------------------------------------------------

// Config dds_statistics under DDS-Security (interface.md 6): make_pki.sh grants no identity
// the statistics topics, and Fast DDS would only log the refused writers, so the participant
// is not created at all and the message says what the permissions lack.
TEST(Permissions, StatisticsTopicsThePermissionsDoNotGrantAreRefusedAtStartUp) {
  try {
    dds::DdsContext p(pmu::test::exclusive_dds_domain(), "", "statistics-not-granted", Pki::get().files("pmu-service"),
                      dds::Transport::UdpOnly, {}, {}, {"_fastdds_statistics_history2history_latency"});
    ADD_FAILURE() << "created";
  } catch (const dds::DdsError& e) {
    EXPECT_EQ(std::string(e.what()),
              "dds_statistics: this identity's permissions do not allow publishing "
              "_fastdds_statistics_history2history_latency in the default partition (DDS-Security; "
              "docs/interface.md section 6 says what to grant)");
  }
}

TEST(SecureDds, GroundStationCommandsAndMissionComputerReadsTelemetry) {
  const int domain = pmu::test::exclusive_dds_domain();
  ServiceUnderTest svc(domain, Pki::get().files("pmu-service"));
  Client gs(domain, Pki::get().files("ground-station"), "ground-station");
  Client mc(domain, Pki::get().files("mission-computer"), "mission-computer");
  EXPECT_TRUE(wait_sample<pmu::v5::Voltages>(gs.voltages(), 20s)) << "ground station: no telemetry";
  EXPECT_TRUE(wait_sample<pmu::v5::Voltages>(mc.voltages(), 20s)) << "mission computer: no telemetry";
  EXPECT_TRUE(wait_sample<pmu::v5::Config>(mc.config(), 10s)) << "mission computer: no pmu/config (state)";
  ASSERT_NO_FATAL_FAILURE(expect_ground_station_commands(svc, gs, "gs-1"));
  EXPECT_EQ(svc.commands.counters().received, 1u);
}

// ---- who is shut out ------------------------------------------------------------------------

TEST(SecureDds, UnauthenticatedParticipantGetsNoTelemetryAndCannotCommand) {
  const int domain = pmu::test::exclusive_dds_domain();
  ServiceUnderTest svc(domain, Pki::get().files("pmu-service"));
  Client good(domain, Pki::get().files("mission-computer"), "mission-computer");
  Client intruder(domain, SecurityFiles{}, "unauthenticated");
  expect_shut_out(svc, intruder, good);
}

TEST(SecureDds, CertificateFromAForeignCaIsRejected) {
  const int domain = pmu::test::exclusive_dds_domain();
  // A complete PKI of its own: its own CAs, governance and permissions, and an identity
  // called ground-station.
  const std::string foreign = Pki::get().foreign();
  ServiceUnderTest svc(domain, Pki::get().files("pmu-service"));
  Client good(domain, Pki::get().files("mission-computer"), "mission-computer");
  Client intruder(domain, dds::security_files_in(foreign, "ground-station"), "foreign-ground-station");
  expect_shut_out(svc, intruder, good);
}

TEST(SecureDds, ExpiredCertificateIsRejected) {
  const int domain = pmu::test::exclusive_dds_domain();
  // A ground-station certificate from the real Identity CA, valid for a few seconds: the
  // intruder's participant is created while it is valid (Fast DDS checks its own identity
  // only then), the service starts after it has expired. On a loaded machine making the
  // certificate and the participant can outlast a short validity; then a longer one is tried,
  // so the test never depends on how fast this machine is.
  std::unique_ptr<Client> intruder;
  std::chrono::system_clock::time_point expiry;
  for (const auto validity : {5s, 20s, 60s}) {
    const auto now = std::chrono::system_clock::now();
    expiry = now + validity;
    const std::string expiring = Pki::get().window("expiring-" + std::to_string(validity.count()), now - 60s, expiry);
    try {
      intruder = std::make_unique<Client>(domain, dds::security_files_in(expiring, "ground-station"),
                                          "expired-ground-station");
      intruder->voltages();
      intruder->commands();
      if (std::chrono::system_clock::now() < expiry) break;
    } catch (const dds::DdsError&) {
      if (std::chrono::system_clock::now() < expiry) throw;  // refused while still valid: a real failure
    }
    intruder.reset();
  }
  ASSERT_TRUE(intruder) << "no participant could be created with a certificate valid for up to 60 s";
  std::this_thread::sleep_until(expiry + 2s);
  ASSERT_GT(std::chrono::system_clock::now(), expiry + 1s);
  ServiceUnderTest svc(domain, Pki::get().files("pmu-service"));
  Client good(domain, Pki::get().files("mission-computer"), "mission-computer");
  expect_shut_out(svc, *intruder, good);
}

TEST(SecureDds, MissionComputerCannotWriteCommands) {
  const int domain = pmu::test::exclusive_dds_domain();
  ServiceUnderTest svc(domain, Pki::get().files("pmu-service"));
  Client mc(domain, Pki::get().files("mission-computer"), "mission-computer");
  ASSERT_TRUE(wait_sample<pmu::v5::Voltages>(mc.voltages(), 20s)) << "the mission computer should read telemetry";
  ASSERT_TRUE(wait_sample<pmu::v5::Config>(mc.config(), 10s)) << "no pmu/config: the service's start-up is not done";
  const std::uint64_t handled_before = svc.handled();
  // Its own participant refuses to create the writer (local access control) ...
  DataWriter* writer = nullptr;
  try {
    writer = &mc.commands();
  } catch (const dds::DdsError&) {
  }
  EXPECT_EQ(writer, nullptr) << "Fast DDS let the mission computer create a pmu/command writer";
  if (writer) {  // only with broken permissions: then show what it can do
    pmu::test::wait_until([&] { return mc.commands_matched() != 0; }, 3s);
    for (int i = 0; i < 5; ++i) {
      pmu::v5::Command c = command("mission-computer-" + std::to_string(i));
      writer->write(&c);
    }
  }
  // ... and the reply topic is not its business either.
  EXPECT_THROW(mc.replies(), dds::DdsError);
  // Meant to let time pass: no command may arrive, so there is no condition to wait for.
  std::this_thread::sleep_for(2s);
  EXPECT_EQ(svc.commands.counters().received, 0u) << "a command from the mission computer reached the service";
  EXPECT_NE(svc.outputs() & kPayload, 0) << "the payload was switched off";
  EXPECT_EQ(svc.handled(), handled_before) << "the PMU handled a request meanwhile";
}

TEST(SecureDds, MissionComputerWithARelaxedGovernanceStillCannotCommand) {
  const int domain = pmu::test::exclusive_dds_domain();
  // The mission computer's real identity and permissions, but a local governance (signed by
  // the real Permissions CA) that does not guard pmu/command, as a tampered or misconfigured
  // client might have: its own participant then creates the writer. The service must still
  // not take its commands. (What stops it in Fast DDS 2.9 is the endpoint security
  // attributes: the writer announces itself as not write-protected, the service's
  // governance requires it to be, and the match is refused before permissions come into
  // it. With the mission computer allowed to publish pmu/command this test still passes:
  // it guards the relaxed-governance case, not the permission itself.)
  const std::string lax = Pki::get().lax();
  ServiceUnderTest svc(domain, Pki::get().files("pmu-service"));
  Client good(domain, Pki::get().files("ground-station"), "ground-station");
  Client mc(domain, dds::security_files_in(lax, "mission-computer"), "tampered-mission-computer");
  ASSERT_NO_THROW(mc.commands()) << "the relaxed governance should let its own participant create the writer";
  ASSERT_TRUE(wait_sample<pmu::v5::Voltages>(mc.voltages(), 20s)) << "it is still a mission computer: telemetry";
  ASSERT_TRUE(wait_sample<pmu::v5::Config>(good.config(), 10s)) << "no pmu/config: the service's start-up is not done";
  const std::uint64_t handled_before = svc.handled();
  for (int i = 0; i < 15; ++i) {
    pmu::v5::Command c = command("tampered-" + std::to_string(i));
    mc.commands().write(&c);
    // Meant to let time pass: 15 x 200 ms in which nothing may reach the service.
    std::this_thread::sleep_for(200ms);
  }
  EXPECT_EQ(mc.commands_matched(), 0) << "the service matched the mission computer's command writer";
  EXPECT_EQ(svc.commands.counters().received, 0u) << "a command from the mission computer reached the service";
  EXPECT_NE(svc.outputs() & kPayload, 0) << "the payload was switched off";
  EXPECT_EQ(svc.handled(), handled_before) << "the PMU handled a request meanwhile";
  // The ground station still commands.
  ASSERT_NO_FATAL_FAILURE(expect_ground_station_commands(svc, good, "gs-after-tampering"));
}

TEST(SecureDds, PermissionsSignedByTheParticipantItselfAreRejected) {
  const int domain = pmu::test::exclusive_dds_domain();
  // CVE-2023-24010's shape: mission-computer gives itself the ground station's rights in a
  // permissions document signed with its own identity (which the Identity CA issued). Its
  // own participant accepts it (it trusts the Identity CA for documents); the service,
  // which trusts only the separate Permissions CA, must not.
  const std::string self = Pki::get().selfsigned();
  ServiceUnderTest svc(domain, Pki::get().files("pmu-service"));
  Client good(domain, Pki::get().files("mission-computer"), "mission-computer");
  Client intruder(domain, dds::security_files_in(self, "mission-computer"), "self-signed-mission-computer");
  expect_shut_out(svc, intruder, good);
}

// The control for the test above, and the reason the start-up check refuses one CA for
// both roles: with a single CA (it issues the identities and signs the documents), Debian's
// Fast DDS 2.9.1 takes the same self-signed permissions and the mission computer reads
// telemetry and switches the payload off. Skipped, not failed, if a fixed Fast DDS refuses.
TEST(SecureDds, Cve202324010WithOneCaTheSelfSignedPermissionsWouldBeAccepted) {
  const int domain = pmu::test::exclusive_dds_domain();
  const std::string single = Pki::get().single_ca();
  ServiceUnderTest svc(domain, dds::security_files_in(single + "/world", "pmu-service"));
  Client good(domain, dds::security_files_in(single + "/world", "ground-station"), "ground-station");
  Client intruder(domain, dds::security_files_in(single + "/intruder", "mission-computer"),
                  "self-signed-mission-computer");
  const Intrusion r = intrude(svc, intruder, good);
  EXPECT_GE(r.good_samples, 4) << "the single-CA world itself does not work";
  if (r.stolen_samples == 0 && r.received == 0)
    GTEST_SKIP() << "this Fast DDS refuses self-signed permissions even with one CA: CVE-2023-24010 is fixed here";
  EXPECT_GT(r.stolen_samples, 0);
  EXPECT_GT(r.received, 0u);
  EXPECT_TRUE(r.outputs_changed) << "the intruder's command should have switched the payload off";
  std::printf(
      "CVE-2023-24010 reproduced with one CA: the intruder got %d telemetry samples, the service took %llu "
      "of its commands\n",
      r.stolen_samples, static_cast<unsigned long long>(r.received));
}

// ---- the wire ------------------------------------------------------------------------------

// Every frame on every interface (AF_PACKET) while it runs; needs CAP_NET_RAW.
class Capture {
 public:
  Capture() : fd_(::socket(AF_PACKET, SOCK_RAW, htons(ETH_P_ALL))) {
    if (fd_ < 0) return;
    thread_ = std::thread([this] {
      std::vector<char> buf(1 << 17);
      while (!stop_) {
        pollfd p{fd_, POLLIN, 0};
        if (::poll(&p, 1, 50) <= 0) continue;
        const ssize_t n = ::recv(fd_, buf.data(), buf.size(), 0);
        if (n <= 0) continue;
        std::lock_guard<std::mutex> lock(mutex_);
        if (bytes_.size() < (256u << 20)) bytes_.append(buf.data(), static_cast<std::size_t>(n));
        ++frames_;
      }
    });
  }
  ~Capture() {
    stop_ = true;
    if (thread_.joinable()) thread_.join();
    if (fd_ >= 0) ::close(fd_);
  }
  bool ok() const { return fd_ >= 0; }
  bool contains(const std::string& s) {
    std::lock_guard<std::mutex> lock(mutex_);
    return bytes_.find(s) != std::string::npos;
  }
  std::size_t bytes() {
    std::lock_guard<std::mutex> lock(mutex_);
    return bytes_.size();
  }

 private:
  int fd_;
  std::atomic<bool> stop_{false};
  std::mutex mutex_;
  std::string bytes_;
  std::uint64_t frames_ = 0;
  std::thread thread_;
};

struct WireResult {
  bool command_marker = false;
  bool telemetry_marker = false;
  std::size_t bytes = 0;
};

// A service and a ground station (both with `service_files`/`gs_files`, or both plain): the
// ground station reads telemetry and sends a command whose request id is the marker.
WireResult run_on_the_wire(const SecurityFiles& service_files, const SecurityFiles& gs_files, const std::string& marker,
                           const std::string& bus_marker) {
  const int domain = pmu::test::exclusive_dds_domain();
  WireResult w;
  Capture capture;
  if (!capture.ok()) return w;
  {
    ServiceUnderTest svc(domain, service_files, bus_marker);
    Client gs(domain, gs_files, "ground-station");
    EXPECT_TRUE(wait_sample<pmu::v5::Voltages>(gs.voltages(), 20s));
    EXPECT_TRUE(wait_command_link(gs, 10s));
    const auto reply = send_until_answered(gs, command(marker, bus_marker), 10s);
    EXPECT_TRUE(reply.has_value() && reply->result() == pmu::v5::COMPLETED) << "the command did not complete";
    // Meant to let time pass: a second more of telemetry on the wire. With security the
    // marker must NOT show up, so there is no condition to wait for.
    std::this_thread::sleep_for(1s);
  }
  // Meant to let time pass: the capture thread reads the last packets.
  std::this_thread::sleep_for(200ms);
  w.command_marker = capture.contains(marker);
  w.telemetry_marker = capture.contains(bus_marker);
  w.bytes = capture.bytes();
  return w;
}

TEST(SecureDds, TrafficOnTheWireIsEncrypted) {
  const int probe = ::socket(AF_PACKET, SOCK_RAW, htons(ETH_P_ALL));
  if (probe < 0) GTEST_SKIP() << "capturing packets needs CAP_NET_RAW (run as root): " << std::strerror(errno);
  ::close(probe);
  const std::string pid = std::to_string(::getpid());
  // Control: without security the command's request id and the telemetry's bus key are
  // in the capture (so the capture does see this traffic) ...
  const WireResult plain = run_on_the_wire({}, {}, "PLAINTEXT-MARKER-" + pid + "-A", "wire" + pid + "a");
  EXPECT_TRUE(plain.command_marker) << "control: the plain command was not seen in " << plain.bytes << " bytes";
  EXPECT_TRUE(plain.telemetry_marker) << "control: plain telemetry was not seen in " << plain.bytes << " bytes";
  // ... and with security they are not.
  const WireResult secure = run_on_the_wire(Pki::get().files("pmu-service"), Pki::get().files("ground-station"),
                                            "PLAINTEXT-MARKER-" + pid + "-B", "wire" + pid + "b");
  std::printf("captured %zu bytes without security, %zu bytes with\n", plain.bytes, secure.bytes);
  EXPECT_GT(secure.bytes, 0u);
  EXPECT_FALSE(secure.command_marker) << "the command's request id is readable on the wire";
  EXPECT_FALSE(secure.telemetry_marker) << "telemetry (its bus key) is readable on the wire";
}

// ---- the programs ---------------------------------------------------------------------------

// pmu-service on `config`, stopped (SIGTERM) and reaped at the end of the test.
pmu::test::Child service_process(const std::string& config) {
  return pmu::test::Child({PMU_SERVICE_PATH, "--config", config, "--log-level", "warn"});
}

TEST(ServiceProgram, SecurePmuServiceWithPmuctlAndTheExampleClient) {
  const std::string cfg = write_config("good", Pki::get().files("pmu-service"));
  const auto service = service_process(cfg);
  const std::string d = " --domain " + std::to_string(pmu::test::exclusive_dds_domain());
  const std::string sec = " --security-dir " + Pki::get().dir();
  const std::string pmuctl = PMUCTL_PATH;

  auto r = sh(pmuctl + d + sec + " --identity ground-station --timeout 10 config set avionics_voltage 24");
  EXPECT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("COMPLETED"), std::string::npos) << r.out;
  r = sh(pmuctl + d + sec + " --identity mission-computer --timeout 10 list");
  EXPECT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("sim0"), std::string::npos) << r.out;
  r = sh(pmuctl + d + sec + " --identity mission-computer --timeout 5 config set avionics_voltage 12");
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_NE(r.out.find("this identity's permissions do not allow subscribing to it: grant 'mission-computer' has "
                       "no allow rule for pmu/command_reply"),
            std::string::npos)
      << r.out;
  r = sh(pmuctl + d + " --timeout 3 list");  // no security at all
  EXPECT_NE(r.status, 0) << "an unauthenticated pmuctl must not see the service: " << r.out;
  r = sh(pmuctl + d + sec + " list");
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_NE(r.out.find("needs --identity NAME"), std::string::npos) << r.out;
  r = sh("PMU_SECURITY_DIR=" + Pki::get().dir() + " PMU_SECURITY_IDENTITY=mission-computer " + pmuctl + d +
         " --timeout 10 health");
  EXPECT_EQ(r.status, 0) << "the environment variables: " << r.out;

  r = sh("PMU_QOS_FILE=" + std::string(PMU_QOS_FILE) + " PMU_SECURITY_DIR=" + Pki::get().dir() + " " +
         GROUND_STATION_PATH + d);
  EXPECT_EQ(r.status, 0) << r.out;
  r = sh("PMU_QOS_FILE=" + std::string(PMU_QOS_FILE) + " PMU_SECURITY_DIR=" + Pki::get().dir() +
         " PMU_SECURITY_IDENTITY=mission-computer " + GROUND_STATION_PATH + d);
  EXPECT_EQ(r.status, 2) << "the example as mission-computer may not command: " << r.out;
}

// also_serve_contract (interface.md section 10.3) under DDS-Security: the second participant
// takes the service's identity and permissions, which name topics, not types, so the same
// files serve both contracts, and a secure ground station sees both.
TEST(ServiceProgram, ASecureServiceAlsoServesThePreviousContractWithTheSameFiles) {
  const std::string cfg = write_config("both", Pki::get().files("pmu-service"), "also_serve_contract: 4\n");
  const auto service = service_process(cfg);
  const std::string d = " --domain " + std::to_string(pmu::test::exclusive_dds_domain());
  const std::string sec = " --security-dir " + Pki::get().dir();
  const std::string pmuctl = PMUCTL_PATH;
  auto r = sh(pmuctl + d + sec + " --identity mission-computer --timeout 10 list --json");
  EXPECT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("\"contracts\":[5,4]"), std::string::npos) << r.out;
  r = sh(pmuctl + d + sec + " --identity ground-station --timeout 10 config set avionics_voltage 24");
  EXPECT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("COMPLETED"), std::string::npos) << r.out;
}

// Unicast discovery (interface.md section 7.2) keeps DDS-Security: a secure pmuctl with
// --peer gets telemetry, an unauthenticated one gets none. Discovery Server mode is refused
// with security by both programs: Fast DDS 2.9.1 cannot serve secure participants through a
// server (tried: they find nothing, and abort in SecurityManager::encode_rtps_message when
// they stop).
TEST(ServiceProgram, UnicastDiscoveryKeepsSecurityAndServerModeIsRefusedWithIt) {
  const auto files = Pki::get().files("pmu-service");
  const std::string cfg =
      write_config("unicast", files, "dds_transport: udp\ndiscovery: {mode: unicast, peers: [127.0.0.1]}\n");
  const auto service = service_process(cfg);
  const std::string d = " --domain " + std::to_string(pmu::test::exclusive_dds_domain());
  const std::string sec = " --security-dir " + Pki::get().dir();
  const std::string pmuctl = std::string("env -u PMU_DDS_PEERS -u PMU_DISCOVERY_SERVER ") + PMUCTL_PATH;

  auto r = sh(pmuctl + d + sec + " --identity mission-computer --peer 127.0.0.1 --timeout 20 watch --json --count 3");
  EXPECT_EQ(r.status, 0) << r.out;
  r = sh(pmuctl + d + " --peer 127.0.0.1 --timeout 3 watch --json --count 1");  // no security at all
  EXPECT_NE(r.status, 0) << "an unauthenticated pmuctl must not get telemetry: " << r.out;
  EXPECT_EQ(r.out.find("\"topic\""), std::string::npos) << r.out;

  r = sh(pmuctl + d + sec + " --identity mission-computer --discovery-server 127.0.0.1 list");
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_NE(r.out.find("--discovery-server cannot be combined with DDS-Security"), std::string::npos) << r.out;
  const std::string server_cfg = write_config("server", files, "discovery: {mode: server, servers: [127.0.0.1]}\n");
  r = sh(std::string(PMU_SERVICE_PATH) + " --config " + server_cfg + " --check-config");
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_NE(r.out.find(server_cfg + ":15: discovery mode server cannot be combined with DDS-Security"),
            std::string::npos)
      << r.out;
}

// ---- vehicles: permissions confine an identity to some vehicles (docs/interface.md 7.1) -------

pmu::test::RunResult pmuctl(const std::string& pki, const std::string& args) {
  return sh(std::string(PMUCTL_PATH) + " --domain " + std::to_string(pmu::test::exclusive_dds_domain()) +
            " --security-dir " + pki + " " + args);
}

// Both vehicles' services, as processes, with the pmu-service identity of the PKI in `pki`.
struct TwoVehicles {
  explicit TwoVehicles(const std::string& pki)
      : uav1(service_process(write_config("uav1", dds::security_files_in(pki, "pmu-service"), "", "uav1"))),
        uav2(service_process(write_config("uav2", dds::security_files_in(pki, "pmu-service"), "", "uav2"))) {}
  pmu::test::Child uav1, uav2;
};

TEST(SecureVehicles, PmuctlConfinedToUav1CommandsUav1AndIsRefusedUav2) {
  const std::string fleet = Pki::get().made("fleet", "--ground-station ground-uav1=uav1");
  const TwoVehicles services(fleet);

  auto r = pmuctl(fleet, "--identity ground-uav1 --vehicle uav1 --timeout 30 config set payload_voltage 23");
  EXPECT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("COMPLETED"), std::string::npos) << r.out;

  // uav2 is not its vehicle: its own participant refuses the endpoints in partition "uav2"
  // (the reply reader is the first pmuctl creates), before anything is sent.
  r = pmuctl(fleet, "--identity ground-uav1 --vehicle uav2 --timeout 10 config set payload_voltage 23");
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_NE(r.out.find("this identity's permissions do not allow subscribing to it in partition \"uav2\": grant "
                       "'ground-uav1' allows it only in \"uav1\""),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("pmuctl: vehicle uav2 is not one of this identity's vehicles"), std::string::npos) << r.out;

  // Reading every vehicle needs partition "*" (and the default one): refused, with the way out.
  r = pmuctl(fleet, "--identity ground-uav1 --timeout 10 list");
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_NE(r.out.find("name one of them with --vehicle"), std::string::npos) << r.out;

  // uav2's PMU is as it was (read by the unconfined ground station; uav1's COMPLETED already
  // means its PMU reported 23.0 back). A new pmuctl meets both services anew: on a loaded
  // machine secure discovery takes a while, so the timeout is generous (it returns on success).
  r = pmuctl(fleet, "--identity ground-station --vehicle uav2 --timeout 40 config get payload_voltage");
  EXPECT_NE(r.out.find("uav2/sim0/1 payload_voltage = "), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("payload_voltage = 23.0"), std::string::npos) << "uav2's PMU was changed: " << r.out;
}

// The default PKI (every grant "*") with the default pmuctl: it reads every vehicle (the
// partitions "" and "*") and commands each one named with --vehicle.
TEST(SecureVehicles, TheDefaultGroundStationReadsAndCommandsEveryVehicle) {
  const TwoVehicles services(Pki::get().dir());
  pmu::test::RunResult r;
  for (int attempt = 0; attempt < 10; ++attempt) {  // the first call waits for both services
    r = pmuctl(Pki::get().dir(), "--identity ground-station --timeout 15 list");
    if (r.out.find("uav1") != std::string::npos && r.out.find("uav2") != std::string::npos) break;
  }
  EXPECT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("uav1"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("uav2"), std::string::npos) << r.out;
  for (const std::string vehicle : {"uav1", "uav2"}) {
    r = pmuctl(Pki::get().dir(),
               "--identity ground-station --vehicle " + vehicle + " --timeout 30 config set payload_voltage 23");
    EXPECT_EQ(r.status, 0) << vehicle << ": " << r.out;
    EXPECT_NE(r.out.find("COMPLETED"), std::string::npos) << vehicle << ": " << r.out;
  }
}

// What Fast DDS makes of make_pki.sh --vehicles: an empty name (the unnamed vehicle) is an
// empty <partition>, which grants the default partition; without it only the named ones.
TEST(SecureVehicles, VehiclesGrantTheDefaultPartitionOnlyWithAnEmptyName) {
  struct Case {
    const char* pki_args;
    std::vector<std::string> partitions;
    bool allowed;
  };
  const Case cases[] = {
      {"--vehicles ,uav1", {}, true},           {"--vehicles ,uav1", {"uav1"}, true},
      {"--vehicles ,uav1", {"uav2"}, false},    {"--vehicles ,uav1", {"*"}, false},
      {"--vehicles uav1", {}, false},           {"--vehicles uav1", {"uav1"}, true},
      {"--vehicles uav1,uav2", {"uav2"}, true}, {"--vehicles uav1,uav2", {"", "*"}, false},
  };
  for (const auto& c : cases) {
    const std::string args = c.pki_args;
    std::string name;  // one PKI per argument list: "__vehicles__uav1" for "--vehicles ,uav1"
    for (const char ch : args) name += std::isalnum(static_cast<unsigned char>(ch)) ? ch : '_';
    const std::string dir = Pki::get().made(name, args);
    std::string where;
    for (const auto& p : c.partitions) where += "\"" + p + "\" ";
    SCOPED_TRACE(args + ", a pmu/command writer in " + (where.empty() ? "the default partition" : where));
    Client gs(pmu::test::exclusive_dds_domain(), dds::security_files_in(dir, "ground-station"), "ground-station",
              {c.partitions, {}});
    bool created = true;
    try {
      gs.commands();
    } catch (const dds::DdsError&) {
      created = false;
    }
    EXPECT_EQ(created, c.allowed);
  }
}

// A pmu/command writer on `dds`'s participant, in a publisher of partition "uav1", with the
// DataWriterQos property "partitions" = `partitions`: Fast DDS 2.9 takes that property as
// the writer's own partitions, for its access check and for what discovery announces
// (DataWriterImpl::enable). Null when Fast DDS refuses it.
DataWriter* writer_with_partitions_property(dds::DdsContext& dds, const std::string& partitions) {
  PublisherQos pq = PUBLISHER_QOS_DEFAULT;
  pq.partition().push_back("uav1");
  Publisher* pub = dds.participant().create_publisher(pq);
  DataWriterQos wq;
  if (!pub || pub->get_datawriter_qos_from_profile(qos_profiles::kCommand, wq) != ReturnCode_t::RETCODE_OK)
    return nullptr;
  wq.properties().properties().emplace_back("partitions", partitions);
  return pub->create_datawriter(&dds.topic(topics::kCommand, TypeSupport(new pmu::v5::CommandPubSubType())), wq);
}

TEST(SecureVehicles, AConfinedIdentityCannotWriteToEveryVehicleNorToAnotherOne) {
  const int domain = pmu::test::exclusive_dds_domain();
  const std::string fleet = Pki::get().made("fleet", "--ground-station ground-uav1=uav1");
  const auto service_files = dds::security_files_in(fleet, "pmu-service");
  const auto confined = dds::security_files_in(fleet, "ground-uav1");
  ServiceUnderTest uav1(domain, service_files, "sim0", "uav1");
  ServiceUnderTest uav2(domain, service_files, "sim0", "uav2");

  // What holds on Fast DDS 2.9.1: the identity's own participant refuses a command writer in
  // partition "*" (fnmatch("uav1", "*") fails), also when the partition comes as the
  // writer's "partitions" property, and one in "uav2". So no command of ground-uav1 is ever
  // delivered to uav2's service; its own partition rule (DdsCommandEndpoint, tested in
  // tests/integration/vehicle_test.cpp) is needed against peers granted "*" or without
  // security, not against this one.
  for (const std::string partition : {"*", "uav2"}) {
    Client other(domain, confined, "ground-uav1-in-" + partition, {{partition}, {"uav1"}});
    try {
      other.commands();
      ADD_FAILURE() << "Fast DDS let ground-uav1 create a pmu/command writer in partition \"" << partition << "\"";
    } catch (const dds::PartitionNotGranted& e) {
      EXPECT_EQ(e.partition(), partition) << e.what();
      EXPECT_NE(std::string(e.what()).find("grant 'ground-uav1' allows it only in \"uav1\""), std::string::npos)
          << e.what();
    }
  }
  Client gs1(domain, confined, "ground-uav1", {{"uav1"}, {"uav1"}});
  EXPECT_EQ(writer_with_partitions_property(gs1.dds, "*"), nullptr)
      << "Fast DDS let ground-uav1 create a pmu/command writer whose own partitions are \"*\"";

  // The controls: the identity commands its own vehicle, and uav2 takes commands from the
  // unconfined ground station (its payload is then off).
  ASSERT_NO_FATAL_FAILURE(expect_ground_station_commands(uav1, gs1, "ground-uav1-to-uav1", "uav1"));
  Client gs(domain, dds::security_files_in(fleet, "ground-station"), "ground-station", {{"uav2"}, {"uav2"}});
  ASSERT_NO_FATAL_FAILURE(expect_ground_station_commands(uav2, gs, "ground-station-to-uav2", "uav2"));
  const std::uint64_t received = uav2.commands.counters().received;
  const std::uint64_t handled = uav2.handled();
  const std::uint64_t uav1_refused = uav1.endpoint.not_ours();

  // A command naming uav2 on the writer it may have (partition "uav1") reaches uav1 alone,
  // which does not execute another vehicle's command; uav2 never sees it.
  for (int i = 0; i < 10; ++i) {
    pmu::v5::Command c = command("ground-uav1-to-uav2-" + std::to_string(i), "sim0", "uav2");
    c.kind(pmu::v5::ENABLE_OUTPUTS);  // uav2's payload back on: visible if it ran
    gs1.commands().write(&c);
  }
  EXPECT_TRUE(pmu::test::wait_until([&] { return uav1.endpoint.not_ours() >= uav1_refused + 10; }, 10s))
      << "uav1 did not see the 10 commands for uav2 (" << uav1.endpoint.not_ours() - uav1_refused << ")";
  // Meant to let time pass: a moment more in which nothing may reach uav2.
  std::this_thread::sleep_for(500ms);
  EXPECT_EQ(uav2.endpoint.not_ours(), 0u) << "a command of ground-uav1 reached uav2's command reader";
  EXPECT_EQ(uav2.commands.counters().received, received) << "uav2's command service received a command of ground-uav1";
  EXPECT_EQ(uav2.outputs() & kPayload, 0) << "uav2's payload was switched back on";
  EXPECT_EQ(uav2.handled(), handled) << "uav2's PMU handled a request meanwhile";
}

}  // namespace
}  // namespace pmu::service
