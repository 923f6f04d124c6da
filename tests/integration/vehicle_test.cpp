// Several vehicles on one DDS domain (docs/interface.md section 7.1): three in-process services
// (the unnamed vehicle, uav1, uav2), each with a simulated PMU under the same keys sim0/1, and
// ground stations that read every vehicle or address one.
#include <gtest/gtest.h>

#include <chrono>
#include <fastdds/dds/core/status/PublicationMatchedStatus.hpp>
#include <fastdds/dds/core/status/SubscriptionMatchedStatus.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <map>
#include <memory>
#include <set>
#include <thread>
#include <vector>

#include "pmu/dds_settings/vehicle.hpp"
#include "pmu/dds/dds_context.hpp"
#include "pmu/idl/command.h"
#include "pmu/idl/commandPubSubTypes.h"
#include "pmu/idl/state.h"
#include "pmu/idl/statePubSubTypes.h"
#include "pmu/idl/telemetry.h"
#include "pmu/idl/telemetryPubSubTypes.h"
#include "pmu/idl/topics.hpp"
#include "support/answered.hpp"
#include "support/domain.hpp"
#include "support/in_process_service.hpp"
#include "support/wait.hpp"

namespace pmu::service {
namespace {

using namespace eprosima::fastdds::dds;
using namespace std::chrono_literals;

using VehicleService = pmu::test::InProcessService;

std::unique_ptr<VehicleService> vehicle_service(int domain, const std::string& vehicle) {
  VehicleService::Options o;
  o.vehicle = vehicle;
  return std::make_unique<VehicleService>(domain, o);
}

// A ground station: reads in `read` partitions, writes commands in `write` partitions.
struct Ground {
  Ground(int domain, const std::string& name, dds::Partitions partitions)
      : dds(domain, "", name, {}, dds::Transport::Default, {}, std::move(partitions)),
        writer(dds.writer(dds.topic(topics::kCommand, TypeSupport(new pmu::v5::CommandPubSubType())),
                          qos_profiles::kCommand)),
        replies(dds.reader(dds.topic(topics::kCommandReply, TypeSupport(new pmu::v5::CommandReplyPubSubType())),
                           qos_profiles::kCommand)),
        configs(
            dds.reader(dds.topic(topics::kConfig, TypeSupport(new pmu::v5::ConfigPubSubType())), qos_profiles::kState)),
        voltages(dds.reader(dds.topic(topics::kVoltages, TypeSupport(new pmu::v5::VoltagesPubSubType())),
                            qos_profiles::kTelemetry)) {}

  std::size_t command_readers() {
    PublicationMatchedStatus p;
    writer.get_publication_matched_status(p);
    return static_cast<std::size_t>(p.current_count);
  }
  std::string send(const std::string& id, const std::string& vehicle, double payload_voltage) {
    pmu::v5::Command c;
    c.request_id(id);
    c.vehicle(vehicle);
    c.bus("sim0");
    c.address(1);
    c.kind(pmu::v5::SET_PARAMETER);
    c.parameter("payload_voltage");
    c.value(payload_voltage);
    EXPECT_TRUE(writer.write(&c));
    return id;
  }
  // Replies so far, by request id, but those to probes.
  std::vector<pmu::v5::CommandReply> take_replies() {
    std::vector<pmu::v5::CommandReply> out;
    pmu::v5::CommandReply r;
    SampleInfo info;
    while (replies.take_next_sample(&r, &info) == ReturnCode_t::RETCODE_OK)
      if (info.valid_data) {
        if (r.request_id().to_string().rfind(kProbe, 0) == 0)
          probes_answered = true;
        else
          out.push_back(r);
      }
    return out;
  }
  // Until `vehicle`'s service has answered this station (support/answered.hpp says why
  // matching on this side is not enough); what the probe reads changes nothing.
  bool answered_by(const std::string& vehicle) {
    pmu::v5::Command c;
    c.request_id(std::string(kProbe) + vehicle);
    c.vehicle(vehicle);
    c.bus("sim0");
    c.address(1);
    c.kind(pmu::v5::GET_SERIAL);
    std::vector<pmu::v5::CommandReply> others;
    const bool ok = pmu::test::until_answered([&] { writer.write(&c); },
                                              [&] {
                                                for (auto& r : take_replies()) others.push_back(r);
                                                return probes_answered;
                                              },
                                              30s);
    EXPECT_TRUE(others.empty()) << "replies to more than the probe";
    return ok;
  }
  // What this station's discovery knows, for a failure message: a vehicle whose samples never
  // come is either unmatched (discovery never reported its writers) or matched and silent.
  std::string discovery_text() {
    SubscriptionMatchedStatus c, v;
    configs.get_subscription_matched_status(c);
    voltages.get_subscription_matched_status(v);
    return "; its pmu/config reader matched " + std::to_string(c.current_count) + " writers, its pmu/voltages reader " +
           std::to_string(v.current_count) + "; discovery reported " +
           std::to_string(dds.remote_writers().writers_of(topics::kConfig).size()) + " pmu/config writers and " +
           std::to_string(
               dds.remote_writers().participants_without_writer(dds::kServiceParticipantName, topics::kConfig)) +
           " pmu-service participants without one";
  }
  static constexpr const char* kProbe = "probe-";
  bool probes_answered = false;

