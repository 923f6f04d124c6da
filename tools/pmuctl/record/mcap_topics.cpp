#include "pmuctl/record/mcap_topics.hpp"

#include <algorithm>

#include "pmu/idl/idl_text.hpp"
#include "pmu/idl/topics.hpp"

namespace pmu::tools {

const std::vector<RecordedTopic>& recorded_topics() {
  using namespace pmu::topics;
  namespace q = pmu::qos_profiles;
  namespace t = pmu::idl_text;
  // The low-rate topics repeat the full-rate samples and commands are the operators' own:
  // recorded only when named.
  static const std::vector<RecordedTopic> all = {
      {kVoltages, "pmu::Voltages", t::k_telemetry, q::kTelemetry, true},
      {kCurrents, "pmu::Currents", t::k_telemetry, q::kTelemetry, true},
      {kBatteryEnergy, "pmu::BatteryEnergy", t::k_telemetry, q::kTelemetry, true},
      {kTemperatures, "pmu::Temperatures", t::k_telemetry, q::kTelemetry, true},
      {kStatus, "pmu::Status", t::k_telemetry, q::kTelemetry, true},
      {kConfig, "pmu::Config", t::k_state, q::kState, true},
      {kInfo, "pmu::DeviceInfo", t::k_state, q::kState, true},
      {kHealth, "pmu::Health", t::k_state, q::kState, true},
      {kBattery, "pmu::Battery", t::k_canopen, q::kTelemetry, true},
      {kBatteryCells, "pmu::BatteryCells", t::k_canopen, q::kTelemetry, true},
      {kMppt, "pmu::Mppt", t::k_canopen, q::kTelemetry, true},
      {kLowRateVoltages, "pmu::Voltages", t::k_telemetry, q::kTelemetry, false},
      {kLowRateCurrents, "pmu::Currents", t::k_telemetry, q::kTelemetry, false},
      {kLowRateBatteryEnergy, "pmu::BatteryEnergy", t::k_telemetry, q::kTelemetry, false},
      {kLowRateTemperatures, "pmu::Temperatures", t::k_telemetry, q::kTelemetry, false},
      {kLowRateStatus, "pmu::Status", t::k_telemetry, q::kTelemetry, false},
      {kCommand, "pmu::Command", t::k_command, q::kCommand, false},
      {kCommandReply, "pmu::CommandReply", t::k_command, q::kCommand, false},
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
      error = "--topic " + n + " is not a topic of the contract (" + known + ")";
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
