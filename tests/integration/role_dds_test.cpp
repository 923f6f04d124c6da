// DdsRoleEndpoint (service/endpoints, interface.md 1.10) between participants on a domain of
// the test's own: one instance's heartbeat reaches the other as the plain report with its
// arrival time, never its own; samples of another vehicle or with enumerators outside the IDL
// are counted and not delivered; a move addressed to the instance is asked of the holder once,
// answered, and a resend answered alike; moves for the peer, expired ones and ones from a
// writer in every partition are not.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <fastdds/dds/core/status/PublicationMatchedStatus.hpp>
#include <fastdds/dds/core/status/SubscriptionMatchedStatus.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <cstdio>
#include <cstdlib>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "pmu/dds/dds_context.hpp"
#include "pmu/dds_settings/vehicle.hpp"
#include "pmu/endpoints/dds_role.hpp"
#include "pmu/idl/role.h"
#include "pmu/idl/rolePubSubTypes.h"
#include "pmu/idl/topics.hpp"
#include "support/domain.hpp"
#include "support/wait.hpp"

namespace {

using namespace eprosima::fastdds::dds;
using namespace std::chrono_literals;
using pmu::redundancy::BusState;
using pmu::redundancy::PeerAlarm;
using pmu::redundancy::Role;
using pmu::redundancy::RoleReport;
using pmu::service::DdsRoleEndpoint;

const std::string kVehicle = "uav7";

pmu::dds::Partitions vehicle_partitions(const std::string& vehicle) {
  return {pmu::dds::vehicle_partitions(vehicle), pmu::dds::vehicle_partitions(vehicle)};
}

std::unique_ptr<pmu::dds::DdsContext> participant(const std::string& name, const pmu::dds::Partitions& partitions) {
  return std::make_unique<pmu::dds::DdsContext>(pmu::test::exclusive_dds_domain(), PMU_QOS_FILE, name,
                                                pmu::dds::SecurityFiles{}, pmu::dds::Transport::Default,
                                                pmu::dds::ResolvedNetwork{}, partitions);
}

bool writer_matched(DataWriter& w, int count = 1) {
  PublicationMatchedStatus s;
  w.get_publication_matched_status(s);
  return s.current_count >= count;
}

bool reader_matched(DataReader& r, int count = 1) {
  SubscriptionMatchedStatus s;
  r.get_subscription_matched_status(s);
  return s.current_count >= count;
}

// What one endpoint's holder was handed, from Fast DDS's thread.
struct Received {
  std::mutex mutex;
  std::vector<RoleReport> reports;
  std::vector<std::chrono::steady_clock::time_point> arrivals;
  std::vector<pmu::redundancy::MoveRequest> moves;
  std::size_t report_count() {
    std::lock_guard<std::mutex> lock(mutex);
    return reports.size();
  }
};

// A fixed steady time, so the arrival handed on is the endpoint's clock, not a guess.
const auto kArrival = std::chrono::steady_clock::time_point(std::chrono::hours(1000));

DdsRoleEndpoint::Clocks test_clocks() {
  DdsRoleEndpoint::Clocks c;
  c.steady = [] { return kArrival; };
  c.wall_ns = [] { return std::uint64_t{2'000'000'000'000'000'000}; };
  return c;
}

TEST(RoleOverDds, AHeartbeatReachesThePeerAsWrittenAndNeverItsOwnWriter) {
  auto a_dds = participant("mc-a", vehicle_partitions(kVehicle));
  auto b_dds = participant("mc-b", vehicle_partitions(kVehicle));
  DdsRoleEndpoint a(*a_dds, kVehicle, test_clocks()), b(*b_dds, kVehicle, test_clocks());
  Received at_a, at_b;
  a.on_report([&](const RoleReport& r, std::chrono::steady_clock::time_point t) {
    std::lock_guard<std::mutex> lock(at_a.mutex);
    at_a.reports.push_back(r);
    at_a.arrivals.push_back(t);
  });
  b.on_report([&](const RoleReport& r, std::chrono::steady_clock::time_point t) {
    std::lock_guard<std::mutex> lock(at_b.mutex);
    at_b.reports.push_back(r);
    at_b.arrivals.push_back(t);
  });
  a.start();
  b.start();
  const RoleReport sent{"mc-a", "mc-b", {Role::Active, 7, 200, false}, BusState::BusOff, PeerAlarm::PeerUnreachable};
  // Volatile: a sample written before B's reader matched is not kept for it; the holder writes
  // every period, so does the test until one arrives.
  ASSERT_TRUE(pmu::test::wait_until(
      [&] {
        a.publish(sent);
        return at_b.report_count() > 0;
      },
      20s, 50ms));
  ASSERT_TRUE(pmu::test::wait_until([&] { return a.own() > 0; }, 20s)) << "A's reader matches A's own writer";
  std::lock_guard<std::mutex> lock(at_b.mutex);
  const auto& got = at_b.reports.front();
  EXPECT_EQ(got.name, "mc-a");
  EXPECT_EQ(got.peer, "mc-b");
  EXPECT_EQ(got.beat.role, Role::Active);
  EXPECT_EQ(got.beat.term, 7u);
  EXPECT_EQ(got.beat.priority, 200);
  EXPECT_FALSE(got.beat.hands_over);
  EXPECT_EQ(got.bus, BusState::BusOff);
  EXPECT_EQ(got.alarm, PeerAlarm::PeerUnreachable);
  EXPECT_EQ(at_b.arrivals.front(), kArrival);
  EXPECT_EQ(at_a.report_count(), 0u) << "an instance's own heartbeat is not handed to its holder";
  EXPECT_EQ(b.malformed(), 0u);
}

TEST(RoleOverDds, AnotherVehiclesOrAnUnknownEnumeratorIsCountedNotDelivered) {
  // A writer in every vehicle's partitions reaches this vehicle's reader with any vehicle field.
  auto raw_dds = participant("hostile", {pmu::dds::every_vehicle_partitions(), {}});
  auto b_dds = participant("mc-b", vehicle_partitions(kVehicle));
  DdsRoleEndpoint b(*b_dds, kVehicle, test_clocks());
  Received at_b;
  b.on_report([&](const RoleReport& r, std::chrono::steady_clock::time_point) {
    std::lock_guard<std::mutex> lock(at_b.mutex);
    at_b.reports.push_back(r);
  });
  b.start();
  // A role writer holds one instance, its own: one writer per sample's key.
  auto& topic = raw_dds->topic(pmu::topics::kRole, TypeSupport(new pmu::v5::RoleHeartbeatPubSubType()));
  DataWriter& w_other = raw_dds->writer(topic, pmu::qos_profiles::kRole);
  DataWriter& w_bad = raw_dds->writer(topic, pmu::qos_profiles::kRole);
  DataWriter& w_good = raw_dds->writer(topic, pmu::qos_profiles::kRole);
  ASSERT_TRUE(pmu::test::wait_until(
      [&] { return writer_matched(w_other) && writer_matched(w_bad) && writer_matched(w_good); }, 20s));
  pmu::v5::RoleHeartbeat other;
  other.vehicle("uav8");
  other.name("mc-x");
  other.role(pmu::v5::ROLE_ACTIVE);
  pmu::v5::RoleHeartbeat bad;
  bad.vehicle(kVehicle);
  bad.name("mc-y");
  bad.role(static_cast<pmu::v5::InstanceRole>(9));
  pmu::v5::RoleHeartbeat good;
  good.vehicle(kVehicle);
  good.name("mc-z");
  good.role(pmu::v5::ROLE_STANDBY);
  ASSERT_TRUE(w_other.write(&other));
  ASSERT_TRUE(pmu::test::wait_until([&] { return b.not_ours() > 0; }, 20s));
  ASSERT_TRUE(w_bad.write(&bad));
  ASSERT_TRUE(pmu::test::wait_until([&] { return b.malformed() > 0; }, 20s));
  ASSERT_TRUE(w_good.write(&good));
  ASSERT_TRUE(pmu::test::wait_until([&] { return at_b.report_count() > 0; }, 20s));
  EXPECT_EQ(b.not_ours(), 1u);
  EXPECT_EQ(b.malformed(), 1u);
  std::lock_guard<std::mutex> lock(at_b.mutex);
  ASSERT_EQ(at_b.reports.size(), 1u);
  EXPECT_EQ(at_b.reports.front().name, "mc-z");
  EXPECT_EQ(at_b.reports.front().beat.role, Role::Standby);
}

// A client of the vehicle as pmuctl is one: its request writer and reply reader.
struct MoveClient {
  std::unique_ptr<pmu::dds::DdsContext> dds;
  DataWriter* writer = nullptr;
  DataReader* reader = nullptr;
  explicit MoveClient(const pmu::dds::Partitions& partitions) : dds(participant("pmuctl", partitions)) {
    writer = &dds->writer(dds->topic(pmu::topics::kRoleMove, TypeSupport(new pmu::v5::RoleMovePubSubType())),
                          pmu::qos_profiles::kCommand);
    reader = &dds->reader(dds->topic(pmu::topics::kRoleMoveReply, TypeSupport(new pmu::v5::RoleMoveReplyPubSubType())),
                          pmu::qos_profiles::kCommand);
  }
  void send(const std::string& id, const std::string& instance, std::uint64_t expires_at = 0) {
    pmu::v5::RoleMove m;
    m.request_id(id);
    m.vehicle(kVehicle);
    m.instance(instance);
    m.requester("op@ground");
    m.expires_at(expires_at);
    ASSERT_TRUE(writer->write(&m));
  }
  std::vector<pmu::v5::RoleMoveReply> replies;
  void take() {
    pmu::v5::RoleMoveReply r;
    SampleInfo info;
    while (reader->take_next_sample(&r, &info) == ReturnCode_t::RETCODE_OK)
      if (info.valid_data) replies.push_back(r);
  }
};

TEST(RoleOverDds, AMoveForThisInstanceIsAskedOnceAndAnsweredAndAResendAlike) {
  auto b_dds = participant("mc-b", vehicle_partitions(kVehicle));
  DdsRoleEndpoint b(*b_dds, kVehicle, test_clocks());
  Received at_b;
  b.on_move("mc-b", [&](const pmu::redundancy::MoveRequest& m) {
    std::lock_guard<std::mutex> lock(at_b.mutex);
    at_b.moves.push_back(m);
    return pmu::redundancy::MoveResult{at_b.moves.size() == 1, at_b.moves.size() == 1 ? "" : "not active"};
  });
  b.start();
  MoveClient client(vehicle_partitions(kVehicle));
  ASSERT_TRUE(
      pmu::test::wait_until([&] { return writer_matched(*client.writer) && reader_matched(*client.reader); }, 20s));
  // Reliable, one writer, in order: each request arrives after the one before it, so the last
  // one's reply says every earlier request was judged.
  client.send("for-peer", "mc-a");
  client.send("expired", "mc-b", 1);
  client.send("move-1", "mc-b", 3'000'000'000'000'000'000ull);
  client.send("move-1", "mc-b", 3'000'000'000'000'000'000ull);  // a resend
  client.send("move-2", "mc-b");
  ASSERT_TRUE(pmu::test::wait_until(
      [&] {
        client.take();
        return client.replies.size() >= 3;
      },
      20s));
  ASSERT_EQ(client.replies.size(), 3u);
  for (std::size_t i = 0; i < 2; ++i) {
    EXPECT_EQ(client.replies[i].request_id(), "move-1");
    EXPECT_TRUE(client.replies[i].accepted()) << "a resend is answered with the first result";
    EXPECT_EQ(client.replies[i].instance(), "mc-b");
    EXPECT_EQ(client.replies[i].vehicle(), kVehicle);
  }
  EXPECT_EQ(client.replies[2].request_id(), "move-2");
  EXPECT_FALSE(client.replies[2].accepted());
  EXPECT_EQ(client.replies[2].reason(), "not active");
  EXPECT_EQ(b.expired(), 1u);
  std::lock_guard<std::mutex> lock(at_b.mutex);
  ASSERT_EQ(at_b.moves.size(), 2u);
  EXPECT_EQ(at_b.moves[0].request_id, "move-1");
  EXPECT_EQ(at_b.moves[0].instance, "mc-b");
  EXPECT_EQ(at_b.moves[0].requester, "op@ground");
  EXPECT_EQ(at_b.moves[1].request_id, "move-2");
}

// In one process (Fast DDS's in-process delivery, as pmu-service runs) an instance's own
// heartbeat comes back to its own reader on the thread that writes it, inside the write. Moves
// answered while heartbeats are written as fast as they can be: every move is answered and the
// heartbeats go on, so neither waits for the other's lock.
TEST(RoleOverDds, MovesAreAnsweredWhileTheInstanceWritesItsHeartbeats) {
  auto b_dds = participant("mc-b", vehicle_partitions(kVehicle));
  DdsRoleEndpoint b(*b_dds, kVehicle, test_clocks());
  std::atomic<int> reports{0};
  b.on_report([&](const RoleReport&, std::chrono::steady_clock::time_point) { ++reports; });
  b.on_move("mc-b", [](const pmu::redundancy::MoveRequest&) {
    return pmu::redundancy::MoveResult{false, "not active"};
  });
  b.start();
  MoveClient client(vehicle_partitions(kVehicle));
  ASSERT_TRUE(
      pmu::test::wait_until([&] { return writer_matched(*client.writer) && reader_matched(*client.reader); }, 20s));
  const RoleReport beat{"mc-b", "mc-a", {Role::Active, 2, 100, false}, BusState::Ok, PeerAlarm::None};
  ASSERT_TRUE(pmu::test::wait_until(
      [&] {
        b.publish(beat);
        return b.own() > 0;
      },
      20s, 50ms))
      << "its own heartbeat never came back to its reader";

  constexpr int kMoves = 300;
  std::atomic<bool> stop{false};
  std::atomic<long> written{0};
  std::thread beats([&] {
    while (!stop) {
      b.publish(beat);
      ++written;
    }
  });
  std::thread moves([&] {
    for (int i = 0; i < kMoves; ++i) client.send("move-" + std::to_string(i), "mc-b");
  });
  const bool answered = pmu::test::wait_until(
      [&] {
        client.take();
        return client.replies.size() >= static_cast<std::size_t>(kMoves);
      },
      30s);
  const long written_then = written;
  const bool beats_go_on = pmu::test::wait_until([&] { return written > written_then; }, 5s);
  if (!answered || !beats_go_on) {
    // A writer and a callback waiting for each other: the threads cannot be joined.
    ADD_FAILURE() << client.replies.size() << " of " << kMoves << " moves answered, heartbeats "
                  << (beats_go_on ? "go on" : "stopped") << " after " << written_then;
    std::fflush(stdout);
    std::_Exit(1);
  }
  stop = true;
  beats.join();
  moves.join();
  EXPECT_EQ(client.replies.size(), static_cast<std::size_t>(kMoves));
  EXPECT_EQ(reports.load(), 0) << "its own heartbeats are no peer's";
}

TEST(RoleOverDds, AMoveFromAWriterInEveryPartitionIsNotMoved) {
  auto b_dds = participant("mc-b", vehicle_partitions(kVehicle));
  DdsRoleEndpoint b(*b_dds, kVehicle, test_clocks());
  std::atomic<int> asked{0};
  b.on_move("mc-b", [&](const pmu::redundancy::MoveRequest&) {
    ++asked;
    return pmu::redundancy::MoveResult{true, ""};
  });
  b.start();
  MoveClient client({pmu::dds::every_vehicle_partitions(), pmu::dds::every_vehicle_partitions()});
  ASSERT_TRUE(pmu::test::wait_until([&] { return writer_matched(*client.writer); }, 20s));
  client.send("everywhere", "mc-b");
  ASSERT_TRUE(pmu::test::wait_until([&] { return b.not_ours() > 0; }, 20s));
  EXPECT_EQ(asked.load(), 0);
  client.take();
  EXPECT_TRUE(client.replies.empty());
}

}  // namespace
