#include "pmuctl/view/sample_json.hpp"

#include "pmuctl/view/sample_fields.hpp"

namespace pmu::tools {

Json values_of(const pmu::v5::Voltages& s) { return json_of(fields_of(s)); }
Json values_of(const pmu::v5::Currents& s) { return json_of(fields_of(s)); }
Json values_of(const pmu::v5::BatteryEnergy& s) { return json_of(fields_of(s)); }
Json values_of(const pmu::v5::Temperatures& s) { return json_of(fields_of(s)); }
Json values_of(const pmu::v5::Status& s) { return json_of(fields_of(s)); }
Json values_of(const pmu::v5::Config& s) { return json_of(fields_of(s)); }
Json values_of(const pmu::v5::DeviceInfo& s) { return json_of(fields_of(s)); }
Json values_of(const pmu::v5::Health& s) { return json_of(fields_of(s)); }
Json values_of(const pmu::v5::Battery& s) { return json_of(fields_of(s)); }
Json values_of(const pmu::v5::BatteryCells& s) { return json_of(fields_of(s)); }
Json values_of(const pmu::v5::Mppt& s) { return json_of(fields_of(s)); }

const char* to_string(pmu::v5::HealthState s) {
  switch (s) {
    case pmu::v5::UNKNOWN: return "UNKNOWN";
    case pmu::v5::ONLINE: return "ONLINE";
    case pmu::v5::STALE: return "STALE";
    case pmu::v5::OFFLINE: return "OFFLINE";
  }
  return "UNKNOWN";
}

const char* to_string(pmu::v5::BusState s) {
  switch (s) {
    case pmu::v5::UP: return "UP";
    case pmu::v5::ERROR_WARNING: return "ERROR_WARNING";
    case pmu::v5::ERROR_PASSIVE: return "ERROR_PASSIVE";
    case pmu::v5::BUS_OFF: return "BUS_OFF";
    case pmu::v5::DOWN: return "DOWN";
  }
  return "DOWN";
}

const char* to_string(pmu::v5::DeviceKind k) {
  switch (k) {
    case pmu::v5::KIND_PMU: return "pmu";
    case pmu::v5::KIND_BATTERY: return "battery";
    case pmu::v5::KIND_MPPT: return "mppt";
  }
  return "pmu";
}

}  // namespace pmu::tools
