// No silent caps: a service with many PMUs serves every one of them to pmuctl. Fast DDS's
// default resource limits (10 instances per writer and reader) once cut a 50-PMU service
// down to 9 or 10 devices in `pmuctl list` and `watch`, with nothing logged.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <map>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <string>
#include <thread>

#include "pmu/dds_settings/capacity.hpp"
#include "pmu/dds/dds_context.hpp"
#include "pmu/endpoints/dds_publisher.hpp"
#include "pmu/idl/statePubSubTypes.h"
#include "pmu/idl/topics.hpp"
#include "support/domain.hpp"
#include "support/json_lines.hpp"
#include "support/process.hpp"
#include "support/wait.hpp"

namespace pmu::service {
namespace {

using namespace eprosima::fastdds::dds;
using namespace std::chrono_literals;

constexpr int kDevices = 50;

// stdout only: pmuctl's diagnostics go to stderr and would not parse as JSON.
pmu::test::RunResult run(const std::string& cmd) { return pmu::test::run_capture(cmd); }

using pmu::test::json_lines;

class ManyPmus : public ::testing::Test {
 protected:
  void SetUp() override {
    char path[] = "/tmp/pmu-capacity-XXXXXX.yaml";
    const int fd = ::mkstemps(path, 5);
    ASSERT_GE(fd, 0);
    ::close(fd);
    config_ = path;
    std::ofstream yaml(config_);
    yaml << "buses:\n  - interface: sim\n    name: sim0\n    devices:\n";
    for (int a = 1; a <= kDevices; ++a) yaml << "      - address: " << a << "\n        period: 0.5\n";
    yaml.close();
    ASSERT_GE(pmu::test::exclusive_dds_domain(), 0);
    domain_ = std::to_string(pmu::test::exclusive_dds_domain());
    service_ = pmu::test::Child({PMU_SERVICE_PATH, "--config", config_, "--domain", domain_, "--log-level", "warn"});
  }
  void TearDown() override {
    (void)service_.stop(10s);
    if (!config_.empty()) std::remove(config_.c_str());
  }
  std::string pmuctl(const std::string& args) const {
    return std::string("PMU_QOS_FILE=" PMU_QOS_FILE " " PMUCTL_PATH " --domain ") + domain_ + " " + args;
  }

