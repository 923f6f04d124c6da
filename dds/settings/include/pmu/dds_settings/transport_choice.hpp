#pragma once
// Which Fast DDS transports a participant uses; a header of its own so the configuration
// (which has no DDS) can name the choice.

namespace pmu::dds {

// Default: Fast DDS's builtin transports (UDPv4, and shared memory between processes on
// one host; Fast DDS 2.9 then sends each sample to a local reader both ways). UdpOnly:
// UDPv4 alone, so all traffic between participants on one host crosses the loopback
// interface (tests that look at the wire, readers running as another user). ShmOnly:
// shared memory alone, for a service whose readers all run on its own host.
enum class Transport { Default, UdpOnly, ShmOnly };

}  // namespace pmu::dds
