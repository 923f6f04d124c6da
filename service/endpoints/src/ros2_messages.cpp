#include "pmu/endpoints/ros2_messages.hpp"

#include <algorithm>
#include <cmath>

#include "pmu/alarms/alarm_table.hpp"

namespace pmu::service {
namespace ros2_messages {

namespace Bs = sensor_msgs::msg::BatteryState_Constants;
namespace Ds = diagnostic_msgs::msg::DiagnosticStatus_Constants;
using alarms::Code;

float as_float(double v) { return static_cast<float>(v); }

std::uint8_t supply_status(double current, double soc_percent) {
  if (std::isnan(current)) return Bs::POWER_SUPPLY_STATUS_UNKNOWN;
  if (current >= kIdleCurrent) return Bs::POWER_SUPPLY_STATUS_CHARGING;
  if (current <= -kIdleCurrent) return Bs::POWER_SUPPLY_STATUS_DISCHARGING;
  if (soc_percent >= 99.5) return Bs::POWER_SUPPLY_STATUS_FULL;
  return Bs::POWER_SUPPLY_STATUS_NOT_CHARGING;
}

// What the battery's own alarms say of its health, the worst first: over-temperature, then a
// critical low (voltage or charge: the battery is spent), then any other fault of the pack.
// Nothing is known of the health of a battery that is not there.
std::uint8_t supply_health(bool present, HealthState health, const std::vector<AlarmReport>& active,
                           const std::vector<Code>& overheat, const std::vector<Code>& dead,
                           const std::vector<Code>& failure) {
  if (!present || health != HealthState::Online) return Bs::POWER_SUPPLY_HEALTH_UNKNOWN;
  auto any = [&](const std::vector<Code>& codes) {
    return std::any_of(active.begin(), active.end(), [&](const AlarmReport& a) {
      return alarm_active(a) && std::find(codes.begin(), codes.end(), a.code) != codes.end();
    });
  };
  if (any(overheat)) return Bs::POWER_SUPPLY_HEALTH_OVERHEAT;
  if (any(dead)) return Bs::POWER_SUPPLY_HEALTH_DEAD;
  if (any(failure)) return Bs::POWER_SUPPLY_HEALTH_UNSPEC_FAILURE;
  return Bs::POWER_SUPPLY_HEALTH_GOOD;
}

double slot(const BatteryState& b, std::string_view name) {
  const auto i = battery_slot(name);
  return i ? b.values[*i] : kUnknown;
}

void add(diagnostic_msgs::msg::DiagnosticStatus& s, std::string key, std::string value) {
  diagnostic_msgs::msg::KeyValue kv;
  kv.key(std::move(key));
  kv.value(std::move(value));
  s.values().push_back(std::move(kv));
}

std::string seconds_text(double s) {
  if (!(s >= 0)) return "never";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.1f", s);
  return buf;
}

}  // namespace ros2_messages

bool alarm_active(const AlarmReport& a) noexcept {
  return a.state == alarms::AlarmState::ActiveUnacknowledged || a.state == alarms::AlarmState::ActiveAcknowledged;
}

void set_stamp(std_msgs::msg::Header& header, std::chrono::system_clock::time_point t) {
  const auto ns = std::chrono::duration_cast<std::chrono::nanoseconds>(t.time_since_epoch()).count();
  const auto sec = ns >= 0 ? ns / 1'000'000'000 : (ns - 999'999'999) / 1'000'000'000;
  header.stamp().sec(static_cast<std::int32_t>(sec));
  header.stamp().nanosec(static_cast<std::uint32_t>(ns - sec * 1'000'000'000));
}

sensor_msgs::msg::BatteryState pmu_battery_message(const PmuBatteryView& v) {
  using namespace ros2_messages;
  sensor_msgs::msg::BatteryState m;
  set_stamp(m.header(), v.stamp);
  m.header().frame_id(v.frame_id);
  m.voltage(as_float(v.voltage));
  m.temperature(as_float(v.temperature));
  m.current(as_float(v.current));
  // The PMU counts charge since its power-up, not the battery's charge; nothing says its
  // capacity or state of charge.
  m.charge(as_float(kUnknown));
  m.capacity(as_float(kUnknown));
  m.design_capacity(as_float(kUnknown));
  m.percentage(as_float(kUnknown));
  m.power_supply_status(supply_status(v.current, kUnknown));
  const bool a = v.input != 'B';
  // An input with no battery reads about 0 V.
  const bool present = !std::isnan(v.voltage) && v.voltage >= 1.0;
  m.power_supply_health(supply_health(present, v.health, v.active,
                                      {a ? Code::BatteryAOverTemperature : Code::BatteryBOverTemperature},
                                      {a ? Code::BatteryACriticalVoltage : Code::BatteryBCriticalVoltage}, {}));
  m.power_supply_technology(Bs::POWER_SUPPLY_TECHNOLOGY_UNKNOWN);
  m.present(present);
  m.location(a ? "battery_a" : "battery_b");
  // The battery has no serial on the bus; the PMU that measures it has.
  m.serial_number(v.pmu_serial ? "pmu " + std::to_string(*v.pmu_serial) : "");
  return m;
}

sensor_msgs::msg::BatteryState bms_battery_message(const BmsView& v) {
  using namespace ros2_messages;
  sensor_msgs::msg::BatteryState m;
  set_stamp(m.header(), v.stamp);
  m.header().frame_id(v.frame_id);
  const double voltage = slot(v.values, "voltage");
  const double current = slot(v.values, "current");
  const double soc = slot(v.values, "state_of_charge");
  m.voltage(as_float(voltage));
  m.temperature(as_float(slot(v.values, "cell_temperature_high")));
  m.current(as_float(current));
  const double design = v.capacity_ah.value_or(kUnknown);
  m.charge(as_float(soc / 100.0 * design));
  m.capacity(as_float(kUnknown));  // the BMS does not report its full-charge capacity
  m.design_capacity(as_float(design));
  m.percentage(as_float(soc / 100.0));
  m.power_supply_status(supply_status(current, soc));
  m.power_supply_health(supply_health(!std::isnan(voltage), v.health, v.active, {Code::BmsOverTemperature},
                                      {Code::BmsCriticalSoc}, {Code::CellLow, Code::CellImbalance}));
  m.power_supply_technology(Bs::POWER_SUPPLY_TECHNOLOGY_UNKNOWN);
  m.present(!std::isnan(voltage));
  // The lowest cell number heard .. the highest (a BMS may count from 0 or from 1), NaN for
  // one between them not heard (the .msg's rule for an unknown cell).
  std::size_t first = v.cells.volts.size(), end = 0;
  for (std::size_t i = 0; i < v.cells.volts.size(); ++i)
    if (!std::isnan(v.cells.volts[i])) {
      first = std::min(first, i);
      end = i + 1;
    }
  std::vector<float> cells;
  for (std::size_t i = first; i < end; ++i) cells.push_back(as_float(v.cells.volts[i]));
  m.cell_voltage(std::move(cells));
  m.location(v.location);
  m.serial_number("");  // the BMS's document gives no serial number
  return m;
}

diagnostic_msgs::msg::DiagnosticStatus device_status(const DeviceDiagnosticsView& v) {
  using namespace ros2_messages;
  diagnostic_msgs::msg::DiagnosticStatus s;
  s.name(v.name);
  s.hardware_id(v.hardware_id);
  std::vector<const AlarmReport*> active;
  for (const auto& a : v.active)
    if (alarm_active(a)) active.push_back(&a);
  std::stable_sort(active.begin(), active.end(), [](const auto* x, const auto* y) {
    return x->severity == alarms::Severity::Critical && y->severity != alarms::Severity::Critical;
  });
  switch (v.health.state) {
    case HealthState::Unknown:
      s.level(Ds::STALE);
      s.message("no frame yet");
      break;
    case HealthState::Stale:
      s.level(Ds::STALE);
      s.message("stale: " + last_frame_text(v.health.last_frame_age));
      break;
    case HealthState::Offline:
      s.level(Ds::ERROR);
      s.message("offline: " + last_frame_text(v.health.last_frame_age));
      break;
    case HealthState::Online:
      if (active.empty()) {
        s.level(Ds::OK);
        s.message("online");
      } else {
        s.level(active.front()->severity == alarms::Severity::Critical ? Ds::ERROR : Ds::WARN);
        s.message(active.front()->message +
                  (active.size() > 1 ? " (+" + std::to_string(active.size() - 1) + " more)" : ""));
      }
      break;
  }
  add(s, "state", to_string(v.health.state));
  add(s, "last_frame_age_s", seconds_text(v.health.last_frame_age));
  add(s, "frames_received", std::to_string(v.health.frames_received));
  add(s, "frames_sent", std::to_string(v.health.frames_sent));
  add(s, "decode_errors", std::to_string(v.health.decode_errors));
  add(s, "bus_errors", std::to_string(v.health.bus_errors));
  add(s, "rx_dropped", std::to_string(v.health.rx_dropped));
  add(s, "timeouts", std::to_string(v.health.timeouts));
  add(s, "reconnects", std::to_string(v.health.reconnects));
  for (const auto& [key, value] : v.extra) add(s, key, value);
  std::string codes;
  for (const auto* a : active) codes += (codes.empty() ? "" : ",") + std::string(alarms::to_string(a->code));
  add(s, "active_alarms", codes);
  for (const auto* a : active)
    add(s, "alarm " + std::string(alarms::to_string(a->code)),
        std::string(alarms::to_string(a->severity)) + ", " + std::string(alarms::to_string(a->state)) + ": " +
            a->message);
  return s;
}

}  // namespace pmu::service
