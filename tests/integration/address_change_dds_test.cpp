// A CAN address change over real Fast DDS (docs/interface.md section 2.6): in one process, the
// old key's health ends OFFLINE and its instance is disposed, and a late joiner sees the new
// key alone; across processes, pmuctl on pmu-service's simulated bus moves the unit there and
// back, every verb agrees, commands without --address find the one PMU, and
// `pmu-service --check-config` names the stale config line from the state directory.
#include <gtest/gtest.h>
#include <unistd.h>

#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fstream>
#include <iterator>
#include <map>
#include <set>
#include <string>

#include "support/harness.hpp"
#include "pmu/dds/dds_context.hpp"
#include "pmu/dispatch/command_service.hpp"
#include "pmu/endpoints/dds_publisher.hpp"
#include "pmu/idl/statePubSubTypes.h"
#include "pmu/idl/topics.hpp"
#include "support/domain.hpp"
#include "support/json_lines.hpp"
#include "support/process.hpp"
#include "support/wait.hpp"

namespace pmu::service::test {
namespace {

using namespace eprosima::fastdds::dds;
using namespace std::chrono_literals;

DataReader& state_reader(dds::DdsContext& c, const char* topic, TypeSupport type) {
  return c.reader(c.topic(topic, type), qos_profiles::kState);
}

// The valid samples of a state topic per address, and the handles of instances disposed.
template <class T>
struct Seen {
  std::map<std::uint16_t, std::vector<T>> valid;
  std::map<std::uint16_t, InstanceHandle_t> handle;
  std::set<InstanceHandle_t> not_alive;
  void take(DataReader& r) {
    T s;
    SampleInfo info;
    while (r.take_next_sample(&s, &info) == ReturnCode_t::RETCODE_OK) {
      if (info.valid_data) {
        valid[s.address()].push_back(s);
        handle[s.address()] = info.instance_handle;
      } else if (info.instance_state != ALIVE_INSTANCE_STATE) {
        not_alive.insert(info.instance_handle);
      }
    }
  }
  bool gone(std::uint16_t address) const {
    auto it = handle.find(address);
    return it != handle.end() && not_alive.count(it->second) > 0;
  }
};

TEST(AddressChangeDds, OldKeyEndsOfflineAndIsDisposedAndALateJoinerSeesTheNewKeyAlone) {
  const int domain = pmu::test::exclusive_dds_domain();
  dds::DdsContext service_side(domain, "", "pmu-service-move");
  DdsPublisher publisher(service_side, 3s);
  dds::DdsContext client(domain, "", "reader-move");
  DataReader& health = state_reader(client, topics::kHealth, TypeSupport(new pmu::v5::HealthPubSubType()));

  Harness h(sim_bus({device(1)}), {pmu(1)}, Timeouts{}, &publisher);
  std::vector<CommandReplyData> replies;
  CommandService commands({&h.worker()}, PolicyConfig{}, Timeouts{}, h.clock(),
                          [&](const CommandReplyData& r) { replies.push_back(r); });
  Seen<pmu::v5::Health> seen;
  ASSERT_TRUE(pmu::test::wait_until(
      [&] {
        h.run_for(100ms);
        seen.take(health);
        return !seen.valid[1].empty();
      },
      20s));

  CommandSample s;
  s.request_id = "move-1";
  s.sender = "test";
  s.bus = "sim0";
  s.address = 1;
  s.kind = static_cast<std::uint32_t>(CommandKind::SetParameter);
  s.parameter = "can_address";
  s.value = 7;
  s.confirm = true;
  commands.submit(s);
  for (int i = 0; i < 500 && replies.empty(); ++i) h.run_for(10ms);
  ASSERT_EQ(replies.size(), 1u);
  ASSERT_EQ(replies[0].result, CommandResult::Completed) << replies[0].reason;

  ASSERT_TRUE(pmu::test::wait_until(
      [&] {
        h.run_for(10ms);
        seen.take(health);
        return seen.gone(1) && !seen.valid[7].empty();
      },
      10s))
      << "old key disposed: " << seen.gone(1);
  EXPECT_EQ(seen.valid[1].back().state(), pmu::v5::OFFLINE) << "the old key's last health";

  dds::DdsContext late(domain, "", "late-reader");
  DataReader& late_health = state_reader(late, topics::kHealth, TypeSupport(new pmu::v5::HealthPubSubType()));
  DataReader& late_info = state_reader(late, topics::kInfo, TypeSupport(new pmu::v5::DeviceInfoPubSubType()));
  DataReader& late_config = state_reader(late, topics::kConfig, TypeSupport(new pmu::v5::ConfigPubSubType()));
  Seen<pmu::v5::Health> lh;
  Seen<pmu::v5::DeviceInfo> li;
  Seen<pmu::v5::Config> lc;
  auto take_all = [&] {
    h.run_for(10ms);
    lh.take(late_health);
    li.take(late_info);
    lc.take(late_config);
  };
  ASSERT_TRUE(pmu::test::wait_until(
      [&] {
        take_all();
        return !lh.valid.empty() && !li.valid.empty() && !lc.valid.empty();
      },
      10s));
  // Whatever else there was would have come in the same burst of historical samples.
  pmu::test::wait_until([&] { return take_all(), false; }, 1s);
  EXPECT_EQ(lh.valid.count(1), 0u);
  EXPECT_EQ(li.valid.count(1), 0u);
  EXPECT_EQ(lc.valid.count(1), 0u);
  ASSERT_EQ(li.valid.count(7), 1u);
  EXPECT_EQ(li.valid[7].back().serial_number(), 4001);
  ASSERT_EQ(lc.valid.count(7), 1u);
  EXPECT_EQ(lc.valid[7].back().can_address(), 7);
  EXPECT_EQ(lh.valid[7].back().state(), pmu::v5::ONLINE);
}

// ---- across processes: pmu-service --config on its simulated bus, pmuctl ----------------------

pmu::test::RunResult sh(const std::string& cmd) { return pmu::test::run_capture(cmd, true); }

std::string read_file(const std::string& path) {
  std::ifstream in(path);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

class MovedService {
 public:
  explicit MovedService(int domain) {
    char dir[] = "/tmp/pmu-move-XXXXXX";
    if (::mkdtemp(dir)) dir_ = dir;
    config_ = dir_ + "/pmu-service.yaml";
    // The device's `address:` is line 6.
    std::ofstream(config_) << "domain: " << domain << "\nqos_file: " << PMU_QOS_FILE
                           << "\nbuses:\n  - interface: sim\n    devices:\n      - address: 1\n        period: 0.5\n";
    log_ = dir_ + "/service.log";
    start();
  }
  ~MovedService() {
    (void)process_.stop(10s);
    for (const auto& f : {config_, log_, state_file()}) ::unlink(f.c_str());
    ::rmdir(dir_.c_str());
  }
  void start() {
    pmu::test::ChildOptions o;
    o.stdout_path = o.stderr_path = log_;
    o.env = {"STATE_DIRECTORY=" + dir_};
    process_ = pmu::test::Child({PMU_SERVICE_PATH, "--config", config_}, o);
  }
  pmu::test::RunResult check_config() const {
    return sh("STATE_DIRECTORY=" + dir_ + " " + PMU_SERVICE_PATH + " --config " + config_ + " --check-config");
  }
  std::string state_file() const { return dir_ + "/moved-addresses"; }
  const std::string& config() const { return config_; }
  std::string log() const { return read_file(log_); }

 private:
  std::string dir_, config_, log_;
  pmu::test::Child process_;
};

// The PMUs `pmuctl list` shows: address -> serial. One list right after a move is enough: the
// old key is disposed a quarter of a second after the reply (DeviceSession::kGoneDelay), and
// list settles 300 ms after its first sample, dropping what is disposed meanwhile.
std::map<int, int> listed(const std::string& pmuctl) {
  std::map<int, int> out;
  for (const auto& j : pmu::test::json_lines(sh(pmuctl + "--timeout 20 --json list").out))
    if (!j.is_discarded() && j.value("kind", "") == "pmu")
      out[j["address"].get<int>()] =
          j["values"]["serial_number"].is_null() ? -1 : j["values"]["serial_number"].get<int>();
  return out;
}

TEST(AddressChangePmuctl, MovedThereAndBackEveryVerbAgreesAndCheckConfigNamesTheLine) {
  const int domain = pmu::test::exclusive_dds_domain();
  MovedService svc(domain);
  const std::string p = std::string(PMUCTL_PATH) + " --domain " + std::to_string(domain) + " ";
  std::map<int, int> pmus;
  for (int i = 0; i < 10 && pmus.empty(); ++i) pmus = listed(p);
  ASSERT_EQ(pmus, (std::map<int, int>{{1, 1001}})) << svc.log();

  auto r = sh(p + "--timeout 20 --confirm config set can_address 7");
  ASSERT_EQ(r.status, 0) << r.out << svc.log();
  EXPECT_NE(r.out.find("moved from address 1 to 7"), std::string::npos) << r.out;

  EXPECT_EQ(listed(p), (std::map<int, int>{{7, 1001}}));
  r = sh(p + "--timeout 20 config get can_address");  // no --address: the one PMU
  EXPECT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("sim/7 can_address = 7"), std::string::npos) << r.out;
  r = sh(p + "--timeout 20 outputs get");  // a command without --address
  EXPECT_EQ(r.status, 0) << r.out;
  r = sh(p + "--timeout 3 --address 1 info");
  EXPECT_EQ(r.status, 2) << r.out;  // no such target
  EXPECT_NE(r.out.find("PMU 1 not seen"), std::string::npos) << r.out;

  const std::string line = svc.config() + ":6";
  EXPECT_NE(svc.log().find(line + ": change `address: 1` to `address: 7`"), std::string::npos) << svc.log();
  EXPECT_NE(read_file(svc.state_file()).find("\nsim 1 7 1001\n"), std::string::npos) << read_file(svc.state_file());
  r = svc.check_config();
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_NE(r.out.find(line + ": bus sim, address 1: the PMU (serial 1001) answers at address 7"), std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("change `address: 1` to `address: 7`"), std::string::npos) << r.out;

  r = sh(p + "--timeout 20 --address 7 --confirm config set can_address 1");
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_EQ(listed(p), (std::map<int, int>{{1, 1001}}));
  r = sh(p + "--timeout 20 config get can_address");
  EXPECT_NE(r.out.find("sim/1 can_address = 1"), std::string::npos) << r.out;
  EXPECT_EQ(read_file(svc.state_file()).find("sim 1"), std::string::npos) << read_file(svc.state_file());
  r = svc.check_config();
  EXPECT_EQ(r.status, 0) << r.out;
}

}  // namespace
}  // namespace pmu::service::test
