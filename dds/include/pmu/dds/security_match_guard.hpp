#pragma once
// A guard against a data race in Fast DDS 2.9.1's SecurityManager (Debian bookworm's
// libfastrtps2.9; fixed upstream in 2.9.2). match_builtin_endpoints and
// match_builtin_key_exchange_endpoints fill one proxy object per participant before they
// match the remote participant's stateless or key-exchange endpoints. When a participant
// discovers two remote participants at once, on two of its receive threads (one announcement
// by multicast, one by unicast), the second overwrites the first's proxy, and the first
// remote participant's builtin endpoint is never matched: its handshake messages are dropped
// for as long as both participants live, silently, and neither side ever sees the other's
// topics.
//
// security_match_guard.cpp defines the two functions under their Fast DDS names. A program
// that links it exports them (the linker puts a symbol a shared library defines into the
// program's dynamic symbol table), so the library's own calls bind to these definitions,
// which take one mutex per function and call the library's. One mutex each, not one for
// both: the key-exchange one is called while a stateless reader is locked, the other locks
// that reader.
//
// Linking: DdsContext refers to security_match_guard_active(), so every program with a
// DdsContext has the guard. The source file needs nothing but libdl: a client of its own can
// carry a copy.
// Threads: any.

namespace pmu::dds {

// True when Fast DDS's calls to both functions come to the guard in this process. False when
// the program was linked without it, or a libfastrtps without these functions (another
// version) is loaded.
bool security_match_guard_active() noexcept;

}  // namespace pmu::dds
