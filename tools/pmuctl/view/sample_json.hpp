#pragma once
// JSON forms of the contract's DDS samples, keyed by the contract's field names
// (interface.md), for `pmuctl --json`: the JSON column of sample_fields.hpp.

#include <nlohmann/json.hpp>

#include "pmu/idl/canopen.h"
#include "pmu/idl/command.h"
#include "pmu/idl/state.h"
#include "pmu/idl/telemetry.h"

namespace pmu::tools {

using Json = nlohmann::ordered_json;

Json values_of(const pmu::v4::Voltages& s);
Json values_of(const pmu::v4::Currents& s);
Json values_of(const pmu::v4::BatteryEnergy& s);
Json values_of(const pmu::v4::Temperatures& s);
Json values_of(const pmu::v4::Status& s);
Json values_of(const pmu::v4::Config& s);
Json values_of(const pmu::v4::DeviceInfo& s);
Json values_of(const pmu::v4::Health& s);
// Batteries and MPPTs (interface.md 1.4): a value not received is null, for integer and
// boolean fields too (their `received` bit), so no consumer mistakes "not yet" for 0.
// Sentinels are null too (sample_fields.hpp).
Json values_of(const pmu::v4::Battery& s);
Json values_of(const pmu::v4::BatteryCells& s);
Json values_of(const pmu::v4::Mppt& s);

const char* to_string(pmu::v4::HealthState s);
const char* to_string(pmu::v4::BusState s);
const char* to_string(pmu::v4::DeviceKind k);  // "pmu", "battery", "mppt"

}  // namespace pmu::tools