  // Replies as soon as at least one came, or none after `timeout`.
  std::vector<pmu::v5::CommandReply> first_replies(std::chrono::seconds timeout) {
    std::vector<pmu::v5::CommandReply> got;
    pmu::test::wait_until(
        [&] {
          for (auto& r : take_replies()) got.push_back(r);
          return !got.empty();
        },
        timeout);
    return got;
  }

  dds::DdsContext dds;
  DataWriter& writer;
  DataReader& replies;
  DataReader& configs;
  DataReader& voltages;
};

// Not the simulator's default (12.0 V), so a set that executes changes the stored value.
constexpr double kNewPayloadVoltage = 23.0;

dds::Partitions every_vehicle() { return {dds::vehicle_partitions(""), dds::every_vehicle_partitions()}; }
dds::Partitions only(const std::string& v) { return {dds::vehicle_partitions(v), dds::vehicle_partitions(v)}; }

class Vehicles : public ::testing::Test {
 protected:
  void SetUp() override {
    domain_ = pmu::test::exclusive_dds_domain();
    for (const char* v : {"", "uav1", "uav2"}) services_[v] = vehicle_service(domain_, v);
  }
  // Waits until `g` has the command readers it should match, and every service has told its
  // state (the start-up reading is over: a set is answered against a known configuration).
  void ready(Ground& g, std::size_t command_readers) {
    ASSERT_TRUE(pmu::test::wait_until([&] { return g.command_readers() == command_readers; }, 20s))
        << "matched " << g.command_readers() << " command readers, expected " << command_readers;
    Ground watcher(domain_, "watcher", every_vehicle());
    std::set<std::string> configured;
    ASSERT_TRUE(pmu::test::wait_until(
        [&] {
          pmu::v5::Config c;
          SampleInfo i;
          while (watcher.configs.take_next_sample(&c, &i) == ReturnCode_t::RETCODE_OK)
            if (i.valid_data) configured.insert(c.vehicle().to_string());
          return configured.size() == services_.size();
        },
        30s))
        << "the watcher got pmu/config from " << configured.size() << " of " << services_.size()
        << " vehicles: " << seen_text(configured) << watcher.discovery_text();
  }
  static std::string seen_text(const std::set<std::string>& vehicles) {
    std::string out;
    for (const auto& v : vehicles) out += (out.empty() ? "" : ", ") + (v.empty() ? std::string("(unnamed)") : v);
    return out.empty() ? "none" : out;
  }
  int domain_ = 0;
  std::map<std::string, std::unique_ptr<VehicleService>> services_;
};

TEST_F(Vehicles, AGroundStationWithDefaultSettingsSeesEveryVehicleAndWhichSampleIsWhose) {
  Ground g(domain_, "ground-all", every_vehicle());
  std::set<std::string> config_vehicles, voltage_vehicles;
  ASSERT_TRUE(pmu::test::wait_until(
      [&] {
        pmu::v5::Config c;
        SampleInfo i;
        while (g.configs.take_next_sample(&c, &i) == ReturnCode_t::RETCODE_OK)
          if (i.valid_data && c.bus().to_string() == "sim0" && c.address() == 1)
            config_vehicles.insert(c.vehicle().to_string());
        pmu::v5::Voltages v;
        while (g.voltages.take_next_sample(&v, &i) == ReturnCode_t::RETCODE_OK)
          if (i.valid_data) voltage_vehicles.insert(v.vehicle().to_string());
        return config_vehicles.size() == 3 && voltage_vehicles.size() == 3;
      },
      30s))
      << "pmu/config from " << seen_text(config_vehicles) << ", pmu/voltages from " << seen_text(voltage_vehicles)
      << g.discovery_text();
  EXPECT_EQ(config_vehicles, (std::set<std::string>{"", "uav1", "uav2"}));
  EXPECT_EQ(voltage_vehicles, (std::set<std::string>{"", "uav1", "uav2"}));
  // Same bus and address, three instances: the state a late joiner gets holds all three.
  Ground late(domain_, "ground-late", every_vehicle());
  std::set<std::string> late_vehicles;
  EXPECT_TRUE(pmu::test::wait_until(
      [&] {
        pmu::v5::Config c;
        SampleInfo i;
        while (late.configs.take_next_sample(&c, &i) == ReturnCode_t::RETCODE_OK)
          if (i.valid_data) late_vehicles.insert(c.vehicle().to_string());
        return late_vehicles.size() == 3;
      },
      10s));
}

TEST_F(Vehicles, ACommandReachesOnlyItsVehicleWhichGivesTheOneReply) {
  Ground g(domain_, "ground-uav1", only("uav1"));
  ready(g, 1);  // its partition holds uav1's command reader alone
  ASSERT_TRUE(g.answered_by("uav1"));
  const auto before_unnamed = services_[""]->parameter(codec::Parameter::PayloadVoltage);
  const auto before_uav1 = services_["uav1"]->parameter(codec::Parameter::PayloadVoltage);
  const auto before_uav2 = services_["uav2"]->parameter(codec::Parameter::PayloadVoltage);
  g.send("to-uav1", "uav1", kNewPayloadVoltage);
  auto replies = g.first_replies(20s);
  ASSERT_FALSE(replies.empty()) << "no reply";
  std::this_thread::sleep_for(500ms);  // a second reply, which must not come, would be here by now
  for (auto& r : g.take_replies()) replies.push_back(r);
  ASSERT_EQ(replies.size(), 1u);
  EXPECT_EQ(replies[0].vehicle().to_string(), "uav1");
  EXPECT_EQ(replies[0].result(), pmu::v5::COMPLETED) << replies[0].reason();
  EXPECT_NE(services_["uav1"]->parameter(codec::Parameter::PayloadVoltage), before_uav1);
  EXPECT_EQ(services_[""]->parameter(codec::Parameter::PayloadVoltage), before_unnamed);
  EXPECT_EQ(services_["uav2"]->parameter(codec::Parameter::PayloadVoltage), before_uav2);
  EXPECT_EQ(services_["uav2"]->commands.counters().received, 0u) << "uav2's service received uav1's command";
  EXPECT_EQ(services_[""]->commands.counters().received, 0u);
}

TEST_F(Vehicles, TheUnnamedVehicleIsCommandedAsBeforeVehiclesExisted) {
  Ground g(domain_, "ground-unnamed", only(""));
  ready(g, 1);
  ASSERT_TRUE(g.answered_by(""));
  const auto before = services_[""]->parameter(codec::Parameter::PayloadVoltage);
  g.send("to-unnamed", "", kNewPayloadVoltage);
  auto replies = g.first_replies(20s);
  ASSERT_FALSE(replies.empty()) << "no reply";
  EXPECT_EQ(replies[0].vehicle().to_string(), "");
  EXPECT_EQ(replies[0].result(), pmu::v5::COMPLETED) << replies[0].reason();
  EXPECT_NE(services_[""]->parameter(codec::Parameter::PayloadVoltage), before);
}

// A command in uav2's partition that names uav1, and one written in partition "*" (which
// matches every vehicle's command reader) that names uav2: neither is executed or answered.
TEST_F(Vehicles, ACommandNotAddressedToThisVehicleAloneIsNeitherExecutedNorAnswered) {
  Ground wrong_name(domain_, "ground-wrong-name", only("uav2"));
  Ground wildcard(domain_, "ground-wildcard", {{"*"}, dds::every_vehicle_partitions()});
  ready(wrong_name, 1);
  ready(wildcard, 2);  // uav1's and uav2's: "*" matches every named partition
  const auto before = services_["uav2"]->parameter(codec::Parameter::PayloadVoltage);
  wrong_name.send("named-uav1-sent-to-uav2", "uav1", kNewPayloadVoltage);
  wildcard.send("wildcard-for-uav2", "uav2", kNewPayloadVoltage);
  auto& uav1 = services_["uav1"]->endpoint;
  auto& uav2 = services_["uav2"]->endpoint;
  // uav2 gets both (one names another vehicle, one comes from "*"); uav1 gets the "*" one,
  // which names uav2.
  ASSERT_TRUE(pmu::test::wait_until([&] { return uav2.not_ours() == 2 && uav1.not_ours() == 1; }, 20s))
      << "uav1 ignored " << uav1.not_ours() << ", uav2 ignored " << uav2.not_ours() << "; received: unnamed "
      << services_[""]->commands.counters().received << ", uav1 " << services_["uav1"]->commands.counters().received
      << ", uav2 " << services_["uav2"]->commands.counters().received;
  std::this_thread::sleep_for(500ms);  // a reply, which must not come, would be here by now
  EXPECT_TRUE(wrong_name.take_replies().empty());
  EXPECT_TRUE(wildcard.take_replies().empty());
  EXPECT_EQ(services_["uav2"]->parameter(codec::Parameter::PayloadVoltage), before);
  EXPECT_EQ(services_["uav2"]->commands.counters().received, 0u);
  EXPECT_EQ(services_["uav1"]->commands.counters().received, 0u);
}

// A ground station in "*" already on the domain when the service starts: its writer is
// discovered while the service is still starting, before the command endpoint exists. Its
// partitions must still be known (the participant records writers from its creation), so
// its command, which names the service's own vehicle, is refused like any from "*".
TEST(VehiclesEarlyPeer, AWildcardWriterFoundBeforeTheCommandEndpointExistedIsStillRefused) {
  const int domain = pmu::test::exclusive_dds_domain();
  Ground wildcard(domain, "ground-wildcard-early", {{"*"}, dds::every_vehicle_partitions()});
  VehicleService::Options o;
  o.vehicle = "uav1";
  o.endpoint_delay = 3s;
  VehicleService uav1(domain, o);
  ASSERT_TRUE(pmu::test::wait_until([&] { return wildcard.command_readers() == 1; }, 20s));
  // The start-up reading must be over, so that a command let through would be executed.
  ASSERT_TRUE(pmu::test::wait_until(
      [&] {
        pmu::v5::Config c;
        SampleInfo i;
        return wildcard.configs.take_next_sample(&c, &i) == ReturnCode_t::RETCODE_OK && i.valid_data;
      },
      30s));
  const auto before = uav1.parameter(codec::Parameter::PayloadVoltage);
  wildcard.send("early-wildcard", "uav1", kNewPayloadVoltage);
  ASSERT_TRUE(pmu::test::wait_until([&] { return uav1.endpoint.not_ours() == 1; }, 20s))
      << "not refused; received " << uav1.commands.counters().received;
  std::this_thread::sleep_for(500ms);  // a reply, which must not come, would be here by now
  EXPECT_TRUE(wildcard.take_replies().empty());
  EXPECT_EQ(uav1.parameter(codec::Parameter::PayloadVoltage), before);
  EXPECT_EQ(uav1.commands.counters().received, 0u);
}

}  // namespace
}  // namespace pmu::service
