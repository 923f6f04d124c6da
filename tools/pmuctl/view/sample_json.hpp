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

Json values_of(const pmu::v5::Voltages& s);
Json values_of(const pmu::v5::Currents& s);
Json values_of(const pmu::v5::BatteryEnergy& s);
Json values_of(const pmu::v5::Temperatures& s);
Json values_of(const pmu::v5::Status& s);
Json values_of(const pmu::v5::Config& s);
Json values_of(const pmu::v5::DeviceInfo& s);
Json values_of(const pmu::v5::Health& s);
// Batteries and MPPTs (interface.md 1.4): a value not received is null, for integer and
// boolean fields too (their `received` bit), so no consumer mistakes "not yet" for 0.
// Sentinels are null too (sample_fields.hpp).
Json values_of(const pmu::v5::Battery& s);
Json values_of(const pmu::v5::BatteryCells& s);
Json values_of(const pmu::v5::Mppt& s);

const char* to_string(pmu::v5::HealthState s);
const char* to_string(pmu::v5::BusState s);
const char* to_string(pmu::v5::DeviceKind k);  // "pmu", "battery", "mppt"

}  // namespace pmu::tools
