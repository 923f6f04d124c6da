// Discovery and interfaces over real Fast DDS (interface.md section 7.2): unicast peers with
// multicast off, Fast DDS's Discovery Server (the `fastdds discovery` program, started here),
// the interface allowlist, and pmu-service + pmuctl with those settings.
//
// In-process participants use UDP only and this program turns Fast DDS's intraprocess
// delivery off (main below), so everything between them crosses the loopback interface as
// between two hosts. Each test runs in its own process on a DDS domain of its own
// (pmu::test::exclusive_dds_domain) and, for the server, on a free UDP port.
#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <ifaddrs.h>
#include <netinet/in.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fastdds/dds/core/status/PublicationMatchedStatus.hpp>
#include <fastdds/dds/core/status/SubscriptionMatchedStatus.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "pmu/dds_settings/network_settings.hpp"
#include "pmu/dds/dds_context.hpp"
#include "pmu/idl/commandPubSubTypes.h"
#include "pmu/idl/telemetryPubSubTypes.h"
#include "pmu/idl/topics.hpp"
#include "support/domain.hpp"
#include "support/json_lines.hpp"
#include "support/process.hpp"
#include "support/udp_ports.hpp"
#include "support/wait.hpp"

namespace pmu::dds {
namespace {

using namespace eprosima::fastdds::dds;
using namespace std::chrono_literals;

constexpr const char* kDiscoveryServer = "/usr/bin/fast-discovery-server";  // fastdds-tools

ResolvedNetwork unicast_to_loopback() {
  ResolvedNetwork n;
  n.mode = DiscoveryMode::Unicast;
  n.peers = {{"127.0.0.1", 0}};
  return n;
}

ResolvedNetwork client_of(std::uint16_t port) {
  ResolvedNetwork n;
  n.mode = DiscoveryMode::Server;
  n.servers = {ResolvedServer{{{"127.0.0.1", port}}}};
  return n;
}

// One participant writing pmu/voltages (a pmu-service stand-in) or reading it (a pmuctl
// stand-in), with the contract's telemetry profile.
struct Side {
  Side(const std::string& name, const ResolvedNetwork& network, Transport transport = Transport::UdpOnly)
      : dds(pmu::test::exclusive_dds_domain(), "", name, {}, transport, network),
        topic(dds.topic(topics::kVoltages, TypeSupport(new pmu::v5::VoltagesPubSubType()))) {}
  DataWriter& writer() { return w ? *w : *(w = &dds.writer(topic, qos_profiles::kTelemetry)); }
  DataReader& reader() { return r ? *r : *(r = &dds.reader(topic, qos_profiles::kTelemetry)); }
  bool matched() {
    if (w) {
      PublicationMatchedStatus s;
      w->get_publication_matched_status(s);
      return s.current_count > 0;
    }
    SubscriptionMatchedStatus s;
    r->get_subscription_matched_status(s);
    return s.current_count > 0;
  }
  DdsContext dds;
  Topic& topic;
  DataWriter* w = nullptr;
  DataReader* r = nullptr;
};

// Writes a sample every 50 ms until the reader has one (best effort: a sample written
// before matching is lost, so keep writing).
bool exchange(Side& pub, Side& sub, std::chrono::seconds timeout) {
  pmu::v5::Voltages v;
  v.bus("sim0");
  v.address(1);
  v.avionics(12.5f);
  return pmu::test::wait_until(
      [&] {
        pub.writer().write(&v);
        pmu::v5::Voltages got;
        SampleInfo info;
        while (sub.reader().take_next_sample(&got, &info) == ReturnCode_t::RETCODE_OK)
          if (info.valid_data && got.avionics() == 12.5f) return true;
        return false;
      },
      timeout, 50ms);
}

// ---- services whose endpoints are still coming -------------------------------------------------

// A client learns that a pmu-service is there from its participant announcement, before that
// service's writers are discovered (seconds later over a slow link): pmuctl's state verbs
// wait for such a service. Participants of other names are not waited for.
TEST(RemoteParticipants, AServiceIsComingUntilItsWriterOfTheTopicIsDiscovered) {
  Side client("pmuctl", unicast_to_loopback());
  Side service(kServiceParticipantName, unicast_to_loopback());
  Side other("ground-station", unicast_to_loopback());
  client.reader();
  other.writer();  // a writer of the topic, of a participant that is not a service
  const auto coming = [&] {
    return client.dds.remote_writers().participants_without_writer(kServiceParticipantName, topics::kVoltages);
  };
  ASSERT_TRUE(pmu::test::wait_until([&] { return coming() == 1; }, 20s))
      << "the service's participant was not seen as coming: " << coming();
  // The other participant's writer is discovered and matched; it never counts as a service.
  ASSERT_TRUE(pmu::test::wait_until([&] { return client.matched(); }, 20s));
  EXPECT_EQ(coming(), 1u);
  service.writer();
  EXPECT_TRUE(pmu::test::wait_until([&] { return coming() == 0; }, 20s))
      << "the service's writer was discovered but it still counts as coming: " << coming();
}

// ---- unicast peers -------------------------------------------------------------------------

TEST(UnicastDiscovery, PeersOnLoopbackFindEachOtherWithNoMulticastSocket) {
  Side service("unicast-publisher", unicast_to_loopback());
  Side client("unicast-subscriber", unicast_to_loopback());
  service.writer();
  client.reader();
  ASSERT_TRUE(exchange(service, client, 20s)) << "no sample over unicast discovery";
  // Both live and matched, and neither has the multicast discovery port open.
  EXPECT_TRUE(pmu::test::dds_discovery_port_free(pmu::test::exclusive_dds_domain()));
}

TEST(UnicastDiscovery, WithoutAPeerAtTheirPortsTheyFindNobody) {
  // Peers at a port where no participant listens: nothing reaches the well-known ports, and
  // with multicast off nothing else would find them.
  ResolvedNetwork nowhere;
  nowhere.mode = DiscoveryMode::Unicast;
  nowhere.peers = {{"127.0.0.1", 9}};  // discard
  Side service("unicast-lonely-publisher", nowhere);
  Side client("unicast-lonely-subscriber", nowhere);
  service.writer();
  client.reader();
  std::this_thread::sleep_for(4s);  // more than Fast DDS's initial announcements (5 x 100 ms) and a period (3 s)
  EXPECT_FALSE(service.matched());
  EXPECT_FALSE(client.matched());
}

// ---- Discovery Server ----------------------------------------------------------------------

// `fastdds discovery -i ID -l 127.0.0.1 -p PORT` runs this program: the fastdds command is a
// Python wrapper that starts it as a child, so a signal to the wrapper would leave the
// server running. Stopped with SIGINT, its clean shutdown (SIGTERM would kill it). With the
// shipped settings (deploy/discovery-server.xml), as pmu-discovery-server.service runs it.
struct Server {
  Server(int id, std::uint16_t port)
      : child({kDiscoveryServer, "-i", std::to_string(id), "-l", "127.0.0.1", "-p", std::to_string(port), "-x",
               PMU_DISCOVERY_SERVER_XML},
              options()) {}
  ~Server() {
    child.signal(SIGINT);
    child.wait_for(5s);
  }
  static pmu::test::ChildOptions options() {
    pmu::test::ChildOptions o;
    o.stdout_path = "/dev/null";
    return o;
  }
  pmu::test::Child child;
};

TEST(DiscoveryServer, ClientsFindEachOtherOnlyThroughTheServerWithTheIdOfTheirPosition) {
  if (::access(kDiscoveryServer, X_OK) != 0)
    GTEST_SKIP() << kDiscoveryServer << " is missing: install Debian's fastdds-tools (scripts/setup.sh does)";
  const std::uint16_t port = pmu::test::free_udp_port();
  Side service("ds-client-publisher", client_of(port));
  Side client("ds-client-subscriber", client_of(port));
  service.writer();
  client.reader();

  // No server: clients send discovery only to it, so they never meet.
  std::this_thread::sleep_for(4s);
  EXPECT_FALSE(service.matched()) << "matched without the server";
  EXPECT_FALSE(client.matched()) << "matched without the server";

  {
    // A server with id 1 where the list's first (id 0) is expected: its GUID prefix is not
    // the one the clients look for, so it serves them nothing.
    Server wrong(1, port);
    std::this_thread::sleep_for(4s);
    EXPECT_FALSE(client.matched()) << "matched through a server of another id";
  }

  Server server(0, port);
  ASSERT_TRUE(exchange(service, client, 20s)) << "no sample through the Discovery Server";
  EXPECT_TRUE(pmu::test::dds_discovery_port_free(pmu::test::exclusive_dds_domain()));
}

std::int32_t matched_readers(DataWriter& w) {
  PublicationMatchedStatus s;
  w.get_publication_matched_status(s);
  return s.current_count;
}

// A long-lived client that serves one job after another (`pmuctl agent`) ends each job's
// readers. Fast DDS's server, processing one reader's disposal, drops the participant's
// other announcements its clients have not all received, so of two readers deleted at once
// one stayed matched at the other clients for good (and a reliable writer heartbeats it for
// ever). Parked instead (DdsContext::reuse_endpoints), both are unmatched after every job,
// and the next job gets them back empty.
TEST(DiscoveryServer, ALongLivedClientsEndedReadersAreUnmatchedAtTheOtherClientsAfterEveryJob) {
  if (::access(kDiscoveryServer, X_OK) != 0)
    GTEST_SKIP() << kDiscoveryServer << " is missing: install Debian's fastdds-tools (scripts/setup.sh does)";
  const std::uint16_t port = pmu::test::free_udp_port();
  Server server(0, port);
  DdsContext service(pmu::test::exclusive_dds_domain(), "", "ds-service", {}, Transport::UdpOnly, client_of(port));
  Topic& voltages_topic = service.topic(topics::kVoltages, TypeSupport(new pmu::v5::VoltagesPubSubType()));
  Topic& currents_topic = service.topic(topics::kCurrents, TypeSupport(new pmu::v5::CurrentsPubSubType()));
  DataWriter& voltages = service.writer(voltages_topic, qos_profiles::kTelemetry);
  DataWriter& currents = service.writer(currents_topic, qos_profiles::kTelemetry);

  DdsContext agent(pmu::test::exclusive_dds_domain(), "", "ds-agent", {}, Transport::UdpOnly, client_of(port));
  agent.reuse_endpoints({qos_profiles::kCommand});
  Topic& v_topic = agent.topic(topics::kVoltages, TypeSupport(new pmu::v5::VoltagesPubSubType()));
  Topic& c_topic = agent.topic(topics::kCurrents, TypeSupport(new pmu::v5::CurrentsPubSubType()));
  DataReader* first_job_reader = nullptr;
  for (int job = 1; job <= 4; ++job) {
    const auto mark = agent.endpoint_mark();
    DataReader& v = agent.reader(v_topic, qos_profiles::kTelemetry);
    (void)agent.reader(c_topic, qos_profiles::kTelemetry);
    if (job == 1) first_job_reader = &v;
    if (job > 1) {
      EXPECT_EQ(&v, first_job_reader) << "job " << job << " made a new reader instead of taking up the parked one";
      EXPECT_EQ(v.get_unread_count(), 0u) << "job " << job << "'s reader came back with the last job's samples";
    }
    ASSERT_TRUE(pmu::test::wait_until([&] { return matched_readers(voltages) == 1 && matched_readers(currents) == 1; },
                                      20s, 20ms))
        << "job " << job << ": the service's writers matched " << matched_readers(voltages) << " and "
        << matched_readers(currents) << " readers";
    // A sample the job leaves unread.
    pmu::v5::Voltages sample;
    sample.bus("sim0");
    sample.address(1);
    ASSERT_TRUE(pmu::test::wait_until(
        [&] {
          voltages.write(&sample);
          return v.get_unread_count() > 0;
        },
        10s, 50ms));

    agent.delete_endpoints_since(mark);
    EXPECT_TRUE(pmu::test::wait_until([&] { return matched_readers(voltages) == 0 && matched_readers(currents) == 0; },
                                      20s, 20ms))
        << "job " << job << " ended, and the service's writers still match " << matched_readers(voltages) << " and "
        << matched_readers(currents) << " of its readers";
  }

  // A command reply reader stays matched between jobs (nothing flows to it unasked), and the
  // next job in the same partitions takes it up without waiting for a match.
  DataWriter& replies = service.writer(
      service.topic(topics::kCommandReply, TypeSupport(new pmu::v5::CommandReplyPubSubType())), qos_profiles::kCommand);
  Topic& r_topic = agent.topic(topics::kCommandReply, TypeSupport(new pmu::v5::CommandReplyPubSubType()));
  auto mark = agent.endpoint_mark();
  DataReader* reply_reader = &agent.reader(r_topic, qos_profiles::kCommand);
  ASSERT_TRUE(pmu::test::wait_until([&] { return matched_readers(replies) == 1; }, 20s, 20ms));
  agent.delete_endpoints_since(mark);
  std::this_thread::sleep_for(2s);
  EXPECT_EQ(matched_readers(replies), 1) << "an idle command reply reader was unmatched";
  mark = agent.endpoint_mark();
  EXPECT_EQ(&agent.reader(r_topic, qos_profiles::kCommand), reply_reader);
  SubscriptionMatchedStatus s;
  reply_reader->get_subscription_matched_status(s);
  EXPECT_EQ(s.current_count, 1) << "the next job's reply reader is not matched at once";
  agent.delete_endpoints_since(mark);
}

// One job of a long-lived participant that reuses endpoints, in `vehicle`'s partitions: the
// command reply reader it takes up or makes, parked again when the job ends.
DataReader* reply_reader_of_a_job(DdsContext& agent, Topic& topic, const std::string& vehicle) {
  EXPECT_TRUE(agent.set_partitions({{vehicle}, {vehicle}}));
  const auto mark = agent.endpoint_mark();
  DataReader* r = &agent.reader(topic, qos_profiles::kCommand);
  agent.delete_endpoints_since(mark);
  return r;
}

// A ground station's long-lived participant commands one vehicle after another. The command
// endpoints it left matched in one vehicle's partitions stay there while another vehicle is
// commanded: moved, each would be announced again across the link, there and back, and the
// first vehicle's next command would wait for that discovery once more.
TEST(EndpointReuse, ACommandEndpointLeftMatchedForOneVehicleStaysThereWhileAnotherIsCommanded) {
  const auto domain = pmu::test::exclusive_dds_domain();
  const ResolvedNetwork network = unicast_to_loopback();
  DdsContext uav1(domain, "", "reuse-uav1", {}, Transport::UdpOnly, network, Partitions{{"uav1"}, {"uav1"}});
  DdsContext uav2(domain, "", "reuse-uav2", {}, Transport::UdpOnly, network, Partitions{{"uav2"}, {"uav2"}});
  auto replies_of = [](DdsContext& dds) -> DataWriter& {
    return dds.writer(dds.topic(topics::kCommandReply, TypeSupport(new pmu::v5::CommandReplyPubSubType())),
                      qos_profiles::kCommand);
  };
  DataWriter& replies1 = replies_of(uav1);
  DataWriter& replies2 = replies_of(uav2);

  DdsContext agent(domain, "", "reuse-agent", {}, Transport::UdpOnly, network);
  agent.reuse_endpoints({qos_profiles::kCommand});
  Topic& topic = agent.topic(topics::kCommandReply, TypeSupport(new pmu::v5::CommandReplyPubSubType()));
  auto job = [&](const std::string& vehicle) { return reply_reader_of_a_job(agent, topic, vehicle); };
  DataReader* for_uav1 = job("uav1");
  ASSERT_TRUE(pmu::test::wait_until([&] { return matched_readers(replies1) == 1; }, 20s, 20ms));
  DataReader* for_uav2 = job("uav2");
  EXPECT_NE(for_uav2, for_uav1) << "uav1's reply reader was moved to uav2";
  ASSERT_TRUE(pmu::test::wait_until([&] { return matched_readers(replies2) == 1; }, 20s, 20ms));
  std::this_thread::sleep_for(1s);  // a move, had there been one, would have unmatched it by now
  EXPECT_EQ(matched_readers(replies1), 1) << "uav1's reply reader was unmatched while uav2 was commanded";
  EXPECT_EQ(job("uav1"), for_uav1) << "uav1's next command did not take up its own reader";
  EXPECT_EQ(job("uav2"), for_uav2) << "uav2's next command did not take up its own reader";
}

// Left matched, they are bounded: beyond kMostIdleMatched vehicles, the least recently
// used one moves to the next vehicle.
TEST(EndpointReuse, BeyondTheMostLeftMatchedTheLeastRecentlyUsedMoves) {
  DdsContext agent(pmu::test::exclusive_dds_domain(), "", "reuse-bound", {}, Transport::UdpOnly, unicast_to_loopback());
  agent.reuse_endpoints({qos_profiles::kCommand});
  Topic& topic = agent.topic(topics::kCommandReply, TypeSupport(new pmu::v5::CommandReplyPubSubType()));
  auto job = [&](const std::string& vehicle) { return reply_reader_of_a_job(agent, topic, vehicle); };
  std::vector<DataReader*> made;
  for (std::size_t i = 0; i < DdsContext::kMostIdleMatched; ++i) made.push_back(job("uav" + std::to_string(i)));
  EXPECT_EQ(std::set<DataReader*>(made.begin(), made.end()).size(), made.size()) << "a vehicle's reader was moved";
  EXPECT_EQ(job("uav0"), made[0]);  // uav0 is now the most recently used, uav1 the least
  EXPECT_EQ(job("one-more"), made[1]) << "not the least recently used one was moved";
}

// ---- the interface allowlist ---------------------------------------------------------------

// The local IPv4 addresses of this process's UDP sockets, from /proc: its socket inodes
// (/proc/self/fd) looked up in /proc/net/udp ("0100007F:1F90" is 127.0.0.1:8080).
std::set<std::string> udp_addresses_of_this_process() {
  std::set<std::string> inodes;
  for (const auto& e : std::filesystem::directory_iterator("/proc/self/fd")) {
    std::error_code ec;
    const std::string target = std::filesystem::read_symlink(e.path(), ec).string();
    if (!ec && target.rfind("socket:[", 0) == 0) inodes.insert(target.substr(8, target.size() - 9));
  }
  std::set<std::string> addresses;
  std::ifstream udp("/proc/net/udp");
  std::string line;
  std::getline(udp, line);  // header
  while (std::getline(udp, line)) {
    std::istringstream f(line);
    std::string slot, local, remote, state, queues, timer, retransmits, uid, timeout, inode;
    f >> slot >> local >> remote >> state >> queues >> timer >> retransmits >> uid >> timeout >> inode;
    if (!inodes.count(inode)) continue;
    in_addr a{};
    // The kernel prints the address as the number in memory: read back, it is network order.
    a.s_addr = static_cast<in_addr_t>(std::stoul(local.substr(0, 8), nullptr, 16));
    addresses.insert(::inet_ntoa(a));
  }
  return addresses;
}

bool has_non_loopback_ipv4() {
  for (const auto& a : system_lookup().local_addresses())
    if (a.address.rfind("127.", 0) != 0) return true;
  return false;
}

TEST(InterfaceAllowlist, ParticipantsBindOnlyTheAllowedAddresses) {
  if (!has_non_loopback_ipv4()) GTEST_SKIP() << "this machine has only loopback: nothing to leave out";
  ASSERT_TRUE(udp_addresses_of_this_process().empty()) << "a UDP socket before any participant";
  // Restricted to loopback through the same resolve_network the programs use; found by
  // unicast peers (multicast on lo is not guaranteed).
  NetworkConfig config;
  config.mode = DiscoveryMode::Unicast;
  config.peers = {Address{"127.0.0.1", "127.0.0.1", 0, "test"}};
  config.interfaces = {Address{"lo", "lo", 0, "test"}};
  const ResolvedNetwork loopback_only = resolve_network(config, system_lookup());
  ASSERT_EQ(loopback_only.interface_addresses, std::vector<std::string>{"127.0.0.1"});
  // Fast DDS's default transports (shared memory and UDP, pmuctl's): with an allowlist
  // its builtin UDP transport, which has none, must not be there as well.
  {
    Side reader("allowlist-reader", loopback_only, Transport::Default);
    reader.reader();
    Side writer("allowlist-writer", loopback_only, Transport::Default);
    writer.writer();
    ASSERT_TRUE(exchange(writer, reader, 20s)) << "no sample between two loopback-only participants";
    // Every UDP socket, for discovery, data and sending, on loopback: none on 0.0.0.0 or
    // on this machine's other addresses.
    EXPECT_EQ(udp_addresses_of_this_process(), std::set<std::string>{"127.0.0.1"});
  }
  // UDP only: the same.
  {
    Side reader("allowlist-udp-reader", loopback_only);
    reader.reader();
    Side writer("allowlist-udp-writer", loopback_only);
    writer.writer();
    ASSERT_TRUE(exchange(writer, reader, 20s)) << "no sample between two loopback-only participants over UDP";
    EXPECT_EQ(udp_addresses_of_this_process(), std::set<std::string>{"127.0.0.1"});
  }
  // The same participant without an allowlist listens on every address (what the
  // allowlist kept it from doing above).
  Side unrestricted("allowlist-unrestricted", unicast_to_loopback());
  unrestricted.writer();
  const auto all = udp_addresses_of_this_process();
  EXPECT_TRUE(std::any_of(all.begin(), all.end(), [](const std::string& a) { return a.rfind("127.", 0) != 0; }))
      << "expected sockets beyond loopback without an allowlist";
}

// ---- pmu-service and pmuctl ----------------------------------------------------------------

// A config file for `pmu-service --bus sim` (which replaces its buses) with these lines.
struct ConfigFile {
  explicit ConfigFile(const std::string& lines) {
    char name[] = "/tmp/pmu-discovery-XXXXXX.yaml";
    const int fd = ::mkstemps(name, 5);
    path = name;
    const std::string yaml =
        lines + "buses:\n  - interface: sim\n    devices:\n      - address: 1\n        period: 0.5\n";
    if (fd < 0 || ::write(fd, yaml.data(), yaml.size()) != static_cast<ssize_t>(yaml.size())) ADD_FAILURE() << path;
    ::close(fd);
  }
  ~ConfigFile() { ::unlink(path.c_str()); }
  std::string path;
};

// `ENV pmuctl --domain D OPTIONS watch --json --count 5`: five telemetry lines of sim0/1.
void expect_watch(const std::string& env, const std::string& options, const std::string& domain) {
  const auto r = pmu::test::run_capture("env -u PMU_DDS_PEERS -u PMU_DISCOVERY_SERVER -u PMU_DDS_INTERFACES " + env +
                                        " " + PMUCTL_PATH + " --domain " + domain + " " + options +
                                        " watch --json --count 5 --timeout 30");
  ASSERT_EQ(r.status, 0) << r.out;
  std::size_t lines = 0;
  for (const auto& j : pmu::test::json_lines(r.out)) {
    ASSERT_FALSE(j.is_discarded()) << r.out;
    EXPECT_EQ(j["bus"], "sim0");
    EXPECT_EQ(j["address"], 1);
    ++lines;
  }
  EXPECT_EQ(lines, 5u) << r.out;
}

TEST(DiscoveryEndToEnd, ServiceWithUnicastPeersFeedsPmuctlWithPeer) {
  const std::string domain = std::to_string(pmu::test::exclusive_dds_domain());
  ConfigFile config("domain: " + domain + "\ndds_transport: udp\ndiscovery: {mode: unicast, peers: [127.0.0.1]}\n");
  pmu::test::ChildOptions o;
  o.stderr_path = config.path + ".log";
  pmu::test::Child service({PMU_SERVICE_PATH, "--config", config.path, "--bus", "sim"}, o);
  expect_watch("", "--peer 127.0.0.1", domain);
  EXPECT_TRUE(pmu::test::dds_discovery_port_free(std::stoi(domain)))
      << "pmu-service or pmuctl opened the multicast port";
  service.stop(5s);
  std::ifstream log(o.stderr_path);
  const std::string text((std::istreambuf_iterator<char>(log)), std::istreambuf_iterator<char>());
  ::unlink(o.stderr_path.c_str());
  EXPECT_NE(text.find("DDS: unicast discovery to 127.0.0.1"), std::string::npos) << text;
}

TEST(DiscoveryEndToEnd, ServiceAndPmuctlAsClientsOfADiscoveryServer) {
  if (::access(kDiscoveryServer, X_OK) != 0)
    GTEST_SKIP() << kDiscoveryServer << " is missing: install Debian's fastdds-tools (scripts/setup.sh does)";
  const std::string domain = std::to_string(pmu::test::exclusive_dds_domain());
  const std::string port = std::to_string(pmu::test::free_udp_port());
  Server server(0, static_cast<std::uint16_t>(std::stoi(port)));
  ConfigFile config("domain: " + domain +
                    "\ndds_transport: udp\ndiscovery:\n  mode: server\n  servers: [\"127.0.0.1:" + port + "\"]\n");
  pmu::test::Child service({PMU_SERVICE_PATH, "--config", config.path, "--bus", "sim", "--log-level", "warn"});
  // The variable, as an operator's shell profile would set it.
  expect_watch("PMU_DISCOVERY_SERVER=127.0.0.1:" + port, "", domain);
  EXPECT_TRUE(service.running());
}

// A Discovery Server on each host, each host's participants clients of their own and the
// ground station a client of all: the service names only server 1 (an empty first entry),
// as pmuctl does.
TEST(DiscoveryEndToEnd, AClientOfTheServerWithId1Alone) {
  if (::access(kDiscoveryServer, X_OK) != 0)
    GTEST_SKIP() << kDiscoveryServer << " is missing: install Debian's fastdds-tools (scripts/setup.sh does)";
  const std::string domain = std::to_string(pmu::test::exclusive_dds_domain());
  const std::string port = std::to_string(pmu::test::free_udp_port());
  Server server(1, static_cast<std::uint16_t>(std::stoi(port)));
  ConfigFile config("domain: " + domain +
                    "\ndds_transport: udp\ndiscovery:\n  mode: server\n  servers: [\"\", \"127.0.0.1:" + port +
                    "\"]\n");
  pmu::test::Child service({PMU_SERVICE_PATH, "--config", config.path, "--bus", "sim", "--log-level", "warn"});
  expect_watch("", "--discovery-server ,127.0.0.1:" + port, domain);
  EXPECT_TRUE(service.running());
}

TEST(DiscoveryEndToEnd, PmuctlOptionsWinOverTheEnvironment) {
  // A bad PMU_DDS_PEERS is not even read when --discovery-server is given, nor a bad
  // PMU_DDS_INTERFACES with --interface: pmuctl gets as far as looking for the service.
  const std::string domain = std::to_string(pmu::test::exclusive_dds_domain());
  const auto r = pmu::test::run_capture("env PMU_DDS_PEERS=bad_host PMU_DDS_INTERFACES=bad/if " +
                                        std::string(PMUCTL_PATH) + " --domain " + domain +
                                        " --discovery-server 127.0.0.1:1 --interface lo --timeout 0.5 list "
                                        "2>&1 >/dev/null");
  EXPECT_NE(r.status, 0);
  EXPECT_EQ(r.out, "pmuctl: no pmu-service on domain " + domain + "\n");
}

}  // namespace
}  // namespace pmu::dds
