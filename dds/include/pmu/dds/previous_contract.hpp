#pragma once
// The previous contract as pmu-service's `also_serve_contract` participant serves it
// (docs/interface.md section 10.3): its writers take this contract's samples, as every
// writer of the service does, and send them in the previous contract's layout and values.
// Types of the same layout and meaning are only renamed (DdsContext::topic); the types of
// kConvertedTypes are converted field by field, so a consumer of the previous contract
// reads exactly what that contract's services sent: 65535 rpm for no reading, 3,932,100 s
// for "not discharging", -1 s for "never heard", 0 / false for a value not received.

#include <fastdds/dds/topic/TypeSupport.hpp>

#include "pmu/idl/canopen.h"
#include "pmu/idl/state.h"
#include "pmu/idl/telemetry.h"
#include "pmu/idl_previous/canopen.h"
#include "pmu/idl_previous/state.h"
#include "pmu/idl_previous/telemetry.h"

namespace pmu::dds {

// The types (without the version module) whose layout or meaning differs from the previous
// contract's, each converted below. tests/contract/idl_layout.py reads this list: a layout
// change of a type of the previous contract that is not in it fails the guard.
inline constexpr const char* kConvertedTypes[] = {"Status", "Health", "Battery", "Mppt"};

// The previous contract's sample of a current one (pure, total: every float, NaN included).
pmu::v4::Status to_previous(const pmu::v5::Status& s);
pmu::v4::Health to_previous(const pmu::v5::Health& s);
pmu::v4::Battery to_previous(const pmu::v5::Battery& s);
pmu::v4::Mppt to_previous(const pmu::v5::Mppt& s);

// For a type of kConvertedTypes (`current` is e.g. new pmu::v5::StatusPubSubType()), the type
// that writes this contract's samples as the previous contract's, named as the previous
// contract names it; an empty TypeSupport for every other type. The converting type only
// writes: it deserialises nothing (the previous contract's participant reads only commands,
// which no version changed).
eprosima::fastdds::dds::TypeSupport previous_contract_type(const eprosima::fastdds::dds::TypeSupport& current);

}  // namespace pmu::dds
