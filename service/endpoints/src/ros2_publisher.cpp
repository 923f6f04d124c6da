#include "pmu/endpoints/ros2_publisher.hpp"

#include <spdlog/spdlog.h>

#include <fastdds/dds/publisher/qos/DataWriterQos.hpp>

#include "diagnostic_msgs/msg/DiagnosticArrayPubSubTypes.h"
#include "pmu/dds/zero_padded_type.hpp"
#include "pmu/endpoints/diagnostics_pace.hpp"
#include "pmu/endpoints/ros2_messages.hpp"
#include "pmu/session/log_throttle.hpp"
#include "sensor_msgs/msg/BatteryStatePubSubTypes.h"

namespace pmu::service {

using dds::Ros2Device;
using eprosima::fastdds::dds::DataWriter;
using eprosima::fastdds::dds::DataWriterQos;

namespace ros2_publisher {

using Key = std::tuple<std::string, std::uint16_t, DeviceKind>;
Key key_of(const DeviceKey& k) { return {k.bus, k.address, k.kind}; }
Key key_of(const AlarmReport& a) {
  const DeviceKind kind = a.source == alarms::DeviceKind::Battery ? DeviceKind::Battery
                          : a.source == alarms::DeviceKind::Mppt  ? DeviceKind::Mppt
                                                                  : DeviceKind::Pmu;
  return {a.bus, a.device, kind};
}
Ros2Device ros2_kind(DeviceKind k) {
  return k == DeviceKind::Battery ? Ros2Device::Bms : k == DeviceKind::Mppt ? Ros2Device::Mppt : Ros2Device::Pmu;
}

struct Device {
  HealthReport health;
  std::map<alarms::Code, AlarmReport> alarms;  // the newest report of each code
  // PMU
  codec::Voltages voltages;
  bool voltages_known = false;
  double current_a = kUnknown, current_b = kUnknown;
  double temperature_a = kUnknown, temperature_b = kUnknown;
  std::optional<std::uint16_t> serial;
  std::string firmware;
  DataWriter* battery_a = nullptr;
  DataWriter* battery_b = nullptr;
  // BMS
  BatteryCellsState cells;
  DataWriter* battery = nullptr;
  // A battery writer Fast DDS refused (DDS-Security permissions) is not asked for again with
  // every frame: refused once, said once.
  bool refused = false;

  std::vector<AlarmReport> active() const {
    std::vector<AlarmReport> out;
    for (const auto& [code, a] : alarms)
      if (alarm_active(a)) out.push_back(a);
    return out;
  }
};

}  // namespace ros2_publisher

// With the newest sample kept for a late (latched) joiner.
DataWriterQos ros2_writer_qos() {
  DataWriterQos q = eprosima::fastdds::dds::DATAWRITER_QOS_DEFAULT;
  q.reliability().kind = eprosima::fastdds::dds::RELIABLE_RELIABILITY_QOS;
  q.durability().kind = eprosima::fastdds::dds::TRANSIENT_LOCAL_DURABILITY_QOS;
  q.history().kind = eprosima::fastdds::dds::KEEP_LAST_HISTORY_QOS;
  q.history().depth = 1;
  q.ownership().kind = eprosima::fastdds::dds::SHARED_OWNERSHIP_QOS;
  return q;
}

struct Ros2Publisher::State {
  dds::DdsContext& dds;
  const transport::Clock& clock;
  dds::Ros2Settings settings;
  std::string vehicle;
  std::map<std::pair<std::string, std::uint8_t>, double> capacity_ah;  // (bus, node)
  std::mutex mutex;
  std::map<ros2_publisher::Key, ros2_publisher::Device> devices;
  DataWriter* diagnostics = nullptr;
  // Each device's newest status: every /diagnostics message carries them all (as ROS 2's
  // diagnostic_updater does), so the one message a KEEP_LAST 1 writer keeps for a late
  // subscriber holds every device's current status.
  std::map<ros2_publisher::Key, diagnostic_msgs::msg::DiagnosticStatus> statuses;
  DiagnosticsPace diagnostics_pace;
  std::uint64_t failures = 0;
  LogThrottle failure_reports{std::chrono::seconds(5)};

  State(dds::DdsContext& d, const transport::Clock& c, dds::Ros2Settings s, std::string v)
      : dds(d), clock(c), settings(std::move(s)), vehicle(std::move(v)) {}

