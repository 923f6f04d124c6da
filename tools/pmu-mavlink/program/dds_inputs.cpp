#include "program/dds_inputs.hpp"

#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>

#include "pmu/dds/baseline_sample.hpp"
#include "pmu/idl/alarmsPubSubTypes.h"
#include "pmu/idl/canopenPubSubTypes.h"
#include "pmu/idl/energyPubSubTypes.h"
#include "pmu/idl/guarded_type.hpp"
#include "pmu/idl/statePubSubTypes.h"
#include "pmu/idl/telemetryPubSubTypes.h"
#include "pmu/idl/topics.hpp"

namespace pmu::mavlink_bridge {

namespace {

using eprosima::fastdds::dds::DataReader;
using eprosima::fastdds::dds::SampleInfo;
using eprosima::fastdds::dds::TypeSupport;

template <class PubSub>
DataReader* reader(pmu::dds::DdsContext& dds, const char* topic, const char* profile) {
  return &dds.reader(dds.topic(topic, TypeSupport(new pmu::idl::Guarded<PubSub>())), profile);
}

// Every valid sample waiting on `r`, handed to `use`; `gone` for a disposed instance's key.
template <class T, class Use, class Gone>
void take_all(DataReader* r, Use use, Gone gone) {
  T sample;
  SampleInfo info;
  while (r->take_next_sample(&sample, &info) == ReturnCode_t::RETCODE_OK) {
    if (info.valid_data) {
      use(sample);
    } else if (info.instance_state != eprosima::fastdds::dds::ALIVE_INSTANCE_STATE) {
      // A disposed or unregistered instance carries its key only: read it into a sample.
      T key;
      if (r->get_key_value(&key, info.instance_handle) == ReturnCode_t::RETCODE_OK) gone(key);
    }
  }
}

template <class T>
DeviceKey pmu_key(const T& s) {
  return {s.bus().to_string(), s.address()};
}

template <class T>
DeviceKey bms_key(const T& s) {
  return {s.bus().to_string(), s.node()};
}

}  // namespace

DdsInputs::DdsInputs(pmu::dds::DdsContext& dds)
    : voltages_(reader<pmu::v5::VoltagesPubSubType>(dds, topics::kVoltages, qos_profiles::kTelemetry)),
      currents_(reader<pmu::v5::CurrentsPubSubType>(dds, topics::kCurrents, qos_profiles::kTelemetry)),
      battery_energy_(reader<pmu::v5::BatteryEnergyPubSubType>(dds, topics::kBatteryEnergy, qos_profiles::kTelemetry)),
      temperatures_(reader<pmu::v5::TemperaturesPubSubType>(dds, topics::kTemperatures, qos_profiles::kTelemetry)),
      status_(reader<pmu::v5::StatusPubSubType>(dds, topics::kStatus, qos_profiles::kTelemetry)),
      energy_(reader<pmu::v5::EnergyPubSubType>(dds, topics::kEnergy, qos_profiles::kState)),
      health_(reader<pmu::v5::HealthPubSubType>(dds, topics::kHealth, qos_profiles::kState)),
      config_(reader<pmu::v5::ConfigPubSubType>(dds, topics::kConfig, qos_profiles::kState)),
      battery_(reader<pmu::v5::BatteryPubSubType>(dds, topics::kBattery, qos_profiles::kTelemetry)),
      cells_(reader<pmu::v5::BatteryCellsPubSubType>(dds, topics::kBatteryCells, qos_profiles::kTelemetry)),
      bms_energy_(reader<pmu::v5::BmsEnergyPubSubType>(dds, topics::kBmsEnergy, qos_profiles::kState)),
      alarm_reader_(reader<pmu::v5::AlarmPubSubType>(dds, topics::kAlarms, qos_profiles::kAlarms)),
      readiness_reader_(reader<pmu::v5::ReadinessPubSubType>(dds, topics::kReadiness, qos_profiles::kState)) {}

void DdsInputs::take() {
  auto none = [](const auto&) {};
  take_all<pmu::v5::Voltages>(
      voltages_, [&](const auto& s) { pmus_[pmu_key(s)].voltages = s; }, none);
  take_all<pmu::v5::Currents>(
      currents_, [&](const auto& s) { pmus_[pmu_key(s)].currents = s; }, none);
  take_all<pmu::v5::BatteryEnergy>(
      battery_energy_, [&](const auto& s) { pmus_[pmu_key(s)].battery_energy = s; }, none);
  take_all<pmu::v5::Temperatures>(
      temperatures_, [&](const auto& s) { pmus_[pmu_key(s)].temperatures = s; }, none);
  take_all<pmu::v5::Status>(
      status_, [&](const auto& s) { pmus_[pmu_key(s)].status = s; }, none);
  take_all<pmu::v5::Energy>(
      energy_, [&](const auto& s) { pmus_[pmu_key(s)].energy = s; }, none);
  take_all<pmu::v5::Battery>(
      battery_, [&](const auto& s) { batteries_[bms_key(s)].battery = s; }, none);
  take_all<pmu::v5::BatteryCells>(
      cells_, [&](const auto& s) { batteries_[bms_key(s)].cells = s; }, none);
  take_all<pmu::v5::BmsEnergy>(
      bms_energy_, [&](const auto& s) { batteries_[bms_key(s)].energy = s; }, none);
  // Health decides what is shown as live (docs/safety.md H7); a device whose health instance
  // is disposed (it moved to another address, interface.md 2.6) is dropped with its values.
  take_all<pmu::v5::Health>(
      health_,
      [&](const pmu::v5::Health& h) {
        const DeviceKey key{h.bus().to_string(), h.address()};
        const bool online = h.state() == pmu::v5::ONLINE;
        if (h.kind() == pmu::v5::KIND_PMU) pmus_[key].online = online;
        if (h.kind() == pmu::v5::KIND_BATTERY) batteries_[key].online = online;
      },
      [&](const pmu::v5::Health& h) {
        const DeviceKey key{h.bus().to_string(), h.address()};
        if (h.kind() == pmu::v5::KIND_PMU) pmus_.erase(key);
        if (h.kind() == pmu::v5::KIND_BATTERY) batteries_.erase(key);
      });
  // A PMU's settings as its service read them (interface.md 4.6); its parameters
  // (program/operations.cpp) are known while this and its ONLINE health say so.
  take_all<pmu::v5::Config>(
      config_, [&](const pmu::v5::Config& c) { configs_[pmu_key(c)] = pmu::service::settings_of(c); },
      [&](const pmu::v5::Config& c) { configs_.erase(pmu_key(c)); });
  alarms_.clear();
  take_all<pmu::v5::Alarm>(
      alarm_reader_,
      [&](const pmu::v5::Alarm& a) {
        alarms_.push_back({a, false});
      },
      [&](const pmu::v5::Alarm& a) {
        alarms_.push_back({a, true});
      });
  take_all<pmu::v5::Readiness>(
      readiness_reader_, [&](const pmu::v5::Readiness& r) { readiness_ = r; }, none);
}

}  // namespace pmu::mavlink_bridge
