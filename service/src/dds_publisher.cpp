#include "pmu/service/dds_publisher.hpp"

#include <cmath>
#include <mutex>

#include "pmu/idl/command.h"
#include "pmu/idl/commandPubSubTypes.h"
#include "pmu/idl/state.h"
#include "pmu/idl/statePubSubTypes.h"
#include "pmu/idl/telemetry.h"
#include "pmu/idl/telemetryPubSubTypes.h"
#include "pmu/idl/topics.hpp"

namespace pmu::service {
namespace {

using namespace eprosima::fastdds::dds;
using codec::Parameter;

float f(double v) { return static_cast<float>(v); }

eprosima::fastrtps::Time_t dds_time(std::chrono::system_clock::time_point t) {
  const auto ns = std::chrono::duration_cast<std::chrono::nanoseconds>(t.time_since_epoch()).count();
  eprosima::fastrtps::Time_t out;
  out.seconds = static_cast<std::int32_t>(ns / 1000000000);
  out.nanosec = static_cast<std::uint32_t>(ns % 1000000000);
  return out;
}

template <class T>
void set_key(T& s, const DeviceKey& k) {
  s.bus(k.bus);
  s.address(k.address);
}

}  // namespace

struct DdsPublisher::Writers {
  DataWriter* voltages;
  DataWriter* currents;
  DataWriter* energy;
  DataWriter* temperatures;
  DataWriter* status;
  DataWriter* config;
  DataWriter* info;
  DataWriter* health;
  // Bus workers run in threads of their own and share these writers.
  std::mutex mutex;
};

DdsPublisher::DdsPublisher(dds::DdsContext& dds, std::chrono::milliseconds telemetry_deadline)
    : w_(std::make_unique<Writers>()) {
  auto telemetry = [&](const char* name, TypeSupport type) {
    DataWriter& w = dds.writer(dds.topic(name, type), qos_profiles::kTelemetry);
    DataWriterQos q = w.get_qos();
    const auto ns = std::chrono::duration_cast<std::chrono::nanoseconds>(telemetry_deadline).count();
    q.deadline().period = eprosima::fastrtps::Duration_t(static_cast<std::int32_t>(ns / 1000000000),
                                                         static_cast<std::uint32_t>(ns % 1000000000));
    if (w.set_qos(q) != ReturnCode_t::RETCODE_OK)
      throw dds::DdsError(std::string("cannot set the DEADLINE of ") + name);
    return &w;
  };
  auto state = [&](const char* name, TypeSupport type) {
    return &dds.writer(dds.topic(name, type), qos_profiles::kState);
  };
  w_->voltages = telemetry(topics::kVoltages, TypeSupport(new pmu::VoltagesPubSubType()));
  w_->currents = telemetry(topics::kCurrents, TypeSupport(new pmu::CurrentsPubSubType()));
  w_->energy = telemetry(topics::kBatteryEnergy, TypeSupport(new pmu::BatteryEnergyPubSubType()));
  w_->temperatures = telemetry(topics::kTemperatures, TypeSupport(new pmu::TemperaturesPubSubType()));
  w_->status = telemetry(topics::kStatus, TypeSupport(new pmu::StatusPubSubType()));
  w_->config = state(topics::kConfig, TypeSupport(new pmu::ConfigPubSubType()));
  w_->info = state(topics::kInfo, TypeSupport(new pmu::DeviceInfoPubSubType()));
  w_->health = state(topics::kHealth, TypeSupport(new pmu::HealthPubSubType()));
}

DdsPublisher::~DdsPublisher() = default;

// DataWriter::write(void*) returns bool in Fast DDS 2.x (write_w_timestamp a ReturnCode_t).
void DdsPublisher::count(bool ok) noexcept {
  if (ok)
    ++written_;
  else
    ++failures_;
}

void DdsPublisher::on_telemetry(const DeviceKey& key, const codec::PmuMessage& m,
                                std::chrono::system_clock::time_point received) {
  const auto ts = dds_time(received);
  std::lock_guard<std::mutex> lock(w_->mutex);
  auto write = [&](DataWriter* w, void* sample) {
    count(w->write_w_timestamp(sample, HANDLE_NIL, ts) == ReturnCode_t::RETCODE_OK);
  };
  if (const auto* v = std::get_if<codec::Voltages>(&m.payload)) {
    pmu::Voltages s;
    set_key(s, key);
    s.avionics(f(v->avionics));
    s.output_28v(f(v->output_28v));
    s.payload(f(v->payload));
    s.servo(f(v->servo));
    s.battery_a(f(v->battery_a));
    s.battery_b(f(v->battery_b));
    s.generator(f(v->generator));
    write(w_->voltages, &s);
  } else if (const auto* c = std::get_if<codec::Currents>(&m.payload)) {
    pmu::Currents s;
    set_key(s, key);
    s.avionics(f(c->avionics));
    s.output_28v(f(c->output_28v));
    s.payload(f(c->payload));
    s.servo(f(c->servo));
    s.battery_a(f(c->battery_a));
    s.battery_b(f(c->battery_b));
    write(w_->currents, &s);
  } else if (const auto* e = std::get_if<codec::BatteryEnergy>(&m.payload)) {
    pmu::BatteryEnergy s;
    set_key(s, key);
    s.battery_a_mah(e->battery_a_mah);
    s.battery_b_mah(e->battery_b_mah);
    write(w_->energy, &s);
  } else if (const auto* t = std::get_if<codec::Temperatures>(&m.payload)) {
    pmu::Temperatures s;
    set_key(s, key);
    s.internal(f(t->internal));
    s.battery_a(f(t->battery_a));  // NaN stays NaN: "no sensor"
    s.battery_b(f(t->battery_b));
    s.generator(f(t->generator));
    s.starter(f(t->starter));
    write(w_->temperatures, &s);
  } else if (const auto* st = std::get_if<codec::Status>(&m.payload)) {
    pmu::Status s;
    set_key(s, key);
    s.generator_rpm(st->generator_rpm);
    s.generation_enabled(st->generation_enabled);
    s.thermal_shutdown(st->thermal_shutdown);
    s.soa_shutdown(st->soa_shutdown);
    s.start_button(st->start_button);
    s.payload_shed(st->payload_shed);
    s.starter_ready(st->starter_ready);
    s.avionics_servo_on(st->avionics_servo_on());
    s.payload_on(st->payload_on());
    s.charger_a_on(st->charger_a_on());
    s.charger_b_on(st->charger_b_on());
    write(w_->status, &s);
  }
}

void DdsPublisher::on_config(const DeviceKey& key, const ConfigState& c) {
  pmu::Config s;
  set_key(s, key);
  auto raw8 = [&](Parameter p) {
    return static_cast<std::uint8_t>(c.raw[static_cast<std::size_t>(p)].value_or(0) & 0xFF);
  };
  s.avionics_voltage(f(c.value(Parameter::AvionicsVoltage)));
  s.payload_voltage(f(c.value(Parameter::PayloadVoltage)));
  s.servo_voltage(f(c.value(Parameter::ServoVoltage)));
  s.battery_voltage(f(c.value(Parameter::BatteryVoltage)));
  s.packet_period(f(c.value(Parameter::PacketPeriod)));
  s.packets_streamed(raw8(Parameter::PacketsStreamed));
  s.temperature_offset(raw8(Parameter::TemperatureOffset));
  s.upper_temperature_limit(raw8(Parameter::UpperTemperatureLimit));
  s.power_up_state(raw8(Parameter::PowerUpState));
  s.cranking_time(f(c.value(Parameter::CrankingTime)));
  s.can_address(static_cast<std::uint16_t>(c.raw[static_cast<std::size_t>(Parameter::CanAddress)].value_or(key.address)));
  s.outputs(c.outputs.value_or(0));
  s.generation_enabled(c.generation_enabled.value_or(false));
  std::lock_guard<std::mutex> lock(w_->mutex);
  count(w_->config->write(&s));
}

void DdsPublisher::on_info(const DeviceKey& key, const InfoState& i) {
  pmu::DeviceInfo s;
  set_key(s, key);
  s.serial_number(i.serial_number);
  s.firmware_major(i.firmware.firmware_major);
  s.firmware_minor(i.firmware.firmware_minor);
  s.build_year(i.firmware.build_year);
  s.build_month(i.firmware.build_month);
  s.build_day(i.firmware.build_day);
  for (const auto feature : codec::kAllFeatures)
    if (codec::supports(i.firmware.version(), feature)) s.features().emplace_back(std::string(codec::feature_name(feature)));
  std::lock_guard<std::mutex> lock(w_->mutex);
  count(w_->info->write(&s));
}

void DdsPublisher::on_health(const DeviceKey& key, const HealthReport& h) {
  pmu::Health s;
  set_key(s, key);
  s.state(static_cast<pmu::HealthState>(static_cast<int>(h.state)));
  s.bus_state(static_cast<pmu::BusState>(static_cast<int>(h.bus_state)));
  s.last_frame_age(f(h.last_frame_age));
  s.frames_received(h.frames_received);
  s.frames_sent(h.frames_sent);
  s.decode_errors(h.decode_errors);
  s.bus_errors(h.bus_errors);
  s.rx_dropped(h.rx_dropped);
  s.timeouts(h.timeouts);
  s.reconnects(h.reconnects);
  std::lock_guard<std::mutex> lock(w_->mutex);
  count(w_->health->write(&s));
}

}  // namespace pmu::service
