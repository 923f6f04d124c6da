#pragma once
// pmu::test::until_answered: a command client is ready to count replies once one of its
// requests has been answered.
//
// Each side of a DDS match discovers the other on its own. A client whose command writer and
// reply reader have both matched the service's can still be unknown to the service's reply
// writer for a while (the client's reader announcement lost once and repaired by the next
// discovery heartbeat, seconds later on a loaded machine), and a VOLATILE writer never sends
// a reader what it wrote before it matched that reader. A reply that arrives proves the
// service's writer has matched this reader; from then on every reply reaches it. pmuctl
// covers the same gap by resending an unanswered request (interface.md 2.4), and so does
// this: the same probe, the same id, once per `resend_after`.
//
//   ASSERT_TRUE(pmu::test::until_answered([&] { send(probe); }, [&] { return got_reply_to(probe); }, 30s));
//
// Returns whether `answered` returned true within `within`. Called from the test's thread.
#include <chrono>

#include "wait.hpp"

namespace pmu::test {

template <class Send, class Answered>
bool until_answered(Send&& send_probe, Answered&& answered, std::chrono::steady_clock::duration within,
                    std::chrono::steady_clock::duration resend_after = std::chrono::seconds(1)) {
  const auto deadline = std::chrono::steady_clock::now() + within;
  do {
    send_probe();
    if (wait_until(answered, resend_after, std::chrono::milliseconds(2))) return true;
  } while (std::chrono::steady_clock::now() < deadline);
  return false;
}

}  // namespace pmu::test
