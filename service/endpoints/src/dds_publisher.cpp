#include "pmu/endpoints/dds_publisher.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <string_view>
#include <mutex>
#include <set>
#include <tuple>
#include <utility>

#include "pmu/dds_settings/capacity.hpp"
#include "pmu/config/low_rate.hpp"
#include "pmu/dds/baseline_sample.hpp"
#include "pmu/dds/no_value.hpp"
#include "pmu/dds/telemetry_samples.hpp"
#include "pmu/dds/zero_padded_type.hpp"
#include "pmu/idl/alarms.h"
#include "pmu/idl/alarmsPubSubTypes.h"
#include "pmu/idl/canopen.h"
#include "pmu/idl/canopenPubSubTypes.h"
#include "pmu/idl/command.h"
#include "pmu/idl/commandPubSubTypes.h"
#include "pmu/idl/energy.h"
#include "pmu/idl/energyPubSubTypes.h"
#include "pmu/idl/state.h"
#include "pmu/idl/statePubSubTypes.h"
#include "pmu/idl/telemetry.h"
#include "pmu/idl/telemetryPubSubTypes.h"
#include "pmu/idl/topics.hpp"
#include "pmu/session/log_throttle.hpp"

namespace pmu::service {
namespace {

using namespace eprosima::fastdds::dds;
using codec::Parameter;

eprosima::fastrtps::Time_t dds_time(std::chrono::system_clock::time_point t) {
  const auto ns = std::chrono::duration_cast<std::chrono::nanoseconds>(t.time_since_epoch()).count();
  eprosima::fastrtps::Time_t out;
  out.seconds = static_cast<std::int32_t>(ns / 1000000000);
  out.nanosec = static_cast<std::uint32_t>(ns % 1000000000);
  return out;
}

constexpr auto kReportInterval = std::chrono::seconds(5);

const char* why(ReturnCode_t rc) {
  if (rc == ReturnCode_t::RETCODE_OUT_OF_RESOURCES) return "out of resources";
  if (rc == ReturnCode_t::RETCODE_TIMEOUT) return "timeout";
  if (rc == ReturnCode_t::RETCODE_NOT_ENABLED) return "writer not enabled";
  if (rc == ReturnCode_t::RETCODE_BAD_PARAMETER) return "bad parameter";
  if (rc == ReturnCode_t::RETCODE_PRECONDITION_NOT_MET) return "precondition not met";
  return "error";
}


// The battery's node or the MPPT's device id fits an octet (node 1..127, device 0..7).
std::uint8_t octet_id(const DeviceKey& k) { return static_cast<std::uint8_t>(k.address & 0xFF); }

// A CANopen state's value by its contract name: NaN when not received, in every field (the
// integer and boolean values too: a 0 would plot as a value the device never sent).
template <std::size_t N>
class Values {
 public:
  Values(const CanOpenValues<N>& state, const CanOpenValue (&table)[N]) : state_(state), table_(table) {}
  float real(std::string_view name) const { return static_cast<float>(exact(name)); }
  // A 32-bit value as sent: a double holds each exactly, a float does not.
  double exact(std::string_view name) const {
    const auto i = slot(name);
    return i < N && state_.received(i) ? state_.values[i] : std::numeric_limits<double>::quiet_NaN();
  }
  // A flag as 1 or 0 (any non-zero value the device sent is set).
  float flag(std::string_view name) const {
    const double v = exact(name);
    return std::isnan(v) ? kNoValue : (v != 0 ? 1.0f : 0.0f);
  }