  std::string name_of(const DeviceKey& k) const {
    return dds::ros2_status_name(settings.name_space, vehicle, k.bus, ros2_publisher::ros2_kind(k.kind), k.address);
  }
  DataWriter* battery_writer(const DeviceKey& k, const char* leaf) {
    const std::string ros_name =
        dds::ros2_device_namespace(settings.name_space, vehicle, k.bus, ros2_publisher::ros2_kind(k.kind), k.address) +
        "/" + leaf;
    try {
      auto& topic =
          dds.topic(dds::ros2_dds_topic(ros_name), dds::zero_padded<sensor_msgs::msg::BatteryStatePubSubType>());
      return &dds.default_partition_writer(topic, ros2_writer_qos());
    } catch (const dds::DdsError& e) {
      failed(ros_name.c_str(), e.what());
      return nullptr;
    }
  }
  void write(DataWriter* w, void* sample, const char* what) {
    if (!w) return;
    if (!w->write(sample)) failed(what, "the write failed");
  }
  void failed(const char* what, const char* why) {
    ++failures;
    if (failure_reports.allow(LogThrottle::Clock::now()))
      spdlog::warn("ROS 2: {}: {} ({} failure(s) so far)", what, why, failures);
  }
  void write_diagnostics() {
    diagnostic_msgs::msg::DiagnosticArray array;
    set_stamp(array.header(), clock.system_now());
    for (const auto& [key, status] : statuses) array.status().push_back(status);
    write(diagnostics, &array, "/diagnostics");
  }
  void write_pmu_batteries(const DeviceKey& k, ros2_publisher::Device& d, std::chrono::system_clock::time_point at) {
    if (!d.refused && !d.battery_a) d.battery_a = battery_writer(k, "battery_a");
    if (!d.refused && !d.battery_b) d.battery_b = battery_writer(k, "battery_b");
    d.refused = !d.battery_a || !d.battery_b;
    for (const char input : {'A', 'B'}) {
      PmuBatteryView v;
      v.input = input;
      if (d.voltages_known) v.voltage = input == 'A' ? d.voltages.battery_a : d.voltages.battery_b;
      v.current = input == 'A' ? d.current_a : d.current_b;
      v.temperature = input == 'A' ? d.temperature_a : d.temperature_b;
      v.pmu_serial = d.serial;
      v.health = d.health.state;
      v.active = d.active();
      v.stamp = at;
      v.frame_id = name_of(k);
      auto m = pmu_battery_message(v);
      write(input == 'A' ? d.battery_a : d.battery_b, &m, "battery");
    }
  }
  // `values` NaN throughout: the message of a device that is gone.
  void write_bms(const DeviceKey& k, ros2_publisher::Device& d, const BatteryState& values,
                 std::chrono::system_clock::time_point at) {
    if (!d.refused && !d.battery) d.battery = battery_writer(k, "battery");
    d.refused = !d.battery;
    BmsView v;
    v.values = values;
    v.cells = d.cells;
    if (auto it = capacity_ah.find({k.bus, static_cast<std::uint8_t>(k.address)}); it != capacity_ah.end())
      v.capacity_ah = it->second;
    v.health = d.health.state;
    v.active = d.active();
    v.stamp = at;
    v.frame_id = name_of(k);
    v.location = "bms node " + std::to_string(k.address);
    auto m = bms_battery_message(v);
    write(d.battery, &m, "battery");
  }
};

Ros2Publisher::Ros2Publisher(dds::DdsContext& dds, const dds::Ros2Settings& settings, std::string vehicle,
                             const std::vector<BusConfig>& buses, const transport::Clock& clock)
    : s_(std::make_unique<State>(dds, clock, settings, std::move(vehicle))) {
  for (const auto& b : buses)
    for (const auto& battery : b.batteries)
      if (battery.capacity_ah) s_->capacity_ah[{b.name, battery.node}] = *battery.capacity_ah;
  auto& topic = dds.topic("rt/diagnostics", dds::zero_padded<diagnostic_msgs::msg::DiagnosticArrayPubSubType>());
  s_->diagnostics = &dds.default_partition_writer(topic, ros2_writer_qos());
}

Ros2Publisher::~Ros2Publisher() = default;

std::uint64_t Ros2Publisher::write_failures() const {
  std::lock_guard<std::mutex> lock(s_->mutex);
  return s_->failures;
}

void Ros2Publisher::on_telemetry(const DeviceKey& key, const codec::PmuMessage& m,
                                 std::chrono::system_clock::time_point received) {
  std::lock_guard<std::mutex> lock(s_->mutex);
  auto& d = s_->devices[ros2_publisher::key_of(key)];
  if (const auto* c = std::get_if<codec::Currents>(&m.payload)) {
    d.current_a = c->battery_a;
    d.current_b = c->battery_b;
  } else if (const auto* t = std::get_if<codec::Temperatures>(&m.payload)) {
    d.temperature_a = t->battery_a;
    d.temperature_b = t->battery_b;
  } else if (const auto* v = std::get_if<codec::Voltages>(&m.payload)) {
    d.voltages = *v;
    d.voltages_known = true;
    s_->write_pmu_batteries(key, d, received);
  }
}

void Ros2Publisher::on_info(const DeviceKey& key, const InfoState& info) {
  std::lock_guard<std::mutex> lock(s_->mutex);
  auto& d = s_->devices[ros2_publisher::key_of(key)];
  d.serial = info.serial_number;
  if (info.firmware_known)
    d.firmware = std::to_string(info.firmware.firmware_major) + "." + std::to_string(info.firmware.firmware_minor);
}

void Ros2Publisher::on_health(const DeviceKey& key, const HealthReport& health) {
  std::lock_guard<std::mutex> lock(s_->mutex);
  auto& d = s_->devices[ros2_publisher::key_of(key)];
  d.health = health;
  DeviceDiagnosticsView v;
  v.name = s_->name_of(key);
  switch (key.kind) {
    case DeviceKind::Pmu:
      v.hardware_id =
          d.serial ? "pmu serial " + std::to_string(*d.serial) : "pmu at address " + std::to_string(key.address);
      if (!d.firmware.empty()) v.extra.emplace_back("firmware", d.firmware);
      if (d.serial) v.extra.emplace_back("serial_number", std::to_string(*d.serial));
      break;
    case DeviceKind::Battery: v.hardware_id = "bms node " + std::to_string(key.address); break;
    case DeviceKind::Mppt: v.hardware_id = "mppt device " + std::to_string(key.address); break;
  }
  v.extra.emplace(v.extra.begin(), "bus", key.bus);
  v.health = health;
  v.active = d.active();
  auto status = device_status(v);
  std::optional<ShownStatus> before;
  const auto k = ros2_publisher::key_of(key);
  if (auto it = s_->statuses.find(k); it != s_->statuses.end())
    before = ShownStatus{it->second.level(), it->second.message()};
  const bool write =
      s_->diagnostics_pace.on_report(before, ShownStatus{status.level(), status.message()}, s_->clock.steady_now());
  s_->statuses[k] = std::move(status);
  if (write) s_->write_diagnostics();
}

void Ros2Publisher::on_gone(const DeviceKey& key) {
  // A ROS 2 topic has no instance to dispose, and its writer keeps the last message for late
  // joiners: the last one says that nothing is there (not present, nothing measured).
  std::lock_guard<std::mutex> lock(s_->mutex);
  // Its status leaves /diagnostics: the address is no device any more.
  if (s_->statuses.erase(ros2_publisher::key_of(key)) && s_->diagnostics_pace.on_gone(s_->clock.steady_now()))
    s_->write_diagnostics();
  auto it = s_->devices.find(ros2_publisher::key_of(key));
  if (it == s_->devices.end()) return;
  ros2_publisher::Device fresh;
  fresh.battery_a = it->second.battery_a;
  fresh.battery_b = it->second.battery_b;
  fresh.battery = it->second.battery;
  fresh.refused = it->second.refused;
  fresh.health.state = HealthState::Offline;
  it->second = std::move(fresh);
  auto& d = it->second;
  const auto now = s_->clock.system_now();
  if (d.battery_a || d.battery_b) s_->write_pmu_batteries(key, d, now);
  if (d.battery) s_->write_bms(key, d, BatteryState{}, now);
}

void Ros2Publisher::on_battery(const DeviceKey& key, const BatteryState& battery,
                               std::chrono::system_clock::time_point newest) {
  std::lock_guard<std::mutex> lock(s_->mutex);
  s_->write_bms(key, s_->devices[ros2_publisher::key_of(key)], battery, newest);
}

void Ros2Publisher::on_battery_cells(const DeviceKey& key, const BatteryCellsState& cells,
                                     std::chrono::system_clock::time_point) {
  std::lock_guard<std::mutex> lock(s_->mutex);
  s_->devices[ros2_publisher::key_of(key)].cells = cells;
}

void Ros2Publisher::on_alarm(const AlarmReport& alarm) {
  if (alarm.source == alarms::DeviceKind::Bus) return;  // a bus is no device of /diagnostics
  std::lock_guard<std::mutex> lock(s_->mutex);
  s_->devices[ros2_publisher::key_of(alarm)].alarms[alarm.code] = alarm;
}

}  // namespace pmu::service
