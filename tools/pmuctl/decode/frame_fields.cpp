#include "pmuctl/decode/frame_fields.hpp"

#include <string>
#include <type_traits>

#include "pmu/codec/telemetry.hpp"

namespace pmu::tools {
namespace {

struct Visitor {
  FieldSink& s;

  void num(std::string_view n, double v, std::string_view unit) { s.field(n, FieldValue::of(v), unit); }
  void integer(std::string_view n, std::int64_t v, std::string_view unit = {}) {
    s.field(n, FieldValue::of_int(v), unit);
  }
  void flag(std::string_view n, bool v) { s.field(n, FieldValue::of_bool(v), {}); }

  void operator()(const codec::NoPayload&) {}
  // The telemetry tables give each field's name and unit in frame order.
  template <class Packet>
  void measured(const Packet& p) {
    for (const auto& f : codec::Telemetry<Packet>::fields) {
      if constexpr (std::is_floating_point_v<std::remove_reference_t<decltype(p.*f.member)>>)
        num(f.name, p.*f.member, f.unit);
      else
        integer(f.name, p.*f.member, f.unit);
    }
  }
  void operator()(const codec::Voltages& v) { measured(v); }
  void operator()(const codec::Currents& c) { measured(c); }
  void operator()(const codec::BatteryEnergy& e) { measured(e); }
  void operator()(const codec::Temperatures& t) { measured(t); }
  void operator()(const codec::Status& st) {
    integer("generator_rpm", st.generator_rpm, "rpm");
    flag("generation_enabled", st.generation_enabled);
    flag("thermal_shutdown", st.thermal_shutdown);
    flag("soa_shutdown", st.soa_shutdown);
    flag("start_button", st.start_button);
    flag("payload_shed", st.payload_shed);
    flag("starter_ready", st.starter_ready);
    for (const auto& o : codec::kOutputNames) flag(std::string(o.name) + "_on", (st.outputs & o.bit) != 0);
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
