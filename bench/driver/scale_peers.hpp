#pragma once
// The processes of the scale rows (pmu_bench peer-telemetry|peer-reader), started by `run`.

#include "peers.hpp"

namespace pmu::bench {

// The bare reference for the scale rows: a participant with the service's eight writers
// (five telemetry, three state; the same QoS profiles, instance limits for `units`) that
// writes the five telemetry samples of each of `units` PMUs every `period` seconds, the
// samples/s pmu-service publishes for that many streaming PMUs. Runs until SIGTERM.
int peer_telemetry(const PeerOptions& o);

// A subscriber process: the five telemetry readers (telemetry_readers.hpp). Runs until
// SIGTERM, then prints "peer-reader: N samples" on stdout.
int peer_reader(const PeerOptions& o);

}  // namespace pmu::bench
