#pragma once
// Which Fast DDS transports a participant uses; a header of its own so the configuration
// (which has no DDS) can name the choice.

namespace pmu::dds {

// Default: Fast DDS's builtin transports (UDPv4, and shared memory between processes on
// one host). UdpOnly: UDPv4 alone, so all traffic between participants on one host crosses
// the loopback interface (tests that look at the wire, readers running as another user).
enum class Transport { Default, UdpOnly };

}  // namespace pmu::dds
