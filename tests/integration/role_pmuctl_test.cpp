// pmuctl against a hot-standby pair's pmu/role (interface.md 1.10, 3.2): two instances written
// by DdsRoleEndpoint in this process, heartbeats every 100 ms as the holder writes them,
// pmuctl a process of its own. A pair with two bus owners and no readiness is NOT READY for
// preflight (docs/safety.md H6), list shows both instances, and role move prints the
// instance's answer with its exit status.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <memory>
#include <string>
#include <thread>

#include "pmu/dds/dds_context.hpp"
#include "pmu/dds_settings/vehicle.hpp"
#include "pmu/endpoints/dds_role.hpp"
#include "support/domain.hpp"
#include "support/process.hpp"

namespace {

using namespace std::chrono_literals;
using pmu::redundancy::BusState;
using pmu::redundancy::PeerAlarm;
using pmu::redundancy::Role;
using pmu::redundancy::RoleReport;

// One instance of the pair: its participant in the vehicle's partition, its endpoint and a
// thread that writes its heartbeat every 100 ms until the instance goes.
class Instance {
 public:
  Instance(const std::string& name, const std::string& peer, Role role)
      : dds_(pmu::test::exclusive_dds_domain(), PMU_QOS_FILE, name, pmu::dds::SecurityFiles{},
             pmu::dds::Transport::Default, pmu::dds::ResolvedNetwork{},
             pmu::dds::Partitions{pmu::dds::vehicle_partitions("uav7"), pmu::dds::vehicle_partitions("uav7")}),
        endpoint_(dds_, "uav7"),
        report_{name,
                peer,
                {role, 4, name == "mc-a" ? std::uint8_t{2} : std::uint8_t{1}, false},
                BusState::Ok,
                PeerAlarm::None} {
    endpoint_.on_move(name, [](const pmu::redundancy::MoveRequest&) {
      return pmu::redundancy::MoveResult{false, "the peer is not a live STANDBY with its bus up"};
    });
    endpoint_.start();
    beat_ = std::thread([this] {
      while (!stop_) {
        endpoint_.publish(report_);
        std::this_thread::sleep_for(100ms);
      }
    });
  }
  ~Instance() {
    stop_ = true;
    beat_.join();
  }

 private:
  pmu::dds::DdsContext dds_;
  pmu::service::DdsRoleEndpoint endpoint_;
  RoleReport report_;
  std::atomic<bool> stop_{false};
  std::thread beat_;
};

std::string pmuctl(const std::string& args) {
  return "PMU_QOS_FILE=" PMU_QOS_FILE " " PMUCTL_PATH " --no-agent --domain " +
         std::to_string(pmu::test::exclusive_dds_domain()) + " --vehicle uav7 " + args + " 2>&1";
}

TEST(RoleWithPmuctl, TwoBusOwnersAreNotReadyAndListShowsBoth) {
  Instance a("mc-a", "mc-b", Role::Active), b("mc-b", "mc-a", Role::Active);
  const auto preflight = pmu::test::run_capture(pmuctl("--timeout 3 preflight"));
  EXPECT_EQ(preflight.status, 1) << preflight.out;
  EXPECT_NE(preflight.out.find("uav7: NOT READY"), std::string::npos) << preflight.out;
  EXPECT_NE(preflight.out.find("two instances own the bus: mc-a and mc-b"), std::string::npos) << preflight.out;
  EXPECT_NE(preflight.out.find("no_readiness"), std::string::npos) << preflight.out;
  EXPECT_EQ(preflight.out.find("READY\n"), std::string::npos) << preflight.out;

  const auto list = pmu::test::run_capture(pmuctl("--timeout 3 --json list"));
  EXPECT_NE(list.out.find(R"("topic":"role","vehicle":"uav7","values":{"name":"mc-a","peer":"mc-b","role":"active")"),
            std::string::npos)
      << list.out;
  EXPECT_NE(list.out.find(R"("name":"mc-b","peer":"mc-a","role":"active")"), std::string::npos) << list.out;
}

TEST(RoleWithPmuctl, AMoveRefusedIsPrintedWithItsReasonAndAnUnknownInstanceIsNoAnswer) {
  Instance a("mc-a", "mc-b", Role::Active), b("mc-b", "mc-a", Role::Standby);
  const auto refused = pmu::test::run_capture(pmuctl("--timeout 5 role move mc-a"));
  EXPECT_EQ(refused.status, 1) << refused.out;
  EXPECT_NE(refused.out.find("REFUSED: the peer is not a live STANDBY with its bus up"), std::string::npos)
      << refused.out;
  // The timeout bounds the match with the pair too; a shorter one on a loaded machine ends in
  // "no pmu-service" before the instances are discovered, which is not the answer looked for.
  const auto unknown = pmu::test::run_capture(pmuctl("--timeout 8 role move mc-x"));
  EXPECT_EQ(unknown.status, 3) << unknown.out;
  EXPECT_NE(unknown.out.find("no reply from instance mc-x of"), std::string::npos) << unknown.out;
}

}  // namespace