  std::string config_;
  std::string domain_;
  pmu::test::Child service_;
};

TEST_F(ManyPmus, PmuctlListsWatchesAndCommandsEveryOneOf50) {
  // The service reads each PMU's identity and parameters before it lists it: poll until all
  // are there or the deadline passes (a cap shows as a count stuck below 50).
  std::set<int> listed;
  pmu::test::wait_until(
      [&] {
        const auto r = run(pmuctl("--json --timeout 5 list"));
        listed.clear();
        for (const auto& j : json_lines(r.out))
          if (j.is_object() && j.contains("address") && j.value("/values/state"_json_pointer, "") == "ONLINE")
            listed.insert(j["address"].get<int>());
        return listed.size() >= kDevices;
      },
      60s, 500ms);
  ASSERT_EQ(listed.size(), static_cast<std::size_t>(kDevices)) << "pmuctl list shows " << listed.size() << " PMUs";
  EXPECT_EQ(*listed.begin(), 1);
  EXPECT_EQ(*listed.rbegin(), kDevices);

  // 50 PMUs x 5 packets every 0.5 s: 1,500 samples take about 3 s and hold every address.
  const auto w = run(pmuctl("--json --timeout 30 watch --count 1500"));
  ASSERT_EQ(w.status, 0) << w.out.substr(0, 2000);
  std::map<std::string, std::set<int>> watched;
  for (const auto& j : json_lines(w.out)) {
    ASSERT_TRUE(j.is_object()) << "pmuctl watch printed a line that is not JSON";
    watched[j["topic"].get<std::string>()].insert(j["address"].get<int>());
  }
  for (const char* topic : {"voltages", "currents", "battery_energy", "temperatures", "status"})
    EXPECT_EQ(watched[topic].size(), static_cast<std::size_t>(kDevices)) << topic << ": addresses seen";

  const auto c = run(pmuctl("--address 30 --timeout 10 config get avionics_voltage 2>&1"));
  EXPECT_EQ(c.status, 0) << c.out;
  EXPECT_NE(c.out.find("sim0/30"), std::string::npos) << c.out;
  EXPECT_NE(c.out.find("avionics_voltage"), std::string::npos) << c.out;
  const auto s = run(pmuctl("--address 50 --timeout 10 config set payload_voltage 18.0 2>&1"));
  EXPECT_EQ(s.status, 0) << s.out;
  EXPECT_NE(s.out.find("COMPLETED"), std::string::npos) << s.out;
}

// A qos.xml whose state writer was left at Fast DDS's default limits (the bug this guards
// against) stops pmu-service at start-up, naming the file, the profile and the shortfall.
TEST(QosCapacity, AMiseditedProfileIsAStartUpError) {
  std::ifstream shipped(PMU_QOS_FILE);
  std::stringstream text;
  text << shipped.rdbuf();
  std::string xml = text.str();
  const std::string state = "<data_writer profile_name=\"state\">";
  const auto at = xml.find(state);
  ASSERT_NE(at, std::string::npos);
  const auto from = xml.find("<resourceLimitsQos>", at), to = xml.find("</resourceLimitsQos>", at);
  ASSERT_NE(from, std::string::npos);
  xml.erase(from, to + std::string("</resourceLimitsQos>").size() - from);
  char path[] = "/tmp/pmu-qos-XXXXXX.xml";
  const int fd = ::mkstemps(path, 4);
  ASSERT_GE(fd, 0);
  ASSERT_EQ(::write(fd, xml.data(), xml.size()), static_cast<ssize_t>(xml.size()));
  ::close(fd);
  ASSERT_GE(pmu::test::exclusive_dds_domain(), 0);
  const auto r = run(std::string("PMU_QOS_FILE=") + path + " " PMU_SERVICE_PATH " --bus sim --domain " +
                     std::to_string(pmu::test::exclusive_dds_domain()) + " 2>&1");
  std::remove(path);
  // A rejected configuration, found by the start-up check before anything is opened, at the
  // profile's line.
  EXPECT_EQ(r.status, 2) << r.out;
  const std::string line =
      std::to_string(std::count(xml.begin(), xml.begin() + static_cast<std::ptrdiff_t>(at), '\n') + 1);
  EXPECT_NE(r.out.find(std::string(path) + ":" + line +
                       ": <data_writer profile_name=\"state\"> (the pmu/config, pmu/info and pmu/health writers): "
                       "max_instances 10 < 256 (PMUs per service, pmu::dds::kMaxDevicesPerService)"),
            std::string::npos)
      << r.out;
}

// A PMU beyond the capacity (discovery can find one) is not published, and that is counted
// and carried in pmu/health's publish_failures rather than lost without a trace.
TEST(QosCapacity, PmusBeyondTheCapacityAreCountedInHealthNotDroppedSilently) {
  ASSERT_GE(pmu::test::exclusive_dds_domain(), 0);
  dds::DdsContext service_side(pmu::test::exclusive_dds_domain(), PMU_QOS_FILE, "capacity-publisher");
  DdsPublisher publisher(service_side, 3s);
  dds::DdsContext client(pmu::test::exclusive_dds_domain(), PMU_QOS_FILE, "capacity-reader");
  DataReader& health =
      client.reader(client.topic(topics::kHealth, TypeSupport(new pmu::v5::HealthPubSubType())), qos_profiles::kState);
  HealthReport report;
  report.state = HealthState::Online;
  for (std::size_t a = 1; a <= dds::kMaxDevicesPerService + 1; ++a)
    publisher.on_health(DeviceKey{"sim0", static_cast<std::uint16_t>(a)}, report);
  EXPECT_EQ(publisher.samples_written(), dds::kMaxDevicesPerService);
  EXPECT_EQ(publisher.samples_over_capacity(), 1u);
  EXPECT_EQ(publisher.write_failures(), 1u);

  publisher.on_health(DeviceKey{"sim0", 1}, report);  // an admitted PMU still publishes
  std::map<int, std::uint64_t> failures_by_address;
  pmu::v5::Health h;
  SampleInfo info;
  // Until address 1's second sample, written after the refusal, has come too: every admitted
  // PMU's first sample can arrive before it.
  pmu::test::wait_until(
      [&] {
        while (health.take_next_sample(&h, &info) == ReturnCode_t::RETCODE_OK)
          if (info.valid_data) failures_by_address[h.address()] = h.publish_failures();
        return failures_by_address.size() >= dds::kMaxDevicesPerService && failures_by_address[1] > 0;
      },
      20s);
  EXPECT_EQ(failures_by_address.size(), dds::kMaxDevicesPerService);
  EXPECT_EQ(failures_by_address.count(static_cast<int>(dds::kMaxDevicesPerService) + 1), 0u);
  EXPECT_EQ(failures_by_address[1], 1u) << "the refused PMU's sample is counted in the next health sample";
}

}  // namespace
}  // namespace pmu::service
