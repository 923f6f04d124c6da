#include "pmu/session/receive_filters.hpp"

namespace pmu::service {

std::vector<transport::IdFilter> receive_filters(const BusConfig& bus) {
  return transport::default_filters(bus.wants_canopen());
}

}  // namespace pmu::service
