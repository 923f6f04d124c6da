#include "pmuctl/record/mcap_topics.hpp"

#include <algorithm>

#include "pmu/idl/idl_text.hpp"
#include "pmu/idl/topics.hpp"

namespace pmu::tools {

const std::vector<RecordedTopic>& recorded_topics() {
  using namespace pmu::topics;
  namespace q = pmu::qos_profiles;
  namespace t = pmu::idl_text;
  // The low-rate topics repeat the full-rate samples, commands, acknowledgements and role moves
  // are the operators' own, and pmu/role is a hot-standby pair's (ten samples a second from
  // each instance): recorded only when named.
  static const std::vector<RecordedTopic> all = {
      {kVoltages, "pmu::v5::Voltages", t::k_Voltages, q::kTelemetry, true},
      {kCurrents, "pmu::v5::Currents", t::k_Currents, q::kTelemetry, true},
      {kBatteryEnergy, "pmu::v5::BatteryEnergy", t::k_BatteryEnergy, q::kTelemetry, true},
      {kTemperatures, "pmu::v5::Temperatures", t::k_Temperatures, q::kTelemetry, true},
      {kStatus, "pmu::v5::Status", t::k_Status, q::kTelemetry, true},
      {kConfig, "pmu::v5::Config", t::k_Config, q::kState, true},
      {kInfo, "pmu::v5::DeviceInfo", t::k_DeviceInfo, q::kState, true},
      {kHealth, "pmu::v5::Health", t::k_Health, q::kState, true},
      {kBattery, "pmu::v5::Battery", t::k_Battery, q::kTelemetry, true},
      {kBatteryCells, "pmu::v5::BatteryCells", t::k_BatteryCells, q::kTelemetry, true},
      {kMppt, "pmu::v5::Mppt", t::k_Mppt, q::kTelemetry, true},
      {kAlarms, "pmu::v5::Alarm", t::k_Alarm, q::kAlarms, true},
      {kReadiness, "pmu::v5::Readiness", t::k_Readiness, q::kState, true},
      {kEnergy, "pmu::v5::Energy", t::k_Energy, q::kState, true},
      {kBmsEnergy, "pmu::v5::BmsEnergy", t::k_BmsEnergy, q::kState, true},
      {kBaseline, "pmu::v5::Baseline", t::k_Baseline, q::kState, true},
      {kLowRateVoltages, "pmu::v5::Voltages", t::k_Voltages, q::kTelemetry, false},
      {kLowRateCurrents, "pmu::v5::Currents", t::k_Currents, q::kTelemetry, false},
      {kLowRateBatteryEnergy, "pmu::v5::BatteryEnergy", t::k_BatteryEnergy, q::kTelemetry, false},
      {kLowRateTemperatures, "pmu::v5::Temperatures", t::k_Temperatures, q::kTelemetry, false},
      {kLowRateStatus, "pmu::v5::Status", t::k_Status, q::kTelemetry, false},
      {kLowRateHealth, "pmu::v5::Health", t::k_Health, q::kState, false},
      {kCommand, "pmu::v5::Command", t::k_Command, q::kCommand, false},
      {kCommandReply, "pmu::v5::CommandReply", t::k_CommandReply, q::kCommand, false},
      {kAlarmAck, "pmu::v5::AlarmAck", t::k_AlarmAck, q::kCommand, false},
      {kAlarmAckReply, "pmu::v5::AlarmAckReply", t::k_AlarmAckReply, q::kCommand, false},
      {kRole, "pmu::v5::RoleHeartbeat", t::k_RoleHeartbeat, q::kRole, false},
      {kRoleMove, "pmu::v5::RoleMove", t::k_RoleMove, q::kCommand, false},
      {kRoleMoveReply, "pmu::v5::RoleMoveReply", t::k_RoleMoveReply, q::kCommand, false},
  };
  return all;
}

const RecordedTopic* find_recorded_topic(std::string_view name) {
  for (const auto& t : recorded_topics()) {
    const std::string_view full = t.topic;
    if (name == full || (full.substr(0, 4) == "pmu/" && name == full.substr(4))) return &t;
  }
  return nullptr;
}

std::vector<const RecordedTopic*> select_topics(const std::vector<std::string>& names, std::string& error) {
  std::vector<const RecordedTopic*> topics;
  for (const auto& n : names) {
    const auto* t = find_recorded_topic(n);
    if (!t) {
      std::string known;
      for (const auto& k : recorded_topics()) known += (known.empty() ? "" : ", ") + std::string(k.topic);
      error = "--topic " + n + " is not a topic of the contract (" + known +
              ") nor a ROS 2 topic of the service (/diagnostics, /<vehicle>/<bus>/pmu_<a>/battery_a, ...)";
      return {};
    }
    if (std::find(topics.begin(), topics.end(), t) == topics.end()) topics.push_back(t);
  }
  if (topics.empty())
    for (const auto& t : recorded_topics())
      if (t.by_default) topics.push_back(&t);
  return topics;
}

}  // namespace pmu::tools
