#include "pmu/dds/telemetry_samples.hpp"

#include <fastdds/rtps/common/SerializedPayload.h>

#include "pmu/dds/no_value.hpp"
#include "pmu/idl/telemetryPubSubTypes.h"
#include "pmu/idl/topics.hpp"

namespace pmu::service {
namespace {


template <class PubSub, class T>
bool serialize(T& s, std::vector<std::uint8_t>& out) {
  try {
    PubSub type;
    eprosima::fastrtps::rtps::SerializedPayload_t payload(type.getSerializedSizeProvider(&s)());
    if (!type.serialize(&s, &payload)) return false;
    out.assign(payload.data, payload.data + payload.length);
    return true;
  } catch (...) {  // Fast CDR reports a bound exceeded (a bus name over 15) by throwing
    return false;
  }
}

template <class T, class PubSub, class Codec>
bool sample(const std::string& vehicle, const DeviceKey& key, const Codec& values, const char* topic,
            TelemetryCdr& out) {
  T s;
  set_key(s, vehicle, key);
  fill(s, values);
  out.topic = topic;
  return serialize<PubSub>(s, out.bytes);
}

}  // namespace

void fill(pmu::v5::Voltages& s, const codec::Voltages& v) {
  s.avionics(idl_float(v.avionics));
  s.output_28v(idl_float(v.output_28v));
  s.payload(idl_float(v.payload));
  s.servo(idl_float(v.servo));
  s.battery_a(idl_float(v.battery_a));
  s.battery_b(idl_float(v.battery_b));
  s.generator(idl_float(v.generator));
}

void fill(pmu::v5::Currents& s, const codec::Currents& c) {
  s.avionics(idl_float(c.avionics));
  s.output_28v(idl_float(c.output_28v));
  s.payload(idl_float(c.payload));
  s.servo(idl_float(c.servo));
  s.battery_a(idl_float(c.battery_a));
  s.battery_b(idl_float(c.battery_b));
}

void fill(pmu::v5::BatteryEnergy& s, const codec::BatteryEnergy& e) {
  s.battery_a_mah(e.battery_a_mah);
  s.battery_b_mah(e.battery_b_mah);
}

void fill(pmu::v5::Temperatures& s, const codec::Temperatures& t) {
  s.internal(idl_float(t.internal));
  s.battery_a(idl_float(t.battery_a));  // NaN stays NaN: "no sensor"
  s.battery_b(idl_float(t.battery_b));
  s.generator(idl_float(t.generator));
  s.starter(idl_float(t.starter));
}

void fill(pmu::v5::Status& s, const codec::Status& st) {
  s.generator_rpm(rpm_or_nan(st.generator_rpm));  // NaN, never 65535: no reading
  s.generation_enabled(st.generation_enabled);
  s.thermal_shutdown(st.thermal_shutdown);
  s.soa_shutdown(st.soa_shutdown);
  s.start_button(st.start_button);
  s.payload_shed(st.payload_shed);
  s.starter_ready(st.starter_ready);
  s.avionics_servo_on(st.avionics_servo_on());
  s.payload_on(st.payload_on());
  s.charger_a_on(st.charger_a_on());
  s.charger_b_on(st.charger_b_on());
}

bool telemetry_cdr(const std::string& vehicle, const DeviceKey& key, const codec::PmuMessage& m, TelemetryCdr& out) {
  if (m.request) return false;
  if (const auto* v = std::get_if<codec::Voltages>(&m.payload))
    return sample<pmu::v5::Voltages, pmu::v5::VoltagesPubSubType>(vehicle, key, *v, topics::kVoltages, out);
  if (const auto* c = std::get_if<codec::Currents>(&m.payload))
    return sample<pmu::v5::Currents, pmu::v5::CurrentsPubSubType>(vehicle, key, *c, topics::kCurrents, out);
  if (const auto* e = std::get_if<codec::BatteryEnergy>(&m.payload))
    return sample<pmu::v5::BatteryEnergy, pmu::v5::BatteryEnergyPubSubType>(vehicle, key, *e, topics::kBatteryEnergy,
                                                                            out);
  if (const auto* t = std::get_if<codec::Temperatures>(&m.payload))
    return sample<pmu::v5::Temperatures, pmu::v5::TemperaturesPubSubType>(vehicle, key, *t, topics::kTemperatures, out);
  if (const auto* st = std::get_if<codec::Status>(&m.payload))
    return sample<pmu::v5::Status, pmu::v5::StatusPubSubType>(vehicle, key, *st, topics::kStatus, out);
  return false;
}

}  // namespace pmu::service
