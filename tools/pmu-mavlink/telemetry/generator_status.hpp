#pragma once
// GENERATOR_STATUS (373) from one PMU: its generator input and the engine it starts
// (interface.md "pmu-mavlink"). Pure: a view in, a message out. Fields the PMU does not
// measure (rectifier temperature, set-point, runtime, maintenance) keep their "not
// provided" values; while the PMU is not ONLINE only COMMUNICATION_WARNING is set and every
// measured field is "not provided" (docs/safety.md H7).
#include "pmu/mavlink/messages.hpp"
#include "telemetry/device_views.hpp"

namespace pmu::mavlink_bridge {

pmu::mavlink::GeneratorStatus generator_status(const PmuView& pmu);

}  // namespace pmu::mavlink_bridge
