#pragma once
// pmu::test_support: probes of the loopback's UDP ports, for tests that need a port nobody
// uses (a Discovery Server's) or must know whether a DDS participant listens on a domain.
// Plain sockets, no DDS; callable from any thread.
#include <cstdint>

namespace pmu::test {

// True when no participant listens on DDS domain `domain`'s multicast discovery port
// (7400 + 250 * domain, Fast DDS's default port mapping): a participant with multicast
// discovery binds it with SO_REUSEADDR, so a bind without it fails while the participant
// lives. A participant on shared memory alone is not seen.
bool dds_discovery_port_free(int domain);

// A UDP port on 127.0.0.1 that was free a moment ago (bound, read back, released): 0 when
// the kernel gave none.
std::uint16_t free_udp_port();

}  // namespace pmu::test
