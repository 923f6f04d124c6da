#include "pmu/dds/previous_contract.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>

#include "pmu/dds/no_value.hpp"
#include "pmu/idl/canopenPubSubTypes.h"
#include "pmu/idl/statePubSubTypes.h"
#include "pmu/idl/telemetryPubSubTypes.h"
#include "pmu/idl_previous/canopenPubSubTypes.h"
#include "pmu/idl_previous/statePubSubTypes.h"
#include "pmu/idl_previous/telemetryPubSubTypes.h"
#include "pmu/idl_tables/canopen_values.hpp"

namespace pmu::dds {
namespace {

using eprosima::fastdds::dds::TopicDataType;
using eprosima::fastrtps::rtps::InstanceHandle_t;
using eprosima::fastrtps::rtps::SerializedPayload_t;

// A whole value as the previous contract's integer field: NaN (not received) is `none`,
// anything else rounded and held within the field (the service sends whole values in range).
template <class Int>
Int whole(double v, Int none = 0) {
  if (std::isnan(v)) return none;
  return static_cast<Int>(std::llround(std::clamp(v, 0.0, static_cast<double>(std::numeric_limits<Int>::max()))));
}
bool flag(float v) { return !std::isnan(v) && v != 0; }

template <std::size_t N>
bool received(std::uint32_t mask, const service::CanOpenValue (&table)[N], std::string_view name) {
  for (std::size_t i = 0; i < N; ++i)
    if (table[i].name == name) return (mask >> i) & 1u;
  return false;
}

// Writes a Current sample as Previous under Previous's name. Keys are the same fields in both
// contracts, so the current type computes the instance handle.
template <class Current, class CurrentPubSub, class Previous, class PreviousPubSub>
class Converting final : public TopicDataType {
 public:
  Converting() {
    setName(previous_.getName());
    m_typeSize = previous_.m_typeSize;
    m_isGetKeyDefined = current_.m_isGetKeyDefined;
  }
  bool serialize(void* data, SerializedPayload_t* payload) override {
    Previous p = to_previous(*static_cast<const Current*>(data));
    return previous_.serialize(&p, payload);
  }
  bool deserialize(SerializedPayload_t*, void*) override { return false; }
  std::function<uint32_t()> getSerializedSizeProvider(void* data) override {
    Previous p = to_previous(*static_cast<const Current*>(data));
    const std::uint32_t size = previous_.getSerializedSizeProvider(&p)();  // the provider reads p now
    return [size] { return size; };
  }
  bool getKey(void* data, InstanceHandle_t* handle, bool force_md5) override {
    return current_.getKey(data, handle, force_md5);
  }
  void* createData() override { return current_.createData(); }
  void deleteData(void* data) override { current_.deleteData(data); }

