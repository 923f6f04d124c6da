#pragma once
// pmu::test_support: waiting for a condition instead of sleeping a fixed time.
//
//   ASSERT_TRUE(pmu::test::wait_until([&] { return reader.matched(); }, 5s)) << "never matched";
//
// Polls `done` every `poll` until it returns true or `timeout` has passed; returns the last
// answer (so a condition that becomes true at the deadline still counts). The timeout is a
// bound for a loaded machine, never a measurement: make it generous.
#include <chrono>
#include <thread>

namespace pmu::test {

template <class Predicate>
bool wait_until(Predicate&& done, std::chrono::steady_clock::duration timeout,
                std::chrono::steady_clock::duration poll = std::chrono::milliseconds(10)) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  while (!done()) {
    if (std::chrono::steady_clock::now() >= deadline) return done();
    std::this_thread::sleep_for(poll);
  }
  return true;
}

}  // namespace pmu::test