 private:
  std::size_t slot(std::string_view name) const {
    for (std::size_t i = 0; i < N; ++i)
      if (table_[i].name == name) return i;
    return N;
  }
  const CanOpenValues<N>& state_;
  const CanOpenValue (&table_)[N];
};

}  // namespace

struct DdsPublisher::Writers {
  explicit Writers(std::chrono::milliseconds low_rate_period) : low_rate(low_rate_period) {}
  std::string vehicle;
  // pmu/low_rate/*, in packet order 0x00..0x04; null when the low-rate topics are off.
  std::array<DataWriter*, LowRateGate::kPackets> low{};
  LowRateGate low_rate;
  DataWriter* voltages;
  DataWriter* currents;
  DataWriter* energy;
  DataWriter* temperatures;
  DataWriter* status;
  DataWriter* config;
  DataWriter* info;
  DataWriter* health;
  // pmu/low_rate/health: null when the low-rate topics are off. `low_health_last`: the state
  // and bus state last written there, per device.
  DataWriter* low_health = nullptr;
  std::map<std::tuple<std::string, DeviceKind, std::uint16_t>, std::pair<HealthState, transport::BusState>>
      low_health_last;
  // Null when the service serves no battery or MPPT (not offered).
  DataWriter* battery = nullptr;
  DataWriter* battery_cells = nullptr;
  DataWriter* mppt = nullptr;
  // Null when the service's DDS-Security permissions do not grant pmu/alarms (made before
  // it existed): the service runs without it rather than not at all.
  DataWriter* alarms = nullptr;
  DataWriter* readiness = nullptr;
  DataWriter* derived_energy = nullptr;  // pmu/energy (`energy` is pmu/battery_energy)
  DataWriter* baseline = nullptr;
  // pmu/bms_energy: null too when the service serves no battery or MPPT, as pmu/battery.
  DataWriter* bms_energy = nullptr;
  // Bus workers run in threads of their own and share these writers and the rest below.
  std::mutex mutex;
  std::set<std::tuple<std::string, DeviceKind, std::uint16_t>> admitted;
  // PMUs (bus, address) configured with a `baseline:`; every other PMU's pmu/baseline
  // instance is disposed when it is first admitted.
  std::set<std::pair<std::string, std::uint16_t>> with_baseline;
  LogThrottle failure_reports{kReportInterval};
  LogThrottle refusal_reports{kReportInterval};
};

DdsPublisher::DdsPublisher(dds::DdsContext& dds, std::chrono::milliseconds telemetry_deadline, std::string vehicle,
                           std::chrono::milliseconds low_rate_period,
                           std::optional<std::chrono::milliseconds> canopen_deadline)
    : w_(std::make_unique<Writers>(low_rate_period)) {
  w_->vehicle = std::move(vehicle);
  auto telemetry = [&](const char* name, TypeSupport type, std::chrono::milliseconds deadline) {
    DataWriter& w = dds.writer(dds.topic(name, type), qos_profiles::kTelemetry);
    DataWriterQos q = w.get_qos();
    const auto ns = std::chrono::duration_cast<std::chrono::nanoseconds>(deadline).count();
    q.deadline().period = eprosima::fastrtps::Duration_t(static_cast<std::int32_t>(ns / 1000000000),
                                                         static_cast<std::uint32_t>(ns % 1000000000));
    if (w.set_qos(q) != ReturnCode_t::RETCODE_OK)
      throw dds::DdsError(std::string("cannot set the DEADLINE of ") + name);
    return &w;
  };
  auto state = [&](const char* name, TypeSupport type) {
    return &dds.writer(dds.topic(name, type), qos_profiles::kState);
  };
  const auto d = telemetry_deadline;
  w_->voltages = telemetry(topics::kVoltages, dds::zero_padded<pmu::v5::VoltagesPubSubType>(), d);
  w_->currents = telemetry(topics::kCurrents, dds::zero_padded<pmu::v5::CurrentsPubSubType>(), d);
  w_->energy = telemetry(topics::kBatteryEnergy, dds::zero_padded<pmu::v5::BatteryEnergyPubSubType>(), d);
  w_->temperatures = telemetry(topics::kTemperatures, dds::zero_padded<pmu::v5::TemperaturesPubSubType>(), d);
  w_->status = telemetry(topics::kStatus, dds::zero_padded<pmu::v5::StatusPubSubType>(), d);
  if (w_->low_rate.enabled()) {
    // The same types on topics of their own: a reader of one never matches the other's writer.
    const auto low = std::max(telemetry_deadline, 3 * low_rate_period);
    w_->low[0] = telemetry(topics::kLowRateVoltages, dds::zero_padded<pmu::v5::VoltagesPubSubType>(), low);
    w_->low[1] = telemetry(topics::kLowRateCurrents, dds::zero_padded<pmu::v5::CurrentsPubSubType>(), low);
    w_->low[2] = telemetry(topics::kLowRateBatteryEnergy, dds::zero_padded<pmu::v5::BatteryEnergyPubSubType>(), low);
    w_->low[3] = telemetry(topics::kLowRateTemperatures, dds::zero_padded<pmu::v5::TemperaturesPubSubType>(), low);
    w_->low[4] = telemetry(topics::kLowRateStatus, dds::zero_padded<pmu::v5::StatusPubSubType>(), low);
  }
  if (canopen_deadline) {
    const auto cd = *canopen_deadline;
    w_->battery = telemetry(topics::kBattery, dds::zero_padded<pmu::v5::BatteryPubSubType>(), cd);
    w_->battery_cells = telemetry(topics::kBatteryCells, dds::zero_padded<pmu::v5::BatteryCellsPubSubType>(), cd);
    w_->mppt = telemetry(topics::kMppt, dds::zero_padded<pmu::v5::MpptPubSubType>(), cd);
  }
  w_->config = state(topics::kConfig, dds::zero_padded<pmu::v5::ConfigPubSubType>());
  w_->info = state(topics::kInfo, dds::zero_padded<pmu::v5::DeviceInfoPubSubType>());
  w_->health = state(topics::kHealth, dds::zero_padded<pmu::v5::HealthPubSubType>());
  // Topics newer than the DDS-Security permissions a service may have been given: without a
  // grant the service runs without them rather than not at all.
  auto newer = [&](const char* name, TypeSupport type, const char* profile) -> DataWriter* {
    try {
      return &dds.writer(dds.topic(name, type), profile);
    } catch (const dds::DdsError& e) {
      if (!dds.secure()) throw;
      spdlog::error(
          "{} is not published: {}; the DDS-Security permissions were made before it existed "
          "(deploy/security/make_pki.sh makes them with it)",
          name, e.what());
      return nullptr;
    }
  };
  w_->alarms = newer(topics::kAlarms, dds::zero_padded<pmu::v5::AlarmPubSubType>(), qos_profiles::kAlarms);
  w_->readiness = newer(topics::kReadiness, dds::zero_padded<pmu::v5::ReadinessPubSubType>(), qos_profiles::kState);
  w_->derived_energy = newer(topics::kEnergy, dds::zero_padded<pmu::v5::EnergyPubSubType>(), qos_profiles::kState);
  w_->baseline = newer(topics::kBaseline, dds::zero_padded<pmu::v5::BaselinePubSubType>(), qos_profiles::kState);
  if (w_->low_rate.enabled())
    w_->low_health = newer(topics::kLowRateHealth, dds::zero_padded<pmu::v5::HealthPubSubType>(), qos_profiles::kState);
  if (canopen_deadline)
    w_->bms_energy = newer(topics::kBmsEnergy, dds::zero_padded<pmu::v5::BmsEnergyPubSubType>(), qos_profiles::kState);
}

DdsPublisher::~DdsPublisher() = default;

void DdsPublisher::clear_histories() {
  std::lock_guard<std::mutex> lock(w_->mutex);
  std::vector<DataWriter*> writers{w_->voltages,   w_->currents,  w_->energy,         w_->temperatures,
                                   w_->status,     w_->config,    w_->info,           w_->health,
                                   w_->low_health, w_->battery,   w_->battery_cells,  w_->mppt,
                                   w_->alarms,     w_->readiness, w_->derived_energy, w_->bms_energy};
  writers.insert(writers.end(), w_->low.begin(), w_->low.end());
  for (auto* writer : writers) {
    if (writer == nullptr) continue;
    // Not logged: Fast DDS 2.9.1 refuses to clear some writers' histories (pmu/alarms' and
    // pmu/low_rate/*'s were seen) without saying why; what stays is at most each instance's last
    // sample, which the new owner's overwrites in every reader that gets both.
    std::size_t removed = 0;
    (void)writer->clear_history(&removed);
  }
  // What pmu/low_rate/health last said is gone with its history: the next owner writes anew.
  w_->low_health_last.clear();
}

bool DdsPublisher::admit(const DeviceKey& key) {
  const auto id = std::make_tuple(key.bus, key.kind, key.address);
  if (w_->admitted.count(id)) return true;
  if (w_->admitted.size() < dds::kMaxDevicesPerService) {
    w_->admitted.insert(id);
    if (key.kind == DeviceKind::Pmu && !w_->with_baseline.count({key.bus, key.address})) dispose_baseline(key);
    return true;
  }
  const auto refused = refused_.fetch_add(1, std::memory_order_relaxed) + 1;
  failures_.fetch_add(1, std::memory_order_relaxed);
  if (const auto held = w_->refusal_reports.allow(LogThrottle::Clock::now()))
    spdlog::error(
        "{}/{}: not published on DDS: this service already publishes {} PMUs, the capacity its DDS "
        "writers are sized for (kMaxDevicesPerService); {} sample(s) of PMUs over capacity not "
        "published so far{}",
        key.bus, key.address, dds::kMaxDevicesPerService, refused,
        *held ? " (" + std::to_string(*held) + " such messages held back)" : std::string());
  return false;
}

void DdsPublisher::count(bool ok, const char* topic, const DeviceKey& key, const char* reason) {
  if (ok) {
    written_.fetch_add(1, std::memory_order_relaxed);
    return;
  }
  const auto total = failures_.fetch_add(1, std::memory_order_relaxed) + 1;
  if (const auto held = w_->failure_reports.allow(LogThrottle::Clock::now()))
    spdlog::warn("{}/{}: DDS write to {} failed ({}); {} sample(s) not published so far{}", key.bus, key.address, topic,
                 reason, total,
                 *held ? " (" + std::to_string(*held) + " failures not logged since the last message)" : std::string());
}

void DdsPublisher::count_failed_write(const char* topic, const DeviceKey& key, const char* why) {
  std::lock_guard<std::mutex> lock(w_->mutex);
  count(false, topic, key, why);
}

// Without this, a reader could not tell a PMU that has no baseline from one whose baseline
// has not reached it yet: samples of different topics arrive independently. The disposed
// instance is kept for late joiners like a written one (state profile).
void DdsPublisher::dispose_baseline(const DeviceKey& key) {
  if (w_->baseline == nullptr) return;
  pmu::v5::Baseline s;
  s.vehicle(w_->vehicle);
  s.bus(key.bus);
  s.address(key.address);
  const InstanceHandle_t handle = w_->baseline->register_instance(&s);
  const ReturnCode_t rc =
      handle == HANDLE_NIL ? ReturnCode_t::RETCODE_OUT_OF_RESOURCES : w_->baseline->dispose(&s, handle);
  // A failure is a sample not published; a disposal is no sample of the PMU's own.
  if (rc != ReturnCode_t::RETCODE_OK) count(false, topics::kBaseline, key, why(rc));
}

void DdsPublisher::publish_baselines(const std::vector<BusConfig>& buses) {
  std::lock_guard<std::mutex> lock(w_->mutex);
  for (const auto& b : buses)
    for (const auto& d : b.devices)
      if (d.baseline) w_->with_baseline.insert({b.name, d.address});
  for (const auto& b : buses)
    for (const auto& d : b.devices) {
      const DeviceKey key{b.name, d.address, DeviceKind::Pmu};
      if (!d.baseline) {
        admit(key);  // says at once that it has none
        continue;
      }
      if (!admit(key)) continue;
      auto s = baseline_sample(w_->vehicle, b.name, d.address, d.baseline_file, d.baseline);
      write_at(w_->baseline, &s, key, std::chrono::system_clock::now());
    }
}

void DdsPublisher::on_telemetry(const DeviceKey& key, const codec::PmuMessage& m,
                                std::chrono::system_clock::time_point received) {
  const auto ts = dds_time(received);
  std::lock_guard<std::mutex> lock(w_->mutex);
  if (!admit(key)) return;
  auto write_one = [&](DataWriter* w, void* sample) {
    const ReturnCode_t rc = w->write_w_timestamp(sample, HANDLE_NIL, ts);
    count(rc == ReturnCode_t::RETCODE_OK, w->get_topic()->get_name().c_str(), key, why(rc));
  };
  // `packet`: 0x00..0x04, the index of the low-rate writer.
  auto write = [&](DataWriter* w, void* sample, std::size_t packet) {
    write_one(w, sample);
    if (w_->low_rate.due(key.bus, key.address, packet, received)) write_one(w_->low[packet], sample);
  };
  if (const auto* v = std::get_if<codec::Voltages>(&m.payload)) {
    pmu::v5::Voltages s;
    set_key(s, w_->vehicle, key);
    fill(s, *v);
    write(w_->voltages, &s, 0);
  } else if (const auto* c = std::get_if<codec::Currents>(&m.payload)) {
    pmu::v5::Currents s;
    set_key(s, w_->vehicle, key);
    fill(s, *c);
    write(w_->currents, &s, 1);
  } else if (const auto* e = std::get_if<codec::BatteryEnergy>(&m.payload)) {
    pmu::v5::BatteryEnergy s;
    set_key(s, w_->vehicle, key);
    fill(s, *e);
    write(w_->energy, &s, 2);
  } else if (const auto* t = std::get_if<codec::Temperatures>(&m.payload)) {
    pmu::v5::Temperatures s;
    set_key(s, w_->vehicle, key);
    fill(s, *t);
    write(w_->temperatures, &s, 3);
  } else if (const auto* st = std::get_if<codec::Status>(&m.payload)) {
    pmu::v5::Status s;
    set_key(s, w_->vehicle, key);
    fill(s, *st);
    write(w_->status, &s, 4);
  }
}

void DdsPublisher::on_config(const DeviceKey& key, const ConfigState& c) {
  pmu::v5::Config s;
  set_key(s, w_->vehicle, key);
  auto raw8 = [&](Parameter p) {
    return static_cast<std::uint8_t>(c.raw[static_cast<std::size_t>(p)].value_or(0) & 0xFF);
  };
  s.avionics_voltage(idl_float(c.value(Parameter::AvionicsVoltage)));
  s.payload_voltage(idl_float(c.value(Parameter::PayloadVoltage)));
  s.servo_voltage(idl_float(c.value(Parameter::ServoVoltage)));
  s.battery_voltage(idl_float(c.value(Parameter::BatteryVoltage)));
  s.packet_period(idl_float(c.value(Parameter::PacketPeriod)));
  s.packets_streamed(raw8(Parameter::PacketsStreamed));
  s.temperature_offset(raw8(Parameter::TemperatureOffset));
  s.upper_temperature_limit(raw8(Parameter::UpperTemperatureLimit));
  s.power_up_state(raw8(Parameter::PowerUpState));
  s.cranking_time(idl_float(c.value(Parameter::CrankingTime)));
  s.can_address(
      static_cast<std::uint16_t>(c.raw[static_cast<std::size_t>(Parameter::CanAddress)].value_or(key.address)));
  s.outputs(c.outputs.value_or(0));
  s.generation_enabled(c.generation_enabled.value_or(false));
  std::lock_guard<std::mutex> lock(w_->mutex);
  if (!admit(key)) return;
  // DataWriter::write(void*) returns bool in Fast DDS 2.x, without a reason.
  count(w_->config->write(&s), topics::kConfig, key, "write returned false");
}

void DdsPublisher::on_info(const DeviceKey& key, const InfoState& i) {
  pmu::v5::DeviceInfo s;
  set_key(s, w_->vehicle, key);
  s.serial_number(i.serial_number);
  s.firmware_major(i.firmware.firmware_major);
  s.firmware_minor(i.firmware.firmware_minor);
  s.build_year(i.firmware.build_year);
  s.build_month(i.firmware.build_month);
  s.build_day(i.firmware.build_day);
  for (const auto feature : codec::kAllFeatures)
    if (codec::supports(i.firmware.version(), feature))
      s.features().emplace_back(std::string(codec::feature_name(feature)));
  std::lock_guard<std::mutex> lock(w_->mutex);
  if (!admit(key)) return;
  count(w_->info->write(&s), topics::kInfo, key, "write returned false");
}

void DdsPublisher::on_health(const DeviceKey& key, const HealthReport& h) {
  pmu::v5::Health s;
  set_key(s, w_->vehicle, key);
  s.kind(static_cast<pmu::v5::DeviceKind>(static_cast<int>(key.kind)));
  s.state(static_cast<pmu::v5::HealthState>(static_cast<int>(h.state)));
  s.bus_state(static_cast<pmu::v5::BusState>(static_cast<int>(h.bus_state)));
  s.last_frame_age(frame_age_or_nan(h.last_frame_age));  // NaN, never -1: never heard
  s.frames_received(h.frames_received);
  s.frames_sent(h.frames_sent);
  s.decode_errors(h.decode_errors);
  s.bus_errors(h.bus_errors);
  s.rx_dropped(h.rx_dropped);
  s.timeouts(h.timeouts);
  s.reconnects(h.reconnects);
  std::lock_guard<std::mutex> lock(w_->mutex);
  if (!admit(key)) return;
  s.publish_failures(failures_.load(std::memory_order_relaxed));
  count(w_->health->write(&s), topics::kHealth, key, "write returned false");
  if (w_->low_health == nullptr) return;
  // The low-rate copy changes with the state alone: a watcher on a slow link sees OFFLINE the
  // moment the service decides it (docs/safety.md H7) without a sample a second for the age.
  const auto id = std::make_tuple(key.bus, key.kind, key.address);
  const auto now = std::make_pair(h.state, h.bus_state);
  const auto last = w_->low_health_last.find(id);
  if (last != w_->low_health_last.end() && last->second == now) return;
  w_->low_health_last[id] = now;
  count(w_->low_health->write(&s), topics::kLowRateHealth, key, "write returned false");
}

void DdsPublisher::on_gone(const DeviceKey& key) {
  std::lock_guard<std::mutex> lock(w_->mutex);
  if (!w_->admitted.erase(std::make_tuple(key.bus, key.kind, key.address))) return;  // never published
  // A writer that never wrote this key answers PRECONDITION_NOT_MET: nothing to dispose there.
  // Unregistered, not only disposed: a reader's DEADLINE must stop watching the old key. Fast
  // DDS 2.9 then logs "Could not set the next deadline in the history" once per writer with a
  // DEADLINE (telemetry, low rate): it looks for the instance it has just let go; the
  // unregistration itself returns OK (measured with `pmu-service --bus sim`).
  auto gone = [&](DataWriter* w, void* sample) {
    if (w == nullptr) return;
    const ReturnCode_t rc = w->unregister_instance(sample, HANDLE_NIL);
    if (rc != ReturnCode_t::RETCODE_PRECONDITION_NOT_MET)
      count(rc == ReturnCode_t::RETCODE_OK, w->get_topic()->get_name().c_str(), key, why(rc));
  };
  pmu::v5::Health h;
  set_key(h, w_->vehicle, key);
  h.kind(static_cast<pmu::v5::DeviceKind>(static_cast<int>(key.kind)));
  gone(w_->health, &h);
  gone(w_->low_health, &h);
  w_->low_health_last.erase(std::make_tuple(key.bus, key.kind, key.address));
  if (key.kind != DeviceKind::Pmu) return;  // batteries and MPPTs keep their node and device id
  pmu::v5::Voltages v;
  set_key(v, w_->vehicle, key);
  pmu::v5::Currents c;
  set_key(c, w_->vehicle, key);
  pmu::v5::BatteryEnergy e;
  set_key(e, w_->vehicle, key);
  pmu::v5::Temperatures t;
  set_key(t, w_->vehicle, key);
  pmu::v5::Status st;
  set_key(st, w_->vehicle, key);
  void* telemetry[LowRateGate::kPackets] = {&v, &c, &e, &t, &st};
  DataWriter* live[LowRateGate::kPackets] = {w_->voltages, w_->currents, w_->energy, w_->temperatures, w_->status};
  for (std::size_t i = 0; i < LowRateGate::kPackets; ++i) {
    gone(live[i], telemetry[i]);
    gone(w_->low[i], telemetry[i]);
  }
  pmu::v5::Config cfg;
  set_key(cfg, w_->vehicle, key);
  gone(w_->config, &cfg);
  pmu::v5::DeviceInfo info;
  set_key(info, w_->vehicle, key);
  gone(w_->info, &info);
  pmu::v5::Energy derived;
  set_key(derived, w_->vehicle, key);
  gone(w_->derived_energy, &derived);
}

}  // namespace pmu::service