 private:
  CurrentPubSub current_;
  PreviousPubSub previous_;
};

template <class Converter>
eprosima::fastdds::dds::TypeSupport make() {
  return eprosima::fastdds::dds::TypeSupport(new Converter());
}

}  // namespace

pmu::v4::Status to_previous(const pmu::v5::Status& s) {
  pmu::v4::Status p;
  p.vehicle(s.vehicle());
  p.bus(s.bus());
  p.address(s.address());
  p.generator_rpm(whole<std::uint16_t>(s.generator_rpm(), service::kNoRpm));
  p.generation_enabled(s.generation_enabled());
  p.thermal_shutdown(s.thermal_shutdown());
  p.soa_shutdown(s.soa_shutdown());
  p.start_button(s.start_button());
  p.payload_shed(s.payload_shed());
  p.starter_ready(s.starter_ready());
  p.avionics_servo_on(s.avionics_servo_on());
  p.payload_on(s.payload_on());
  p.charger_a_on(s.charger_a_on());
  p.charger_b_on(s.charger_b_on());
  return p;
}

pmu::v4::Health to_previous(const pmu::v5::Health& s) {
  pmu::v4::Health p;
  p.vehicle(s.vehicle());
  p.bus(s.bus());
  p.address(s.address());
  p.kind(static_cast<pmu::v4::DeviceKind>(static_cast<int>(s.kind())));
  p.state(static_cast<pmu::v4::HealthState>(static_cast<int>(s.state())));
  p.bus_state(static_cast<pmu::v4::BusState>(static_cast<int>(s.bus_state())));
  p.last_frame_age(std::isnan(s.last_frame_age()) ? static_cast<float>(service::kNeverHeard) : s.last_frame_age());
  p.frames_received(s.frames_received());
  p.frames_sent(s.frames_sent());
  p.decode_errors(s.decode_errors());
  p.bus_errors(s.bus_errors());
  p.rx_dropped(s.rx_dropped());
  p.timeouts(s.timeouts());
  p.reconnects(s.reconnects());
  p.publish_failures(s.publish_failures());
  return p;
}

pmu::v4::Battery to_previous(const pmu::v5::Battery& s) {
  pmu::v4::Battery p;
  p.vehicle(s.vehicle());
  p.bus(s.bus());
  p.node(s.node());
  p.voltage(s.voltage());
  p.current(s.current());
  p.current_discharge(s.current_discharge());
  p.current_charge(s.current_charge());
  p.state_of_charge(s.state_of_charge());
  // NaN with its bit set: received, and the battery was not discharging.
  const bool not_discharging =
      std::isnan(s.time_to_go()) && received(s.received(), service::kBatteryValues, "time_to_go");
  p.time_to_go(not_discharging ? static_cast<float>(service::kNotDischarging) : s.time_to_go());
  p.cell_temperature_high(s.cell_temperature_high());
  p.cell_temperature_low(s.cell_temperature_low());
  p.cell_voltage_high(s.cell_voltage_high());
  p.cell_voltage_low(s.cell_voltage_low());
  p.bms_state(whole<std::uint32_t>(s.bms_state()));
  p.temperature_1(s.temperature_1());
  p.temperature_2(s.temperature_2());
  p.temperature_3(s.temperature_3());
  p.temperature_4(s.temperature_4());
  p.power_level(s.power_level());
  p.received(s.received());
  return p;
}

pmu::v4::Mppt to_previous(const pmu::v5::Mppt& s) {
  pmu::v4::Mppt p;
  p.vehicle(s.vehicle());
  p.bus(s.bus());
  p.device(s.device());
  p.voltage_output_raw(s.voltage_output_raw());
  p.current_output_raw(s.current_output_raw());
  p.voltage_out_sw_raw(s.voltage_out_sw_raw());
  p.mppt_state(whole<std::uint8_t>(s.mppt_state()));
  p.safety_enabled(flag(s.safety_enabled()));
  p.pwm_enabled(flag(s.pwm_enabled()));
  p.temperature(s.temperature());
  p.voltage_panel_1_raw(s.voltage_panel_1_raw());
  p.current_panel_1_raw(s.current_panel_1_raw());
  p.duty_cycle_panel_1(s.duty_cycle_panel_1());
  p.channel_1_active(whole<std::uint8_t>(s.channel_1_active()));
  p.voltage_panel_2_raw(s.voltage_panel_2_raw());
  p.current_panel_2_raw(s.current_panel_2_raw());
  p.duty_cycle_panel_2(s.duty_cycle_panel_2());
  p.channel_2_active(whole<std::uint8_t>(s.channel_2_active()));
  p.voltage_panel_3_raw(s.voltage_panel_3_raw());
  p.current_panel_3_raw(s.current_panel_3_raw());
  p.duty_cycle_panel_3(s.duty_cycle_panel_3());
  p.channel_3_active(whole<std::uint8_t>(s.channel_3_active()));
  p.voltage_panel_4_raw(s.voltage_panel_4_raw());
  p.current_panel_4_raw(s.current_panel_4_raw());
  p.duty_cycle_panel_4(s.duty_cycle_panel_4());
  p.channel_4_active(whole<std::uint8_t>(s.channel_4_active()));
  p.received(s.received());
  return p;
}

eprosima::fastdds::dds::TypeSupport previous_contract_type(const eprosima::fastdds::dds::TypeSupport& current) {
  const std::string name = current.get_type_name();
  if (name == pmu::v5::StatusPubSubType().getName())
    return make<Converting<pmu::v5::Status, pmu::v5::StatusPubSubType, pmu::v4::Status, pmu::v4::StatusPubSubType>>();
  if (name == pmu::v5::HealthPubSubType().getName())
    return make<Converting<pmu::v5::Health, pmu::v5::HealthPubSubType, pmu::v4::Health, pmu::v4::HealthPubSubType>>();
  if (name == pmu::v5::BatteryPubSubType().getName())
    return make<Converting<pmu::v5::Battery, pmu::v5::BatteryPubSubType, pmu::v4::Battery, pmu::v4::BatteryPubSubType>>();
  if (name == pmu::v5::MpptPubSubType().getName())
    return make<Converting<pmu::v5::Mppt, pmu::v5::MpptPubSubType, pmu::v4::Mppt, pmu::v4::MpptPubSubType>>();
  return {};
}

}  // namespace pmu::dds
