// Fast DDS 2.9.1's matching race (pmu/dds/security_match_guard.hpp), made to happen whenever
// it can by match_race_window.hpp: a secured participant that finds two peers at once
// authenticates both, and no two of its threads are ever inside the matching at once. The
// guard's presence in the installed programs is checked on their dynamic symbol tables.
//
// A program of its own: the window slows every secured discovery of the process.
#include <gtest/gtest.h>

#include <chrono>
#include <string>

#include "match_race_window.hpp"
#include "support/pki_fixture.hpp"
#include "pmu/dds/dds_context.hpp"
#include "pmu/dds/security_match_guard.hpp"
#include "pmu/idl/commandPubSubTypes.h"
#include "pmu/idl/topics.hpp"
#include "support/domain.hpp"
#include "support/process.hpp"
#include "support/wait.hpp"

namespace pmu::security_test {
namespace {

using namespace eprosima::fastdds::dds;
using namespace std::chrono_literals;

// A participant with a pmu/command reader (a service) or writer (a ground station), over UDP
// so that multicast and unicast announcements arrive on two receive threads.
struct Participant {
  Participant(int domain, const std::string& identity, const std::string& name)
      : dds(domain, "", name, Pki::get().files(identity), dds::Transport::UdpOnly) {}
  dds::DdsContext dds;
  Topic& topic() { return dds.topic(topics::kCommand, TypeSupport(new pmu::v5::CommandPubSubType())); }
};

struct Service : Participant {
  Service(int domain, const std::string& name)
      : Participant(domain, "pmu-service", name), reader(dds.reader(topic(), qos_profiles::kCommand)) {}
  int matched() {
    SubscriptionMatchedStatus s;
    reader.get_subscription_matched_status(s);
    return s.current_count;
  }
  DataReader& reader;
};

struct GroundStation : Participant {
  explicit GroundStation(int domain)
      : Participant(domain, "ground-station", "ground-station"), writer(dds.writer(topic(), qos_profiles::kCommand)) {}
  int matched() {
    PublicationMatchedStatus s;
    writer.get_publication_matched_status(s);
    return s.current_count;
  }
  DataWriter& writer;
};

TEST(SecurityMatchGuard, IsActiveInThisProgram) { EXPECT_TRUE(dds::security_match_guard_active()); }

// Both services announce themselves by multicast and by unicast while the ground station
// joins, so it finds them on two threads; the window holds the first finding open until the
// second comes or 3 s pass.
TEST(SecurityMatchGuard, AGroundStationThatFindsTwoServicesAtOnceAuthenticatesBoth) {
  const int domain = pmu::test::exclusive_dds_domain();
  Service uav1(domain, "uav1");
  Service uav2(domain, "uav2");
  GroundStation gs(domain);
  const bool linked =
      pmu::test::wait_until([&] { return gs.matched() == 2 && uav1.matched() == 1 && uav2.matched() == 1; }, 40s);
  EXPECT_TRUE(linked) << "the ground station's command writer matched " << gs.matched()
                      << " of 2 services' readers (uav1 " << uav1.matched() << ", uav2 " << uav2.matched() << ")";
  EXPECT_EQ(match_overlaps(), 0) << "two threads of one participant were matching builtin endpoints at once";
  EXPECT_GT(match_windows_alone(), 0) << "no matching went through the window: the test did not test";
}

// The programs users run: each exports both Fast DDS names, so the library's calls reach the
// guard (security_match_guard.hpp says why the linker does this).
TEST(SecurityMatchGuard, EveryProgramWithDdsSecurityCarriesIt) {
  for (const std::string program : {PMU_SERVICE_PATH, PMUCTL_PATH}) {
    const auto r = sh("nm -D --defined-only '" + program + "'");
    ASSERT_EQ(r.status, 0) << r.out;
    for (const std::string name :
         {"SecurityManager23match_builtin_endpoints", "SecurityManager36match_builtin_key_exchange_endpoints"})
      EXPECT_NE(r.out.find(name), std::string::npos) << program << " does not define " << name;
  }
}

}  // namespace
}  // namespace pmu::security_test