namespace pmu::service {

void DdsPublisher::write_at(DataWriter* writer, void* sample, const DeviceKey& key,
                            std::chrono::system_clock::time_point when) {
  if (writer == nullptr) return;  // topics not offered: no session can produce these samples
  const ReturnCode_t rc = writer->write_w_timestamp(sample, HANDLE_NIL, dds_time(when));
  count(rc == ReturnCode_t::RETCODE_OK, writer->get_topic()->get_name().c_str(), key, why(rc));
}

void DdsPublisher::on_battery(const DeviceKey& key, const BatteryState& b,
                              std::chrono::system_clock::time_point newest) {
  pmu::v5::Battery s;
  s.vehicle(w_->vehicle);
  s.bus(key.bus);
  s.node(octet_id(key));
  const Values<kBatteryValueCount> v(b, kBatteryValues);
  s.voltage(v.real("voltage"));
  s.current(v.real("current"));
  s.current_discharge(v.real("current_discharge"));
  s.current_charge(v.real("current_charge"));
  s.state_of_charge(v.real("state_of_charge"));
  s.time_to_go(time_to_go_or_nan(v.exact("time_to_go")));  // NaN also while not discharging
  s.cell_temperature_high(v.real("cell_temperature_high"));
  s.cell_temperature_low(v.real("cell_temperature_low"));
  s.cell_voltage_high(v.real("cell_voltage_high"));
  s.cell_voltage_low(v.real("cell_voltage_low"));
  s.bms_state(v.exact("bms_state"));
  s.temperature_1(v.real("temperature_1"));
  s.temperature_2(v.real("temperature_2"));
  s.temperature_3(v.real("temperature_3"));
  s.temperature_4(v.real("temperature_4"));
  s.power_level(v.real("power_level"));
  s.received(b.received_mask());
  std::lock_guard<std::mutex> lock(w_->mutex);
  if (!admit(key)) return;
  write_at(w_->battery, &s, key, newest);
}

void DdsPublisher::on_battery_cells(const DeviceKey& key, const BatteryCellsState& c,
                                    std::chrono::system_clock::time_point newest) {
  pmu::v5::BatteryCells s;
  s.vehicle(w_->vehicle);
  s.bus(key.bus);
  s.node(octet_id(key));
  for (std::size_t cell = 0; cell < c.volts.size(); ++cell) {
    if (std::isnan(c.volts[cell])) continue;
    pmu::v5::BatteryCell one;
    one.cell(static_cast<std::uint8_t>(cell));
    one.cell_voltage(idl_float(c.volts[cell]));
    s.cells().push_back(one);
  }
  std::lock_guard<std::mutex> lock(w_->mutex);
  if (!admit(key)) return;
  write_at(w_->battery_cells, &s, key, newest);
}

void DdsPublisher::on_mppt(const DeviceKey& key, const MpptState& m, std::chrono::system_clock::time_point newest) {
  pmu::v5::Mppt s;
  s.vehicle(w_->vehicle);
  s.bus(key.bus);
  s.device(octet_id(key));
  const Values<kMpptValueCount> v(m, kMpptValues);
  s.voltage_output_raw(v.real("voltage_output_raw"));
  s.current_output_raw(v.real("current_output_raw"));
  s.voltage_out_sw_raw(v.real("voltage_out_sw_raw"));
  s.mppt_state(v.real("mppt_state"));
  s.safety_enabled(v.flag("safety_enabled"));
  s.pwm_enabled(v.flag("pwm_enabled"));
  s.temperature(v.real("temperature"));
  s.voltage_panel_1_raw(v.real("voltage_panel_1_raw"));
  s.current_panel_1_raw(v.real("current_panel_1_raw"));
  s.duty_cycle_panel_1(v.real("duty_cycle_panel_1"));
  s.channel_1_active(v.real("channel_1_active"));
  s.voltage_panel_2_raw(v.real("voltage_panel_2_raw"));
  s.current_panel_2_raw(v.real("current_panel_2_raw"));
  s.duty_cycle_panel_2(v.real("duty_cycle_panel_2"));
  s.channel_2_active(v.real("channel_2_active"));
  s.voltage_panel_3_raw(v.real("voltage_panel_3_raw"));
  s.current_panel_3_raw(v.real("current_panel_3_raw"));
  s.duty_cycle_panel_3(v.real("duty_cycle_panel_3"));
  s.channel_3_active(v.real("channel_3_active"));
  s.voltage_panel_4_raw(v.real("voltage_panel_4_raw"));
  s.current_panel_4_raw(v.real("current_panel_4_raw"));
  s.duty_cycle_panel_4(v.real("duty_cycle_panel_4"));
  s.channel_4_active(v.real("channel_4_active"));
  s.received(m.received_mask());
  std::lock_guard<std::mutex> lock(w_->mutex);
  if (!admit(key)) return;
  write_at(w_->mppt, &s, key, newest);
}

namespace {

pmu::v5::AlarmSource source_of(alarms::DeviceKind k) {
  switch (k) {
    case alarms::DeviceKind::Battery: return pmu::v5::SOURCE_BATTERY;
    case alarms::DeviceKind::Mppt: return pmu::v5::SOURCE_MPPT;
    case alarms::DeviceKind::Bus: return pmu::v5::SOURCE_BUS;
    case alarms::DeviceKind::Pmu:
    case alarms::DeviceKind::AnyDevice: break;
  }
  return pmu::v5::SOURCE_PMU;
}

pmu::v5::AlarmState state_of(alarms::AlarmState s) {
  switch (s) {
    case alarms::AlarmState::ActiveUnacknowledged: return pmu::v5::ALARM_ACTIVE_UNACKNOWLEDGED;
    case alarms::AlarmState::ActiveAcknowledged: return pmu::v5::ALARM_ACTIVE_ACKNOWLEDGED;
    case alarms::AlarmState::ClearedUnacknowledged: return pmu::v5::ALARM_CLEARED_UNACKNOWLEDGED;
    case alarms::AlarmState::Normal: break;
  }
  return pmu::v5::ALARM_NORMAL;
}

}  // namespace

void DdsPublisher::on_alarm(const AlarmReport& a) {
  const bool flag = alarms::spec_of(a.code).condition == alarms::Condition::Flag;
  pmu::v5::Alarm s;
  s.vehicle(w_->vehicle);
  s.bus(a.bus);
  s.device(a.device);
  s.kind(source_of(a.source));
  s.code(std::string(alarms::to_string(a.code)));
  s.severity(a.severity == alarms::Severity::Critical ? pmu::v5::SEVERITY_CRITICAL : pmu::v5::SEVERITY_WARNING);
  s.state(state_of(a.state));
  s.value(flag ? std::numeric_limits<float>::quiet_NaN() : static_cast<float>(a.value));
  s.limit(flag ? std::numeric_limits<float>::quiet_NaN() : static_cast<float>(a.limit));
  s.since(static_cast<std::uint64_t>(std::max<std::int64_t>(
      0, std::chrono::duration_cast<std::chrono::nanoseconds>(a.since.time_since_epoch()).count())));
  s.message(a.message.substr(0, alarms::kMaxMessageLength));
  const DeviceKey key{a.bus, a.device, DeviceKind::Pmu};
  std::lock_guard<std::mutex> lock(w_->mutex);
  write_at(w_->alarms, &s, key, a.since);
}

void DdsPublisher::on_readiness(const ReadinessReport& r) {
  pmu::v5::Readiness s;
  s.vehicle(w_->vehicle);
  s.ready(r.ready);
  s.level(!r.ready ? pmu::v5::LEVEL_NOT_READY : r.warnings() ? pmu::v5::LEVEL_WARNING : pmu::v5::LEVEL_READY);
  s.since(static_cast<std::uint64_t>(std::max<std::int64_t>(
      0, std::chrono::duration_cast<std::chrono::nanoseconds>(r.since.time_since_epoch()).count())));
  constexpr std::size_t kCarried = 64;  // the IDL's bound; reasons_total counts the rest
  for (std::size_t i = 0; i < r.reasons.size() && i < kCarried; ++i) {
    const auto& x = r.reasons[i];
    pmu::v5::ReadinessReason y;
    y.code(x.code.substr(0, 31));
    y.severity(x.severity == alarms::Severity::Critical ? pmu::v5::SEVERITY_CRITICAL : pmu::v5::SEVERITY_WARNING);
    y.bus(x.bus.substr(0, 15));
    y.kind(source_of(x.source));
    y.device(x.device);
    y.message(x.message.substr(0, 42));
    y.description(x.description.substr(0, 127));
    s.reasons().push_back(y);
  }
  s.reasons_total(static_cast<std::uint32_t>(r.reasons.size()));
  const DeviceKey key{"", 0, DeviceKind::Pmu};
  std::lock_guard<std::mutex> lock(w_->mutex);
  write_at(w_->readiness, &s, key, std::chrono::system_clock::now());
}

namespace {

pmu::v5::EnergyBattery battery_of(const energy::BatteryFigures& b) {
  pmu::v5::EnergyBattery s;
  s.power(idl_float(b.power));
  s.used_wh(b.used_wh);
  s.integrated_s(idl_float(b.integrated_s));
  s.endurance_s(idl_float(b.endurance_s));
  s.critical_voltage(idl_float(b.critical_voltage));
  return s;
}

}  // namespace

void DdsPublisher::on_energy(const DeviceKey& key, const energy::Figures& f, std::chrono::system_clock::time_point at) {
  pmu::v5::Energy s;
  set_key(s, w_->vehicle, key);
  s.avionics_power(idl_float(f.avionics_power));
  s.output_28v_power(idl_float(f.output_28v_power));
  s.payload_power(idl_float(f.payload_power));
  s.servo_power(idl_float(f.servo_power));
  s.generator_power(idl_float(f.generator_power));
  s.battery_a(battery_of(f.battery_a));
  s.battery_b(battery_of(f.battery_b));
  std::lock_guard<std::mutex> lock(w_->mutex);
  if (!admit(key)) return;
  write_at(w_->derived_energy, &s, key, at);
}

void DdsPublisher::on_bms_energy(const DeviceKey& key, const energy::BmsFigures& f,
                                 std::chrono::system_clock::time_point at) {
  pmu::v5::BmsEnergy s;
  s.vehicle(w_->vehicle);
  s.bus(key.bus);
  s.node(octet_id(key));
  s.power(idl_float(f.power));
  s.used_wh(f.used_wh);
  s.integrated_s(idl_float(f.integrated_s));
  s.endurance_s(idl_float(f.endurance_s));
  s.capacity_ah(idl_float(f.capacity_ah));
  s.critical_state_of_charge(idl_float(f.critical_state_of_charge));
  std::lock_guard<std::mutex> lock(w_->mutex);
  if (!admit(key)) return;
  write_at(w_->bms_energy, &s, key, at);
}

}  // namespace pmu::service
