#pragma once
// The contract topics pmu-mavlink reads (interface.md 1.2, 1.4, 1.6, 1.7, 1.8), taken into
// one PmuView per PMU and one BmsView per BMS, each PMU's pmu/config as its settings, and the
// alarm and readiness samples since the last take. Readers only: the commands that change a
// device go through the service (service_link.hpp).
// Lifetime: the DdsContext outlives this. Threads: take() on the program's loop only (the
// readers are polled, no listener runs on Fast DDS's threads).
#include <fastdds/dds/subscriber/DataReader.hpp>

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <tuple>
#include <vector>

#include "pmu/baseline/settings.hpp"
#include "pmu/dds/dds_context.hpp"
#include "pmu/idl/alarms.h"
#include "telemetry/device_views.hpp"

namespace pmu::mavlink_bridge {

using DeviceKey = std::tuple<std::string, std::uint16_t>;  // bus, address (PMU) or node (BMS)

struct AlarmSample {
  pmu::v5::Alarm alarm;
  bool disposed = false;  // the instance went away (its device is gone)
};

class DdsInputs {
 public:
  explicit DdsInputs(pmu::dds::DdsContext& dds);

  // Takes every sample waiting. Views keep the latest of each topic.
  void take();

  const std::map<DeviceKey, PmuView>& pmus() const noexcept { return pmus_; }
  const std::map<DeviceKey, BmsView>& batteries() const noexcept { return batteries_; }
  // Each PMU's latest pmu/config sample as its settings; a disposed instance is gone.
  const std::map<DeviceKey, pmu::baseline::Settings>& configs() const noexcept { return configs_; }
  // The alarm samples taken by the last take(), in order.
  const std::vector<AlarmSample>& alarms() const noexcept { return alarms_; }
  // The newest readiness sample, and whether the last take() brought one.
  const std::optional<pmu::v5::Readiness>& readiness() const noexcept { return readiness_; }

 private:
  eprosima::fastdds::dds::DataReader* voltages_;
  eprosima::fastdds::dds::DataReader* currents_;
  eprosima::fastdds::dds::DataReader* battery_energy_;
  eprosima::fastdds::dds::DataReader* temperatures_;
  eprosima::fastdds::dds::DataReader* status_;
  eprosima::fastdds::dds::DataReader* energy_;
  eprosima::fastdds::dds::DataReader* health_;
  eprosima::fastdds::dds::DataReader* config_;
  eprosima::fastdds::dds::DataReader* battery_;
  eprosima::fastdds::dds::DataReader* cells_;
  eprosima::fastdds::dds::DataReader* bms_energy_;
  eprosima::fastdds::dds::DataReader* alarm_reader_;
  eprosima::fastdds::dds::DataReader* readiness_reader_;

  std::map<DeviceKey, PmuView> pmus_;
  std::map<DeviceKey, BmsView> batteries_;
  std::map<DeviceKey, pmu::baseline::Settings> configs_;
  std::vector<AlarmSample> alarms_;
  std::optional<pmu::v5::Readiness> readiness_;
};

}  // namespace pmu::mavlink_bridge
