// EventLoop (event_loop.hpp): fd readiness, posted work from other threads, timers by the
// injected clock, stop, and what a callback may do to the loop while it runs. Threads are
// waited for with wait_until, never with fixed sleeps; run these under TSan too.

#include "pmu/transport/event_loop.hpp"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <poll.h>
#include <sys/eventfd.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstdint>
#include <string>
#include <thread>
#include <vector>

#include "support/wait.hpp"

namespace pmu::transport::test {
namespace {

using namespace std::chrono_literals;
using std::chrono::milliseconds;

// A fd the test makes readable and unreadable at will.
class Signal {
 public:
  Signal() : fd_(::eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC)) {}
  int fd() const { return fd_.get(); }
  void raise() {
    const std::uint64_t one = 1;
    ASSERT_EQ(::write(fd_.get(), &one, sizeof one), static_cast<ssize_t>(sizeof one));
  }
  void consume() {
    std::uint64_t count = 0;
    (void)!::read(fd_.get(), &count, sizeof count);
  }

 private:
  UniqueFd fd_;
};

bool readable(int fd) {
  struct pollfd p {
    fd, POLLIN, 0
  };
  return ::poll(&p, 1, 0) == 1 && (p.revents & POLLIN) != 0;
}

class Loop : public ::testing::Test {
 protected:
  ManualClock clock_;
  EventLoop loop_{clock_, "test"};
};

// --- fds ---

TEST_F(Loop, ReadyFdCallsItsCallbackWithTheReportedEventsEveryTurnItStaysReady) {
  Signal s;
  std::vector<std::uint32_t> calls;
  ASSERT_EQ(loop_.watch(s.fd(), EventLoop::kReadable, [&](std::uint32_t e) { calls.push_back(e); }), 0);
  EXPECT_EQ(loop_.run_once(0ms), 0u) << "nothing ready yet";
  EXPECT_TRUE(calls.empty());

  s.raise();
  EXPECT_EQ(loop_.run_once(0ms), 1u);
  ASSERT_EQ(calls.size(), 1u);
  EXPECT_EQ(calls[0], static_cast<std::uint32_t>(EPOLLIN));
  // Level-triggered: not consumed, so called again.
  loop_.run_once(0ms);
  EXPECT_EQ(calls.size(), 2u);
  s.consume();
  loop_.run_once(0ms);
  EXPECT_EQ(calls.size(), 2u);
}

TEST_F(Loop, HangUpIsReportedToAReadableWatch) {
  int ends[2];
  ASSERT_EQ(::pipe2(ends, O_CLOEXEC | O_NONBLOCK), 0);
  UniqueFd read_end{ends[0]}, write_end{ends[1]};
  std::uint32_t seen = 0;
  ASSERT_EQ(loop_.watch(read_end.get(), EventLoop::kReadable, [&](std::uint32_t e) { seen |= e; }), 0);
  write_end.reset();  // the writer went away
  loop_.run_once(0ms);
  EXPECT_NE(seen & EPOLLHUP, 0u);
  EXPECT_EQ(loop_.unwatch(read_end.get()), 0);
}

TEST_F(Loop, WatchAndUnwatchReportErrorsAsValues) {
  Signal s;
  ASSERT_EQ(loop_.watch(s.fd(), EventLoop::kReadable, {}), 0);
  EXPECT_EQ(loop_.watch(s.fd(), EventLoop::kReadable, {}), EEXIST);
  EXPECT_EQ(loop_.unwatch(s.fd()), 0);
  EXPECT_EQ(loop_.unwatch(s.fd()), ENOENT);
  EXPECT_EQ(loop_.watch(-1, EventLoop::kReadable, {}), EBADF);
  // Watched again after the failure: nothing was left behind by it.
  EXPECT_EQ(loop_.watch(s.fd(), EventLoop::kReadable, {}), 0);
}

TEST_F(Loop, AWatchWithoutCallbackOnlyMakesTheLoopFdReadable) {
  Signal s;
  ASSERT_EQ(loop_.watch(s.fd(), EventLoop::kReadable, {}), 0);
  EXPECT_FALSE(readable(loop_.fd()));
  s.raise();
  EXPECT_TRUE(readable(loop_.fd())) << "another loop watching this one must wake";
  EXPECT_EQ(loop_.run_once(0ms), 0u);
  s.consume();
  EXPECT_FALSE(readable(loop_.fd()));
}

TEST_F(Loop, UnwatchingItselfInsideItsCallbackIsSafeAndFinal) {
  Signal s;
  int calls = 0;
  ASSERT_EQ(loop_.watch(s.fd(), EventLoop::kReadable,
                        [&](std::uint32_t) {
                          ++calls;
                          EXPECT_EQ(loop_.unwatch(s.fd()), 0);
                        }),
            0);
  s.raise();
  for (int i = 0; i < 3; ++i) loop_.run_once(0ms);  // still readable: never consumed
  EXPECT_EQ(calls, 1);
}

TEST_F(Loop, NoCallbackAfterUnwatchEvenForAnEventCollectedThisTurn) {
  // Both are ready in the same turn; whichever runs first unwatches the other.
  Signal a, b;
  int a_calls = 0, b_calls = 0;
  ASSERT_EQ(loop_.watch(a.fd(), EventLoop::kReadable,
                        [&](std::uint32_t) {
                          ++a_calls;
                          loop_.unwatch(b.fd());
                        }),
            0);
  ASSERT_EQ(loop_.watch(b.fd(), EventLoop::kReadable,
                        [&](std::uint32_t) {
                          ++b_calls;
                          loop_.unwatch(a.fd());
                        }),
            0);
  a.raise();
  b.raise();
  EXPECT_EQ(loop_.run_once(0ms), 1u);
  ASSERT_EQ(a_calls + b_calls, 1);
  const bool a_won = a_calls == 1;
  // Both fds stay readable: only the survivor is called from now on.
  for (int i = 0; i < 3; ++i) loop_.run_once(0ms);
  EXPECT_EQ(a_won ? b_calls : a_calls, 0);
  EXPECT_EQ(a_won ? a_calls : b_calls, 4);
}

TEST_F(Loop, AnFdUnwatchedAndWatchedAgainInOneTurnGetsOnlyTheNewCallback) {
  Signal s, trigger;
  std::vector<std::string> calls;
  ASSERT_EQ(loop_.watch(s.fd(), EventLoop::kReadable, [&](std::uint32_t) { calls.push_back("old"); }), 0);
  ASSERT_EQ(loop_.watch(trigger.fd(), EventLoop::kReadable,
                        [&](std::uint32_t) {
                          trigger.consume();
                          loop_.unwatch(s.fd());
                          loop_.watch(s.fd(), EventLoop::kReadable, [&](std::uint32_t) { calls.push_back("new"); });
                        }),
            0);
  trigger.raise();
  s.raise();
  loop_.run_once(0ms);
  loop_.run_once(0ms);
  ASSERT_FALSE(calls.empty());
  // The old callback may have run only if epoll reported `s` before the trigger.
  EXPECT_EQ(calls.back(), "new");
  for (std::size_t i = 1; i < calls.size(); ++i) EXPECT_EQ(calls[i], "new");
}

// --- posted work ---

TEST_F(Loop, PostedWorkRunsOnTheLoopThreadInPostingOrder) {
  std::vector<int> order;
  std::thread::id ran_on;
  std::atomic<bool> done{false};
  std::thread loop_thread([&] {
    ran_on = std::this_thread::get_id();
    loop_.run();  // no timers, no max_wait: only posted work or stop ends a wait
  });
  for (int i = 0; i < 5; ++i) loop_.post([&, i] { order.push_back(i); });
  loop_.post([&] { done = true; });
  ASSERT_TRUE(pmu::test::wait_until([&] { return done.load(); }, 10s));
  loop_.stop();
  loop_thread.join();
  EXPECT_EQ(order, (std::vector<int>{0, 1, 2, 3, 4}));
  EXPECT_NE(ran_on, std::this_thread::get_id());
}

TEST_F(Loop, UrgentWorkRunsBeforeTheTurnsFdsAndBeforeWorkPostedEarlier) {
  Signal s;
  s.raise();
  std::vector<std::string> order;
  ASSERT_EQ(loop_.watch(s.fd(), EventLoop::kReadable,
                        [&](std::uint32_t) {
                          order.push_back("fd");
                          s.consume();
                        }),
            0);
  loop_.post([&] { order.push_back("work 1"); });
  loop_.post([&] { order.push_back("work 2"); });
  loop_.post_urgent([&] { order.push_back("urgent 1"); });
  loop_.post_urgent([&] { order.push_back("urgent 2"); });
  EXPECT_EQ(loop_.run_once(0ms), 5u);
  EXPECT_EQ(order, (std::vector<std::string>{"urgent 1", "urgent 2", "fd", "work 1", "work 2"}));
}

TEST_F(Loop, UrgentWorkPostedByAnFdCallbackRunsThatTurnBeforeTheOtherWork) {
  Signal s;
  s.raise();
  std::vector<std::string> order;
  ASSERT_EQ(loop_.watch(s.fd(), EventLoop::kReadable,
                        [&](std::uint32_t) {
                          s.consume();
                          loop_.post_urgent([&] { order.push_back("urgent"); });
                        }),
            0);
  loop_.post([&] { order.push_back("work"); });
  loop_.run_once(0ms);
  EXPECT_EQ(order, (std::vector<std::string>{"urgent", "work"}));
}

TEST_F(Loop, PostFromAnotherThreadEndsAWaitWithoutBound) {
  std::atomic<bool> returned{false};
  std::atomic<std::size_t> called{0};
  std::thread loop_thread([&] {
    called = loop_.run_once(EventLoop::kForever);
    returned = true;
  });
  loop_.post([] {});
  ASSERT_TRUE(pmu::test::wait_until([&] { return returned.load(); }, 10s)) << "post did not wake the loop";
  loop_thread.join();
  EXPECT_EQ(called.load(), 1u);
}

TEST_F(Loop, WorkPostedByWorkRunsNextTurnAndTheLoopFdSaysSo) {
  int second = 0;
  loop_.post([&] { loop_.post([&] { ++second; }); });
  EXPECT_TRUE(readable(loop_.fd()));
  EXPECT_EQ(loop_.run_once(0ms), 1u);
  EXPECT_EQ(second, 0);
  EXPECT_TRUE(readable(loop_.fd()));
  EXPECT_EQ(loop_.run_once(0ms), 1u);
  EXPECT_EQ(second, 1);
  EXPECT_FALSE(readable(loop_.fd()));
}

TEST_F(Loop, WakeEndsTheWaitAndRunsNothing) {
  loop_.wake();
  EXPECT_TRUE(readable(loop_.fd()));
  EXPECT_EQ(loop_.run_once(EventLoop::kForever), 0u);
  EXPECT_FALSE(readable(loop_.fd()));
}

// --- timers ---

TEST_F(Loop, TimersFireInDeadlineOrderWhenTheClockPassesThem) {
  const auto t0 = clock_.steady_now();
  std::vector<std::string> fired;
  std::vector<EventLoop::TimePoint> when;
  auto record = [&](const char* name) {
    return [&, name](EventLoop::TimePoint now) {
      fired.push_back(name);
      when.push_back(now);
    };
  };
  loop_.add_timer(t0 + 30ms, 0ms, record("30"));
  loop_.add_timer(t0 + 10ms, 0ms, record("10a"));
  loop_.add_timer(t0 + 20ms, 0ms, record("20"));
  loop_.add_timer(t0 + 10ms, 0ms, record("10b"));  // same deadline: added later, fires later

  clock_.advance(9ms);
  EXPECT_EQ(loop_.run_once(0ms), 0u) << "nothing is due before its deadline";
  clock_.advance(16ms);  // t0 + 25 ms
  EXPECT_EQ(loop_.run_once(0ms), 3u);
  EXPECT_EQ(fired, (std::vector<std::string>{"10a", "10b", "20"}));
  clock_.advance(5ms);  // exactly t0 + 30 ms: due
  EXPECT_EQ(loop_.run_once(0ms), 1u);
  EXPECT_EQ(fired.back(), "30");
  EXPECT_EQ(when.back(), t0 + 30ms) << "the callback gets the reading it was found due by";
  clock_.advance(1s);
  EXPECT_EQ(loop_.run_once(0ms), 0u) << "one-shot timers fire once";
}

TEST_F(Loop, PeriodicTimerKeepsItsRateAndSkipsWhatALateLoopMissed) {
  const auto t0 = clock_.steady_now();
  std::vector<milliseconds> fired;
  loop_.add_timer(
      t0, 10ms, [&](EventLoop::TimePoint now) { fired.push_back(std::chrono::duration_cast<milliseconds>(now - t0)); });
  loop_.run_once(0ms);  // due at once
  clock_.advance(4ms);
  loop_.run_once(0ms);  // t0 + 4: not yet
  clock_.advance(6ms);
  loop_.run_once(0ms);  // t0 + 10: on its rate, not 10 ms after the turn that fired it
  clock_.advance(35ms);
  loop_.run_once(0ms);  // t0 + 45: late by three periods, fires once
  clock_.advance(9ms);
  loop_.run_once(0ms);  // t0 + 54: next is t0 + 55, 10 ms after the late firing
  clock_.advance(1ms);
  loop_.run_once(0ms);  // t0 + 55
  EXPECT_EQ(fired, (std::vector<milliseconds>{0ms, 10ms, 45ms, 55ms}));
}

TEST_F(Loop, OneShotTimerStaysRegisteredAndScheduleArmsItAgain) {
  const auto t0 = clock_.steady_now();
  int fired = 0;
  const auto id = loop_.add_timer(t0 + 5ms, 0ms, [&](EventLoop::TimePoint) { ++fired; });
  clock_.advance(5ms);
  loop_.run_once(0ms);
  ASSERT_EQ(fired, 1);
  EXPECT_TRUE(loop_.schedule(id, t0 + 20ms));
  clock_.advance(10ms);
  loop_.run_once(0ms);
  EXPECT_EQ(fired, 1);
  clock_.advance(5ms);
  loop_.run_once(0ms);
  EXPECT_EQ(fired, 2);

  EXPECT_TRUE(loop_.schedule(id, t0));
  EXPECT_TRUE(loop_.disarm(id));
  loop_.run_once(0ms);
  EXPECT_EQ(fired, 2) << "disarmed";
  EXPECT_TRUE(loop_.remove_timer(id));
  EXPECT_FALSE(loop_.schedule(id, t0));
  EXPECT_FALSE(loop_.remove_timer(id));
}

TEST_F(Loop, ATimerMayRemoveItselfOrReArmInThePastWithoutStallingTheTurn) {
  const auto t0 = clock_.steady_now();
  int removed_calls = 0, eager_calls = 0;
  EventLoop::TimerId self = 0;
  self = loop_.add_timer(t0, 1ms, [&](EventLoop::TimePoint) {
    ++removed_calls;
    EXPECT_TRUE(loop_.remove_timer(self));
  });
  EventLoop::TimerId eager = 0;
  eager = loop_.add_timer(t0, 0ms, [&](EventLoop::TimePoint now) {
    ++eager_calls;
    loop_.schedule(eager, now - 1ms);  // always due: at most once per turn all the same
  });
  EXPECT_EQ(loop_.run_once(0ms), 2u);
  clock_.advance(5ms);
  EXPECT_EQ(loop_.run_once(0ms), 1u);
  EXPECT_EQ(removed_calls, 1);
  EXPECT_EQ(eager_calls, 2);
}

TEST(LoopTimers, TheWaitEndsAtTheEarliestDeadlineOfTheRealClock) {
  SystemClock clock;
  EventLoop loop{clock, "test"};
  const auto deadline = clock.steady_now() + 30ms;
  EventLoop::TimePoint fired_at{};
  loop.add_timer(deadline, 0ms, [&](EventLoop::TimePoint now) { fired_at = now; });
  loop.add_timer(deadline + 1h, 0ms, {});
  // No bound on the wait: only the timer ends it, and it is due when the wait ends.
  EXPECT_EQ(loop.run_once(EventLoop::kForever), 1u);
  EXPECT_GE(fired_at, deadline);
  EXPECT_GE(clock.steady_now(), deadline);
}

TEST(LoopTimers, MaxWaitBoundsTheWaitBeforeALaterTimer) {
  SystemClock clock;
  EventLoop loop{clock, "test"};
  const auto start = clock.steady_now();
  int fired = 0;
  loop.add_timer(start + 1h, 0ms, [&](EventLoop::TimePoint) { ++fired; });
  EXPECT_EQ(loop.run_once(20ms), 0u);
  EXPECT_GE(clock.steady_now(), start + 20ms);
  EXPECT_EQ(fired, 0);
}

// --- run and stop ---

TEST_F(Loop, StopFromAnotherThreadEndsRunAfterTheTurnInProgress) {
  std::atomic<int> turns{0};
  std::atomic<bool> returned{false};
  std::thread loop_thread([&] {
    loop_.run(EventLoop::kForever, [&] { ++turns; });
    returned = true;
  });
  loop_.post([] {});
  ASSERT_TRUE(pmu::test::wait_until([&] { return turns.load() >= 1; }, 10s));
  loop_.stop();
  ASSERT_TRUE(pmu::test::wait_until([&] { return returned.load(); }, 10s)) << "stop did not end run()";
  loop_thread.join();
  EXPECT_FALSE(loop_.stop_requested()) << "run() consumes the request";
}

TEST_F(Loop, StopFromInsideACallbackEndsRunWhenTheTurnEnds) {
  int turns = 0, later_work = 0;
  loop_.post([&] {
    loop_.stop();
    loop_.post([&] { ++later_work; });
  });
  loop_.run(EventLoop::kForever, [&] { ++turns; });
  EXPECT_EQ(turns, 1) << "the turn that asked for the stop still finished";
  EXPECT_EQ(later_work, 0) << "work posted during the last turn waits for the next run";
  loop_.post([&] { loop_.stop(); });
  loop_.run();
  EXPECT_EQ(later_work, 1) << "run() runs again after a stop";
}

TEST_F(Loop, StopBeforeRunMakesItReturnAtOnce) {
  int turns = 0;
  loop_.stop();
  loop_.run(EventLoop::kForever, [&] { ++turns; });
  EXPECT_EQ(turns, 0);
}

}  // namespace
}  // namespace pmu::transport::test
