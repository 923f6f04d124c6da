#pragma once
// How the service's cost grows: CPU and RSS of pmu-service with 1, 10 and 100
// PMUs streaming every packet at 10 Hz, and with 1, 4 and 16 subscriber processes, each
// beside a bare Fast DDS writer process publishing the same samples/s of the same types
// to the same readers, measured in the same run.

#include "benchmarks.hpp"

namespace pmu::bench {

// Appends the scale rows. Uses `domain` for the service and `ref_domain` for the reference;
// nothing else may use them meanwhile.
void scale_rows(const Settings& s, Rows& rows, int domain, int ref_domain);

}  // namespace pmu::bench
