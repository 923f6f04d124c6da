#pragma once
// Which CAN ids a bus's socket passes up (transport/filters.hpp): the PMUs' always, and the
// batteries' and MPPTs' only on a bus that serves them (listed, or listen_canopen), so a
// PMU-only bus never wakes the service for frames it would drop.

#include <vector>

#include "pmu/config/config.hpp"
#include "pmu/transport/filters.hpp"

namespace pmu::service {

std::vector<transport::IdFilter> receive_filters(const BusConfig& bus);

}  // namespace pmu::service
