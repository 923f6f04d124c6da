// ROS 2's view of the power system end to end (docs/interface.md section 11): pmu-service with
// `ros2: enabled` on the built-in simulator (a PMU with known battery voltages, a BMS at a known
// state of charge), read by a participant that does what a ROS 2 node does: topic "rt/...",
// ROS 2's type name, no partition, ROS 2's default reader QoS (RELIABLE, VOLATILE, KEEP_LAST
// 10), then a sensor-data (BEST_EFFORT) and a latched (TRANSIENT_LOCAL) reader. The readers
// keep the bytes as they came (RawSampleType); each is decoded with the generated type and
// checked against the simulator's settings. With PMU_ROS2_CAPTURE=FILE the bytes and the
// values decoded here go to FILE, one JSON line each, for Foxglove's own decoder
// (tests/mcap/ros2_decode.mjs, run by tests/mcap/ros2_decode_test.sh).
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/topic/Topic.hpp>
#include <fstream>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "../../tools/pmuctl/record/raw_sample_type.hpp"
#include "support/ros2_reader_qos.hpp"
#include "diagnostic_msgs/msg/DiagnosticArrayPubSubTypes.h"
#include "pmu/dds/dds_context.hpp"
#include "pmu/endpoints/ros2_publisher.hpp"
#include "sensor_msgs/msg/BatteryStatePubSubTypes.h"
#include "support/configured_service.hpp"
#include "support/domain.hpp"
#include "support/wait.hpp"

// A namespace of its own: the unity builds put this file in one translation unit with the
// other integration tests.
namespace ros2_dds_test {
namespace {

using namespace eprosima::fastdds::dds;
using namespace std::chrono_literals;
using Json = nlohmann::json;
using pmu::tools::RawSample;
using pmu::tools::RawSampleType;

const char* const kPmuA = "rt/test/uav1/sim/pmu_1/battery_a";
const char* const kPmuB = "rt/test/uav1/sim/pmu_1/battery_b";
const char* const kBms = "rt/test/uav1/sim/bms_2/battery";
const char* const kDiagnostics = "rt/diagnostics";

std::string config(int domain) {
  return "domain: " + std::to_string(domain) +
         "\nqos_file: " PMU_QOS_FILE
         "\nvehicle: uav1\nros2:\n  enabled: true\n  namespace: /test\n"
         "buses:\n  - interface: sim\n    devices:\n      - address: 1\n"
         "        sim: {battery_a_voltage: 24.6, battery_b_voltage: 0, serial: 4321}\n"
         "    batteries:\n      - node: 2\n        capacity_ah: 20\n"
         "        sim:\n          state_of_charge: 80\n"
         "          cell_voltages: [4.0, 4.0, 4.0, 4.0, 4.0, 4.0, 4.0, 4.0, 4.0, 4.0, 4.0, 4.0]\n";
}

DataReaderQos reader_qos(ReliabilityQosPolicyKind reliability, DurabilityQosPolicyKind durability) {
  return pmu::test::ros2_reader_qos(reliability, durability);
}
DataReaderQos ros2_default() { return reader_qos(RELIABLE_RELIABILITY_QOS, VOLATILE_DURABILITY_QOS); }

// A participant as a ROS 2 node's: default partition, no type object, the ROS 2 type names.
class Ros2Side {
 public:
  explicit Ros2Side(int domain) {
    participant_ = DomainParticipantFactory::get_instance()->create_participant(static_cast<DomainId_t>(domain),
                                                                                PARTICIPANT_QOS_DEFAULT);
    if (!participant_) return;
    battery_ = TypeSupport(new RawSampleType<sensor_msgs::msg::BatteryStatePubSubType>());
    diagnostics_ = TypeSupport(new RawSampleType<diagnostic_msgs::msg::DiagnosticArrayPubSubType>());
    battery_.register_type(participant_);
    diagnostics_.register_type(participant_);
    subscriber_ = participant_->create_subscriber(SUBSCRIBER_QOS_DEFAULT);
  }
  ~Ros2Side() {
    if (!participant_) return;
    participant_->delete_contained_entities();
    DomainParticipantFactory::get_instance()->delete_participant(participant_);
  }
  Ros2Side(const Ros2Side&) = delete;
  Ros2Side& operator=(const Ros2Side&) = delete;
  bool ready() const { return participant_ && subscriber_; }

