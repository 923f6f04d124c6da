#pragma once
// Ros2Publisher: the StateSink that offers the power system to ROS 2 nodes in ROS 2's own
// names and types (docs/interface.md section 11), beside the contract's topics:
//   <device namespace>/battery_a, /battery_b   sensor_msgs/BatteryState of a PMU's inputs,
//                                               one per pmu/voltages sample
//   <device namespace>/battery                 sensor_msgs/BatteryState of a BMS, one per
//                                               pmu/battery sample
//   /diagnostics                               diagnostic_msgs/DiagnosticArray: every
//                                               device's status, at once on a change of
//                                               level or message, else at most once a second
// as ROS 2 nodes see them: DDS topics "rt/...", type names sensor_msgs::msg::dds_::..._, no
// key, the default partition, RELIABLE + TRANSIENT_LOCAL + KEEP_LAST 1 (a default, a
// sensor-data and a latched subscriber all match), no type object. Only pmu-service writes
// them: it owns the bus.
//
// Lifetime: `dds` must outlive the publisher (it owns the writers' participant), and so must
// `clock` (the /diagnostics pace and the stamps of the messages it writes without a frame's
// time). The publisher must outlive every BusWorker that writes through it.
// Threads: every StateSink member from any bus worker thread (one mutex); a device's topics
// are created at its first sample, under that mutex, so no other code may call the
// context's topic() or writer() functions after the bus workers start.

#include <chrono>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <tuple>
#include <vector>

#include <fastdds/dds/publisher/qos/DataWriterQos.hpp>

#include "pmu/config/config.hpp"
#include "pmu/dds/dds_context.hpp"
#include "pmu/session/state_sink.hpp"
#include "pmu/transport/clock.hpp"

namespace pmu::service {

// The QoS of every ROS 2 writer (above): what ROS 2 subscribers of every usual profile match.
eprosima::fastdds::dds::DataWriterQos ros2_writer_qos();

class Ros2Publisher final : public StateSink {
 public:
  // `buses`: the configured batteries' capacity_ah. Creates /diagnostics's writer; throws
  // DdsError at start-up.
  Ros2Publisher(dds::DdsContext& dds, const dds::Ros2Settings& settings, std::string vehicle,
                const std::vector<BusConfig>& buses, const transport::Clock& clock);
  ~Ros2Publisher() override;

  void on_telemetry(const DeviceKey& key, const codec::PmuMessage& message,
                    std::chrono::system_clock::time_point received) override;
  void on_config(const DeviceKey&, const ConfigState&) override {}
  void on_info(const DeviceKey& key, const InfoState& info) override;
  void on_health(const DeviceKey& key, const HealthReport& health) override;
  void on_gone(const DeviceKey& key) override;
  void on_battery(const DeviceKey& key, const BatteryState& battery,
                  std::chrono::system_clock::time_point newest) override;
  void on_battery_cells(const DeviceKey& key, const BatteryCellsState& cells,
                        std::chrono::system_clock::time_point newest) override;
  void on_mppt(const DeviceKey&, const MpptState&, std::chrono::system_clock::time_point) override {}
  void on_alarm(const AlarmReport& alarm) override;
  void on_readiness(const ReadinessReport&) override {}
  void on_energy(const DeviceKey&, const energy::Figures&, std::chrono::system_clock::time_point) override {}
  void on_bms_energy(const DeviceKey&, const energy::BmsFigures&, std::chrono::system_clock::time_point) override {}

  // Writes Fast DDS refused (logged at most every few seconds too). Any thread.
  std::uint64_t write_failures() const;

 private:
  struct State;
  std::unique_ptr<State> s_;
};

}  // namespace pmu::service
