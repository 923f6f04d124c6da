#pragma once
// Makes Fast DDS 2.9.1's matching race (pmu/dds/security_match_guard.hpp) happen whenever it
// can. This test program defines WriterProxyData::set_remote_locators, which Fast DDS calls
// in match_builtin_endpoints between writing the remote participant's GUID into the
// participant's one proxy object and matching that proxy: the first call on a proxy waits
// until another thread calls it on the same proxy (which means that thread is inside
// match_builtin_endpoints too, and has overwritten the GUID), or until `kWindow` has passed.
// Without the guard the second discovery then always lands in the first one's window; with
// it the second waits for the first to finish.
//
// Threads: Fast DDS's receive threads; the counters from any thread.
#include <chrono>

namespace pmu::security_test {

inline constexpr std::chrono::seconds kWindow{3};

// Second callers that came while a first one waited on the same proxy: the race happened.
int match_overlaps();
// First callers that waited the whole window alone.
int match_windows_alone();

}  // namespace pmu::security_test