  DataReader* reader(const std::string& topic, const DataReaderQos& qos) {
    Topic* t = topics_.count(topic) ? topics_[topic] : nullptr;
    if (!t) {
      const bool diag = topic == kDiagnostics;
      t = participant_->create_topic(topic, diag ? diagnostics_.get_type_name() : battery_.get_type_name(),
                                     TOPIC_QOS_DEFAULT);
      topics_[topic] = t;
    }
    return t ? subscriber_->create_datareader(t, qos) : nullptr;
  }

 private:
  DomainParticipant* participant_ = nullptr;
  Subscriber* subscriber_ = nullptr;
  TypeSupport battery_, diagnostics_;
  std::map<std::string, Topic*> topics_;
};

template <class PubSub>
bool decode(const RawSample& raw, typename PubSub::type& out) {
  eprosima::fastrtps::rtps::SerializedPayload_t payload(static_cast<std::uint32_t>(raw.bytes.size()));
  std::copy(raw.bytes.begin(), raw.bytes.end(), payload.data);
  payload.length = static_cast<std::uint32_t>(raw.bytes.size());
  PubSub type;
  return type.deserialize(&payload, &out);
}

// The next sample of `reader` for which `wanted` holds, within `timeout`.
template <class PubSub>
bool next(DataReader& reader, RawSample& raw, typename PubSub::type& out, std::chrono::milliseconds timeout,
          const std::function<bool(const typename PubSub::type&)>& wanted) {
  return pmu::test::wait_until(
      [&] {
        SampleInfo info;
        while (reader.take_next_sample(&raw, &info) == ReturnCode_t::RETCODE_OK)
          if (info.valid_data && decode<PubSub>(raw, out) && wanted(out)) return true;
        return false;
      },
      timeout, 10ms);
}

std::string hex(const std::vector<std::uint8_t>& bytes) {
  static const char* digits = "0123456789abcdef";
  std::string s;
  for (const auto b : bytes) {
    s += digits[b >> 4];
    s += digits[b & 15];
  }
  return s;
}

// NaN as JSON null, as the decoder's comparison expects.
Json number(float v) { return std::isnan(v) ? Json() : Json(v); }

Json battery_json(const sensor_msgs::msg::BatteryState& m) {
  Json cells = Json::array();
  for (const float c : m.cell_voltage()) cells.push_back(number(c));
  return {{"header",
           {{"stamp", {{"sec", m.header().stamp().sec()}, {"nanosec", m.header().stamp().nanosec()}}},
            {"frame_id", m.header().frame_id()}}},
          {"voltage", number(m.voltage())},
          {"temperature", number(m.temperature())},
          {"current", number(m.current())},
          {"charge", number(m.charge())},
          {"capacity", number(m.capacity())},
          {"design_capacity", number(m.design_capacity())},
          {"percentage", number(m.percentage())},
          {"power_supply_status", m.power_supply_status()},
          {"power_supply_health", m.power_supply_health()},
          {"power_supply_technology", m.power_supply_technology()},
          {"present", m.present()},
          {"cell_voltage", cells},
          {"cell_temperature", Json::array()},
          {"location", m.location()},
          {"serial_number", m.serial_number()}};
}

Json diagnostics_json(const diagnostic_msgs::msg::DiagnosticArray& a) {
  Json status = Json::array();
  for (const auto& s : a.status()) {
    Json values = Json::array();
    for (const auto& kv : s.values()) values.push_back({{"key", kv.key()}, {"value", kv.value()}});
    status.push_back({{"level", s.level()},
                      {"name", s.name()},
                      {"message", s.message()},
                      {"hardware_id", s.hardware_id()},
                      {"values", values}});
  }
  return {{"header",
           {{"stamp", {{"sec", a.header().stamp().sec()}, {"nanosec", a.header().stamp().nanosec()}}},
            {"frame_id", a.header().frame_id()}}},
          {"status", status}};
}

// PMU_ROS2_CAPTURE: one line per sample, {topic, type, cdr (hex), decoded}.
void capture(const std::string& topic, const char* type, const RawSample& raw, const Json& decoded) {
  const char* file = std::getenv("PMU_ROS2_CAPTURE");
  if (!file) return;
  std::ofstream out(file, std::ios::app);
  out << Json{{"topic", topic}, {"type", type}, {"cdr", hex(raw.bytes)}, {"decoded", decoded}}.dump() << "\n";
}

std::string value_of(const diagnostic_msgs::msg::DiagnosticStatus& s, const std::string& key) {
  for (const auto& kv : s.values())
    if (kv.key() == key) return kv.value();
  return "<absent>";
}

namespace Bs = sensor_msgs::msg::BatteryState_Constants;
namespace Ds = diagnostic_msgs::msg::DiagnosticStatus_Constants;

TEST(Ros2OverDds, BatteriesAndDiagnosticsReachARos2DefaultReaderWithTheSimulatorsValues) {
  const int domain = pmu::test::exclusive_dds_domain();
  pmu::test::ConfiguredService service(PMU_SERVICE_PATH, config(domain));
  Ros2Side ros2(domain);
  ASSERT_TRUE(ros2.ready());
  DataReader* pmu_a = ros2.reader(kPmuA, ros2_default());
  DataReader* pmu_b = ros2.reader(kPmuB, ros2_default());
  DataReader* bms = ros2.reader(kBms, ros2_default());
  DataReader* diagnostics = ros2.reader(kDiagnostics, ros2_default());
  ASSERT_TRUE(pmu_a && pmu_b && bms && diagnostics);
  using Battery = sensor_msgs::msg::BatteryStatePubSubType;
  using Diagnostics = diagnostic_msgs::msg::DiagnosticArrayPubSubType;
  RawSample raw;

  // PMU 1's battery A: the simulator's 24.6 V (0.1 V steps), its 25 degC sensor, the PMU's
  // serial once the service has read it. A sample goes out with each pmu/voltages frame, with
  // the newest current and temperature: NaN until their packets have come.
  sensor_msgs::msg::BatteryState a;
  ASSERT_TRUE(next<Battery>(*pmu_a, raw, a, 30s, [](const auto& m) {
    return !m.serial_number().empty() && !std::isnan(m.current()) && !std::isnan(m.temperature());
  })) << service.describe();
  capture(kPmuA, "sensor_msgs/msg/BatteryState", raw, battery_json(a));
  EXPECT_NEAR(a.voltage(), 24.6, 0.051);
  EXPECT_FLOAT_EQ(a.temperature(), 25.0f);
  EXPECT_FALSE(std::isnan(a.current()));
  EXPECT_TRUE(a.present());
  EXPECT_TRUE(std::isnan(a.percentage())) << "a PMU does not know a state of charge";
  EXPECT_EQ(a.power_supply_health(), Bs::POWER_SUPPLY_HEALTH_GOOD);
  EXPECT_EQ(a.header().frame_id(), "test/uav1/sim/pmu_1");
  EXPECT_EQ(a.location(), "battery_a");
  EXPECT_EQ(a.serial_number(), "pmu 4321");
  const auto now_s =
      std::chrono::duration_cast<std::chrono::seconds>(std::chrono::system_clock::now().time_since_epoch()).count();
  EXPECT_LT(std::abs(a.header().stamp().sec() - now_s), 30) << "the frame's receive time, on the wall clock";
  // The sign: the current of a battery charging reads positive, of one discharging negative.
  if (a.current() >= 0.1f) {
    EXPECT_EQ(a.power_supply_status(), Bs::POWER_SUPPLY_STATUS_CHARGING);
  } else if (a.current() <= -0.1f) {
    EXPECT_EQ(a.power_supply_status(), Bs::POWER_SUPPLY_STATUS_DISCHARGING);
  } else {
    EXPECT_EQ(a.power_supply_status(), Bs::POWER_SUPPLY_STATUS_NOT_CHARGING);
  }

  // Battery B reads 0 V: no battery there.
  sensor_msgs::msg::BatteryState b;
  ASSERT_TRUE(next<Battery>(*pmu_b, raw, b, 10s, [](const auto&) { return true; }));
  capture(kPmuB, "sensor_msgs/msg/BatteryState", raw, battery_json(b));
  EXPECT_FLOAT_EQ(b.voltage(), 0.0f);
  EXPECT_FALSE(b.present());
  EXPECT_EQ(b.location(), "battery_b");

  // The BMS: 12 cells at 4.0 V, 80 % (0.8 here) of 20 Ah, discharging into the load.
  sensor_msgs::msg::BatteryState m;
  ASSERT_TRUE(next<Battery>(*bms, raw, m, 30s,
                            [](const auto& x) {
                              bool cells = x.cell_voltage().size() == 12;
                              for (const float c : x.cell_voltage()) cells = cells && !std::isnan(c);
                              return cells && !std::isnan(x.percentage()) && !std::isnan(x.current());
                            }))
      << battery_json(m).dump() << "\n"
      << service.describe();
  capture(kBms, "sensor_msgs/msg/BatteryState", raw, battery_json(m));
  EXPECT_NEAR(m.voltage(), 48.0, 0.01);
  for (const float c : m.cell_voltage()) EXPECT_NEAR(c, 4.0, 0.001);
  EXPECT_NEAR(m.percentage(), 0.80, 0.02) << "0..1";
  EXPECT_NEAR(m.charge(), m.percentage() * 20, 1e-3);
  EXPECT_FLOAT_EQ(m.design_capacity(), 20.0f);
  EXPECT_LT(m.current(), 0) << "no sun: the load discharges the battery, negative as the .msg says";
  EXPECT_EQ(m.power_supply_status(), Bs::POWER_SUPPLY_STATUS_DISCHARGING);
  EXPECT_TRUE(m.present());
  EXPECT_EQ(m.header().frame_id(), "test/uav1/sim/bms_2");

  // /diagnostics: PMU 1 and the BMS each with a status, OK while online without alarms.
  std::map<std::string, diagnostic_msgs::msg::DiagnosticStatus> seen;
  std::map<std::string, int> reports;
  diagnostic_msgs::msg::DiagnosticArray array;
  bool captured = false;
  ASSERT_TRUE(next<Diagnostics>(*diagnostics, raw, array, 30s, [&](const auto& x) {
    for (const auto& s : x.status()) {
      seen[s.name()] = s;
      ++reports[s.name()];
    }
    if (!x.status().empty() && x.status()[0].name() == "test/uav1/sim/pmu_1" && x.status()[0].level() == Ds::OK &&
        value_of(x.status()[0], "firmware") != "<absent>" && !captured) {
      captured = true;
      capture(kDiagnostics, "diagnostic_msgs/msg/DiagnosticArray", raw, diagnostics_json(x));
    }
    return seen.count("test/uav1/sim/pmu_1") && seen.count("test/uav1/sim/bms_2") &&
           seen["test/uav1/sim/pmu_1"].level() == Ds::OK && reports["test/uav1/sim/pmu_1"] >= 2 &&
           value_of(seen["test/uav1/sim/pmu_1"], "firmware") != "<absent>";
  })) << service.describe();
  const auto& p = seen["test/uav1/sim/pmu_1"];
  EXPECT_EQ(p.message(), "online");
  EXPECT_EQ(p.hardware_id(), "pmu serial 4321");
  EXPECT_EQ(value_of(p, "state"), "ONLINE");
  EXPECT_EQ(value_of(p, "bus"), "sim");
  EXPECT_EQ(value_of(p, "serial_number"), "4321");
  EXPECT_NE(value_of(p, "frames_received"), "0");
  EXPECT_EQ(value_of(p, "active_alarms"), "");
  EXPECT_EQ(seen["test/uav1/sim/bms_2"].hardware_id(), "bms node 2");

  // ROS 2's other usual profiles match too: sensor data (BEST_EFFORT) and latched
  // (TRANSIENT_LOCAL, which gets the newest sample at once).
  DataReader* best_effort = ros2.reader(kPmuA, reader_qos(BEST_EFFORT_RELIABILITY_QOS, VOLATILE_DURABILITY_QOS));
  DataReader* latched = ros2.reader(kBms, reader_qos(RELIABLE_RELIABILITY_QOS, TRANSIENT_LOCAL_DURABILITY_QOS));
  ASSERT_TRUE(best_effort && latched);
  EXPECT_TRUE(next<Battery>(*best_effort, raw, a, 10s, [](const auto&) { return true; }));
  EXPECT_TRUE(next<Battery>(*latched, raw, m, 10s, [](const auto&) { return true; }));
  const auto log = service.describe();
  EXPECT_EQ(log.find("ROS 2: "), log.find("ROS 2: sensor_msgs/BatteryState")) << "a ROS 2 warning:\n" << log;
}

// A PMU that is gone (it moved to another CAN address): a latched subscriber that joins later
// gets, as each battery's last message, one that says nothing is there.
TEST(Ros2OverDds, AGoneDeviceLeavesANotPresentBatteryForLateJoiners) {
  const int domain = pmu::test::exclusive_dds_domain();
  pmu::dds::DdsContext service_side(domain, PMU_QOS_FILE, "pmu-service-ros2");
  pmu::dds::Ros2Settings settings;
  settings.enabled = true;
  const pmu::transport::SystemClock clock;
  pmu::service::Ros2Publisher publisher(service_side, settings, "uav1", {}, clock);
  const pmu::service::DeviceKey key{"can0", 1, pmu::service::DeviceKind::Pmu};
  pmu::service::HealthReport online;
  online.state = pmu::service::HealthState::Online;
  publisher.on_health(key, online);
  pmu::codec::PmuMessage voltages;
  voltages.payload = pmu::codec::Voltages{12, 28, 12, 6, 24.5, 24.1, 0};
  publisher.on_telemetry(key, voltages, std::chrono::system_clock::now());

  Ros2Side ros2(domain);
  ASSERT_TRUE(ros2.ready());
  using Battery = sensor_msgs::msg::BatteryStatePubSubType;
  RawSample raw;
  sensor_msgs::msg::BatteryState m;
  DataReader* before =
      ros2.reader("rt/uav1/can0/pmu_1/battery_a", reader_qos(RELIABLE_RELIABILITY_QOS, TRANSIENT_LOCAL_DURABILITY_QOS));
  ASSERT_NE(before, nullptr);
  ASSERT_TRUE(next<Battery>(*before, raw, m, 10s, [](const auto&) { return true; }));
  EXPECT_TRUE(m.present());
  EXPECT_FLOAT_EQ(m.voltage(), 24.5f);

  publisher.on_gone(key);
  DataReader* after =
      ros2.reader("rt/uav1/can0/pmu_1/battery_b", reader_qos(RELIABLE_RELIABILITY_QOS, TRANSIENT_LOCAL_DURABILITY_QOS));
  ASSERT_NE(after, nullptr);
  ASSERT_TRUE(next<Battery>(*after, raw, m, 10s, [](const auto&) { return true; }));
  EXPECT_FALSE(m.present());
  EXPECT_TRUE(std::isnan(m.voltage()));
  EXPECT_EQ(m.power_supply_health(), Bs::POWER_SUPPLY_HEALTH_UNKNOWN);
  EXPECT_EQ(m.power_supply_status(), Bs::POWER_SUPPLY_STATUS_UNKNOWN);
}

}  // namespace
}  // namespace ros2_dds_test
