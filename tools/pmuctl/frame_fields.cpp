#include "pmuctl/frame_fields.hpp"

#include <type_traits>

namespace pmu::tools {
namespace {

using codec::output_bit::AvionicsServo;
using codec::output_bit::ChargerA;
using codec::output_bit::ChargerB;
using codec::output_bit::Payload;

struct Visitor {
  FieldSink& s;

  void num(std::string_view n, double v, std::string_view unit) { s.field(n, FieldValue::of(v), unit); }
  void integer(std::string_view n, std::int64_t v, std::string_view unit = {}) {
    s.field(n, FieldValue::of_int(v), unit);
  }
  void flag(std::string_view n, bool v) { s.field(n, FieldValue::of_bool(v), {}); }

  void operator()(const codec::NoPayload&) {}
  void operator()(const codec::Voltages& v) {
    num("avionics", v.avionics, "V");
    num("output_28v", v.output_28v, "V");
    num("payload", v.payload, "V");
    num("servo", v.servo, "V");
    num("battery_a", v.battery_a, "V");
    num("battery_b", v.battery_b, "V");
    num("generator", v.generator, "V");
  }
  void operator()(const codec::Currents& c) {
    num("avionics", c.avionics, "A");
    num("output_28v", c.output_28v, "A");
    num("payload", c.payload, "A");
    num("servo", c.servo, "A");
    num("battery_a", c.battery_a, "A");
    num("battery_b", c.battery_b, "A");
  }
  void operator()(const codec::BatteryEnergy& e) {
    integer("battery_a_mah", e.battery_a_mah, "mAh");
    integer("battery_b_mah", e.battery_b_mah, "mAh");
  }
  void operator()(const codec::Temperatures& t) {
    num("internal", t.internal, "degC");
    num("battery_a", t.battery_a, "degC");
    num("battery_b", t.battery_b, "degC");
    num("generator", t.generator, "degC");
    num("starter", t.starter, "degC");
  }
  void operator()(const codec::Status& st) {
    integer("generator_rpm", st.generator_rpm, "rpm");
    flag("generation_enabled", st.generation_enabled);
    flag("thermal_shutdown", st.thermal_shutdown);
    flag("soa_shutdown", st.soa_shutdown);
    flag("start_button", st.start_button);
    flag("payload_shed", st.payload_shed);
    flag("starter_ready", st.starter_ready);
    flag("avionics_servo_on", st.outputs & AvionicsServo);
    flag("payload_on", st.outputs & Payload);
    flag("charger_a_on", st.outputs & ChargerA);
    flag("charger_b_on", st.outputs & ChargerB);
  }
  void operator()(const codec::MeasurementRequest& r) { integer("measurements", r.groups); }
  void operator()(const codec::ParameterValue& p) {
    const auto& spec = codec::spec_of(p.parameter);
    if (spec.kind == codec::ParameterKind::Scaled)
      num(spec.name, p.value, spec.unit);
    else
      integer(spec.name, p.raw, spec.unit);
  }
  void operator()(const codec::OutputStates& o) { integer("outputs", o.mask); }
  void operator()(const codec::EnableOutputs& o) { integer("outputs", o.mask); }
  void operator()(const codec::DisableOutputs& o) { integer("outputs", o.mask); }
  void operator()(const codec::GenerationState& g) { flag("generation_enabled", g.enabled); }
  void operator()(const codec::SerialNumber& sn) { integer("serial_number", sn.serial_number); }
  void operator()(const codec::FirmwareInfo& f) {
    integer("firmware_major", f.firmware_major);
    integer("firmware_minor", f.firmware_minor);
    integer("build_year", f.build_year);
    integer("build_month", f.build_month);
    integer("build_day", f.build_day);
  }
};

}  // namespace

void visit_fields(const codec::PmuMessage& m, FieldSink& sink) { std::visit(Visitor{sink}, m.payload); }

void visit_fields(const codec::canopen::CanOpenMessage& m, FieldSink& sink) {
  for (std::size_t i = 0; i < m.field_count; ++i) {
    const auto& f = m.fields[i];
    const bool integral = f.value == static_cast<double>(static_cast<std::int64_t>(f.value)) && f.unit.empty();
    sink.field(f.name, integral ? FieldValue::of_int(static_cast<std::int64_t>(f.value)) : FieldValue::of(f.value),
               f.unit);
  }
}

std::string_view bit6_meaning_name(codec::Bit6Meaning m) {
  return m == codec::Bit6Meaning::SoaShutdown ? "soa_shutdown" : "start_button";
}

}  // namespace pmu::tools
