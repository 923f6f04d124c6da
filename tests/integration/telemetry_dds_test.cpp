// The telemetry path end to end over real Fast DDS: the service's bus worker and publisher,
// a simulated PMU, and readers written against interface.md's types and QoS profiles, in one
// process (fake clock for the bus side) and across processes (pmu-service and pmuctl).
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fastdds/dds/core/status/PublicationMatchedStatus.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fstream>
#include <future>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>
#include <thread>

#include "support/harness.hpp"
#include "bus_thread.hpp"
#include "pmu/dds/dds_context.hpp"
#include "pmu/endpoints/dds_publisher.hpp"
#include "pmu/idl/commandPubSubTypes.h"
#include "pmu/idl/statePubSubTypes.h"
#include "pmu/idl/telemetryPubSubTypes.h"
#include "pmu/idl/topics.hpp"
#include "support/domain.hpp"
#include "support/json_lines.hpp"
#include "support/process.hpp"
#include "support/wait.hpp"

namespace pmu::service::test {
namespace {

using namespace eprosima::fastdds::dds;
using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

template <class T>
bool wait_sample(DataReader& r, T& out, SampleInfo& info, std::chrono::milliseconds timeout) {
  return pmu::test::wait_until(
      [&] {
        while (r.take_next_sample(&out, &info) == ReturnCode_t::RETCODE_OK)
          if (info.valid_data) return true;
        return false;
      },
      timeout, 5ms);
}

struct Readers {
  explicit Readers(dds::DdsContext& c)
      : voltages(c.reader(c.topic(topics::kVoltages, TypeSupport(new pmu::v5::VoltagesPubSubType())),
                          qos_profiles::kTelemetry)),
        currents(c.reader(c.topic(topics::kCurrents, TypeSupport(new pmu::v5::CurrentsPubSubType())),
                          qos_profiles::kTelemetry)),
        energy(c.reader(c.topic(topics::kBatteryEnergy, TypeSupport(new pmu::v5::BatteryEnergyPubSubType())),
                        qos_profiles::kTelemetry)),
        temperatures(c.reader(c.topic(topics::kTemperatures, TypeSupport(new pmu::v5::TemperaturesPubSubType())),
                              qos_profiles::kTelemetry)),
        status(
            c.reader(c.topic(topics::kStatus, TypeSupport(new pmu::v5::StatusPubSubType())), qos_profiles::kTelemetry)),
        config(c.reader(c.topic(topics::kConfig, TypeSupport(new pmu::v5::ConfigPubSubType())), qos_profiles::kState)),
        info(c.reader(c.topic(topics::kInfo, TypeSupport(new pmu::v5::DeviceInfoPubSubType())), qos_profiles::kState)),
        health(c.reader(c.topic(topics::kHealth, TypeSupport(new pmu::v5::HealthPubSubType())), qos_profiles::kState)) {
  }
  DataReader& voltages;
  DataReader& currents;
  DataReader& energy;
  DataReader& temperatures;
  DataReader& status;
  DataReader& config;
  DataReader& info;
  DataReader& health;
};

TEST(DdsTelemetry, EveryTopicArrivesWithTheSimulatorsValuesAndFrameTimestamps) {
  dds::DdsContext service_side(pmu::test::exclusive_dds_domain(), "", "pmu-service-test");
  DdsPublisher publisher(service_side, 3s);
  dds::DdsContext client(pmu::test::exclusive_dds_domain(), "", "reader-test");
  Readers r(client);

  auto unit = pmu(1, codec::kCurrentFirmware, 5);
  Harness h(sim_bus({device(1)}), {unit}, Timeouts{}, &publisher);
  h.pmus().with_model(1, [&](sim::PmuModel& m) { m.set_engine_running(true, h.clock().steady_now()); });
  const auto expected = [&] {
    sim::Telemetry t;
    h.pmus().with_model(1, [&](sim::PmuModel& m) { t = m.telemetry(); });
    return t;
  }();
  BusThread bus(h);

  SampleInfo si;
  pmu::v5::Voltages v;
  ASSERT_TRUE(wait_sample(r.voltages, v, si, 10s));
  EXPECT_EQ(v.bus().to_string(), "sim0");
  EXPECT_EQ(v.address(), 1);
  EXPECT_FLOAT_EQ(v.avionics(), static_cast<float>(expected.voltages.avionics));
  EXPECT_FLOAT_EQ(v.generator(), static_cast<float>(expected.voltages.generator));
  // Source timestamp = the frame's receive time on the (fake) bus clock, which started at
  // 1700000000 s: nothing like the wall clock of this run.
  EXPECT_GE(si.source_timestamp.seconds(), 1700000000);
  EXPECT_LT(si.source_timestamp.seconds(), 1700000000 + 3600);

  pmu::v5::Currents c;
  ASSERT_TRUE(wait_sample(r.currents, c, si, 5s));
  EXPECT_FLOAT_EQ(c.payload(), static_cast<float>(expected.currents.payload));
  pmu::v5::BatteryEnergy e;
  ASSERT_TRUE(wait_sample(r.energy, e, si, 5s));
  pmu::v5::Temperatures t;
  ASSERT_TRUE(wait_sample(r.temperatures, t, si, 5s));
  EXPECT_FLOAT_EQ(t.internal(), static_cast<float>(expected.temperatures.internal));
  EXPECT_TRUE(std::isnan(t.generator())) << "no generator sensor in the simulator: NaN";
  pmu::v5::Status s;
  ASSERT_TRUE(wait_sample(r.status, s, si, 5s));
  EXPECT_TRUE(s.generation_enabled());
  EXPECT_TRUE(s.avionics_servo_on());
  EXPECT_GT(s.generator_rpm(), 0);

  pmu::v5::Config cfg;
  ASSERT_TRUE(wait_sample(r.config, cfg, si, 5s));
  EXPECT_FLOAT_EQ(cfg.avionics_voltage(), 12.0f);
  EXPECT_FLOAT_EQ(cfg.packet_period(), 0.5f);
  EXPECT_EQ(cfg.can_address(), 1);
  pmu::v5::DeviceInfo info;
  ASSERT_TRUE(wait_sample(r.info, info, si, 5s));
  EXPECT_EQ(info.serial_number(), 4001);
  EXPECT_EQ(info.firmware_minor(), 17);
  EXPECT_EQ(info.features().size(), std::size(codec::kAllFeatures)) << "1.17 has every feature";
  pmu::v5::Health hl;
  ASSERT_TRUE(wait_sample(r.health, hl, si, 5s));
  EXPECT_EQ(hl.address(), 1);

  // A late-joining reader gets config, info and health as soon as it has discovered the
  // writers (TRANSIENT_LOCAL). The wait is discovery's, which under ThreadSanitizer beside
  // other tests took more than 3 s once; wait_sample returns at the first sample.
  dds::DdsContext late(pmu::test::exclusive_dds_domain(), "", "late-reader");
  Readers lr(late);
  ASSERT_TRUE(wait_sample(lr.config, cfg, si, 10s));
  EXPECT_FLOAT_EQ(cfg.avionics_voltage(), 12.0f);
  ASSERT_TRUE(wait_sample(lr.info, info, si, 10s));
  EXPECT_EQ(info.serial_number(), 4001);
  ASSERT_TRUE(wait_sample(lr.health, hl, si, 10s));
}

// `link: round_trip` (config.hpp): the reliable writers made after heartbeat_at_least
// heartbeat no more often than that; best-effort writers have no heartbeat to change, and a
// context without it keeps qos.xml's periods.
TEST(DdsWriters, ReliableWritersHeartbeatNoMoreOftenThanTheLinkAllows) {
  const auto period_of = [](DataWriter& w) { return w.get_qos().reliable_writer_qos().times.heartbeatPeriod; };
  dds::DdsContext plain(pmu::test::exclusive_dds_domain(), "", "heartbeat-plain");
  const auto shipped = period_of(
      plain.writer(plain.topic(topics::kHealth, TypeSupport(new pmu::v5::HealthPubSubType())), qos_profiles::kState));
  ASSERT_LT(shipped, eprosima::fastrtps::Duration_t(0, 900000000))
      << "qos.xml's state period is not below the floor tested";

  dds::DdsContext radio(pmu::test::exclusive_dds_domain(), "", "heartbeat-radio");
  radio.heartbeat_at_least(900ms);
  auto& health =
      radio.writer(radio.topic(topics::kHealth, TypeSupport(new pmu::v5::HealthPubSubType())), qos_profiles::kState);
  EXPECT_EQ(period_of(health), eprosima::fastrtps::Duration_t(0, 900000000));
  auto& replies = radio.writer(radio.topic(topics::kCommandReply, TypeSupport(new pmu::v5::CommandReplyPubSubType())),
                               qos_profiles::kCommand);
  EXPECT_EQ(period_of(replies), eprosima::fastrtps::Duration_t(0, 900000000));
  // The rest of the profile is the profile's.
  EXPECT_EQ(health.get_qos().durability().kind, TRANSIENT_LOCAL_DURABILITY_QOS);
  EXPECT_EQ(health.get_qos().history().depth, 1);
  EXPECT_EQ(replies.get_qos().history().depth, 4096);
  auto& voltages = radio.writer(radio.topic(topics::kVoltages, TypeSupport(new pmu::v5::VoltagesPubSubType())),
                                qos_profiles::kTelemetry);
  EXPECT_EQ(voltages.get_qos().reliability().kind, BEST_EFFORT_RELIABILITY_QOS);
  // A floor below the profile's period leaves it.
  dds::DdsContext lan(pmu::test::exclusive_dds_domain(), "", "heartbeat-lan");
  lan.heartbeat_at_least(1ms);
  EXPECT_EQ(period_of(lan.writer(lan.topic(topics::kHealth, TypeSupport(new pmu::v5::HealthPubSubType())),
                                 qos_profiles::kState)),
            shipped);
}

TEST(DdsTelemetry, RateFollowsThePacketPeriod) {
  dds::DdsContext service_side(pmu::test::exclusive_dds_domain(), "", "pmu-service-rate");
  DdsPublisher publisher(service_side, 3s);
  dds::DdsContext client(pmu::test::exclusive_dds_domain(), "", "reader-rate");
  Readers r(client);
  Harness h(sim_bus({device(1)}), {pmu(1, codec::kCurrentFirmware, 2)}, Timeouts{}, &publisher);  // PP 0.2 s
  pmu::v5::Voltages v;
  SampleInfo si;
  std::set<std::int64_t> stamps;
  {
    BusThread bus(h);  // bus time runs ~5x faster than real time: a sample every ~40 ms
    pmu::test::wait_until(
        [&] {
          while (r.voltages.take_next_sample(&v, &si) == ReturnCode_t::RETCODE_OK)
            if (si.valid_data) stamps.insert(static_cast<std::int64_t>(si.source_timestamp.to_ns() / 1000000));
          return stamps.size() >= 30;
        },
        4s, 2ms);
  }
  ASSERT_GE(stamps.size(), 30u);
  // Consecutive samples are one packet period apart in frame time (a best-effort sample may
  // be lost, never invented): every gap is a whole multiple of 200 ms, nearly all exactly one.
  std::vector<std::int64_t> t(stamps.begin(), stamps.end());
  std::size_t exact = 0;
  for (std::size_t i = 1; i < t.size(); ++i) {
    EXPECT_EQ((t[i] - t[i - 1]) % 200, 0) << t[i] - t[i - 1];
    exact += (t[i] - t[i - 1]) == 200 ? 1u : 0u;
  }
  EXPECT_GE(exact, (t.size() - 1) * 9 / 10);
}

// ---- across processes -----------------------------------------------------------------------

using pmu::test::run_capture;

TEST(CrossProcess, ServiceOnSimulatedBusFeedsPmuctl) {
  const std::string domain = std::to_string(pmu::test::exclusive_dds_domain());
  pmu::test::Child service({PMU_SERVICE_PATH, "--bus", "sim", "--domain", domain, "--log-level", "warn"});
  const auto watched =
      run_capture(std::string(PMUCTL_PATH) + " --domain " + domain + " watch --json --count 15 --timeout 20");
  const std::string& out = watched.out;
  ASSERT_EQ(watched.status, 0) << out;
  std::set<std::string> topics;
  std::size_t lines = 0;
  for (const auto& j : pmu::test::json_lines(out)) {
    ASSERT_FALSE(j.is_discarded()) << out;
    ++lines;
    topics.insert(j["topic"].get<std::string>());
    EXPECT_EQ(j["bus"], "sim0");
    EXPECT_EQ(j["address"], 1);
    if (j["topic"] == "voltages") {
      EXPECT_EQ(j["values"]["avionics"], 12.0);
    }
  }
  EXPECT_EQ(lines, 15u);
  EXPECT_EQ(topics, (std::set<std::string>{"voltages", "currents", "battery_energy", "temperatures", "status"}));

  const auto listed =
      run_capture(std::string(PMUCTL_PATH) + " --domain " + domain + " --timeout 20 list --json");  // returns once seen
  const std::string& list = listed.out;
  ASSERT_EQ(listed.status, 0) << list;
  const auto l = nlohmann::json::parse(list.substr(0, list.find('\n')));
  EXPECT_EQ(l["values"]["state"], "ONLINE");
  EXPECT_EQ(l["values"]["firmware"], "1.17");

  // SIGTERM stops the service cleanly within a second. Not a speed measurement (those live in
  // bench/): the README and interface.md promise systemd a stop within a second of SIGTERM,
  // a behavioural bound, so it stays an assertion. Stopping takes tens of ms; a second is
  // the contract's own margin.
  const auto t0 = Clock::now();
  ASSERT_TRUE(service.signal(SIGTERM));
  const std::optional<int> stopped = service.wait_for(3s);
  const auto took = Clock::now() - t0;
  const int wstatus = stopped.value_or(-1);
  EXPECT_TRUE(stopped && WIFEXITED(wstatus));
  EXPECT_EQ(WEXITSTATUS(wstatus), 0);
  EXPECT_LT(took, 1s);
}

// Fast DDS 2.9's writer destructor can loop for ever, holding the writer's lock, when the
// writer's periodic heartbeat fires while it runs (dds_context.cpp says how, and how DdsContext
// avoids it). What that takes: a reliable writer with many samples that a reader in another
// process has not acknowledged (here pmu-service's command reader, stopped with SIGSTOP, so
// none is), and a heartbeat due during the deletion: every 1 ms here instead of qos.xml's 100 ms.
// Without the workaround this hung in each of 13 runs. A hung destructor cannot be undone, so
// the test ends the process with the failure instead of sitting out ctest's timeout.
TEST(CrossProcess, AContextWhoseReaderNeverAcknowledgedIsDestroyedPromptly) {
  const int domain = pmu::test::exclusive_dds_domain();
  const std::string qos = "/tmp/pmu-unacked-" + std::to_string(::getpid()) + ".xml";
  std::ofstream(qos) << R"(<?xml version="1.0" encoding="UTF-8" ?>
<dds xmlns="http://www.eprosima.com/XMLSchemas/fastRTPS_Profiles"><profiles>
  <data_writer profile_name="unacked-1ms-heartbeat">
    <topic>
      <historyQos><kind>KEEP_LAST</kind><depth>4096</depth></historyQos>
      <resourceLimitsQos><max_samples>4096</max_samples><max_instances>1</max_instances>
        <max_samples_per_instance>4096</max_samples_per_instance></resourceLimitsQos>
    </topic>
    <qos><reliability><kind>RELIABLE</kind></reliability><durability><kind>VOLATILE</kind></durability></qos>
    <times><heartbeatPeriod><sec>0</sec><nanosec>1000000</nanosec></heartbeatPeriod></times>
  </data_writer>
</profiles></dds>
)";
  pmu::test::Child service(
      {PMU_SERVICE_PATH, "--bus", "sim", "--domain", std::to_string(domain), "--log-level", "warn"});
  auto dds = std::make_unique<dds::DdsContext>(domain, qos, "unacked-writer");
  ::unlink(qos.c_str());  // loaded
  DataWriter& w =
      dds->writer(dds->topic(topics::kCommand, TypeSupport(new pmu::v5::CommandPubSubType())), "unacked-1ms-heartbeat");
  ASSERT_TRUE(pmu::test::wait_until(
      [&] {
        PublicationMatchedStatus m;
        w.get_publication_matched_status(m);
        return m.current_count > 0;
      },
      20s))
      << "pmu-service's command reader never matched";
  ASSERT_TRUE(service.signal(SIGSTOP));
  pmu::v5::Command c;
  c.bus("nowhere");
  for (int i = 0; i < 4096; ++i) {
    c.request_id("unacked-" + std::to_string(i));
    ASSERT_TRUE(w.write(&c));
  }
  std::promise<void> destroyed;
  auto done = destroyed.get_future();
  std::thread([&dds, destroyed = std::move(destroyed)]() mutable {
    dds.reset();
    destroyed.set_value();
  }).detach();
  const bool prompt = done.wait_for(20s) == std::future_status::ready;
  (void)service.signal(SIGCONT);
  if (!prompt) {
    ADD_FAILURE() << "deleting a writer whose reader never acknowledged hung (Fast DDS 2.9's writer "
                     "destructor against its periodic heartbeat)";
    (void)service.stop(2s);
    std::fflush(stdout);
    std::_Exit(1);  // the hung thread holds Fast DDS's locks: a normal exit would hang too
  }
}

TEST(CrossProcess, PmuctlSaysWhenNoServiceIsThere) {
  // This process's own domain: no service runs on it (this test starts none).
  const std::string domain = std::to_string(pmu::test::exclusive_dds_domain());
  const auto r = run_capture(std::string(PMUCTL_PATH) + " --domain " + domain + " list --timeout 1", true);
  const std::string& err = r.out;
  EXPECT_EQ(r.status, 3);  // nothing answered
  EXPECT_NE(err.find("no pmu-service on domain " + domain), std::string::npos) << err;
}

TEST(CrossProcess, BadConfigIsRefusedWithItsLineBeforeAnythingStarts) {
  char path[] = "/tmp/pmu-bad-XXXXXX";
  const int fd = ::mkstemp(path);
  ASSERT_GE(fd, 0);
  const std::string yaml = "buses:\n  - interface: vcan0\n    devices:\n      - address: 70000\n";
  ASSERT_EQ(::write(fd, yaml.data(), yaml.size()), static_cast<ssize_t>(yaml.size()));
  ::close(fd);
  const auto r = run_capture(std::string(PMU_SERVICE_PATH) + " --config " + path, true);
  const std::string& err = r.out;
  ::unlink(path);
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(err.find(std::string(path) + ":4: address 70000 out of range 0..65534"), std::string::npos) << err;
}

}  // namespace
}  // namespace pmu::service::test
