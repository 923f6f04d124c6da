// BusWorker seen from other threads (bus_worker.hpp): the sessions belong to the worker's
// thread; other threads read only device_count() (and progress()). Run under
// ThreadSanitizer (scripts/test.sh, build/tsan) these tests fail on a read of the session
// map from another thread, which is what pmu-service's status line did before
// device_count() existed (main.cpp's summary() called addresses() while discovery added
// sessions).
#include <gtest/gtest.h>

#include <atomic>
#include <thread>

#include "support/harness.hpp"
#include "support/wait.hpp"
#include "pmu/dispatch/command_service.hpp"

namespace pmu::service::test {
namespace {

using Clock = std::chrono::steady_clock;

TEST(WorkerThreads, DeviceCountIsReadFromAnotherThreadWhileTheWorkerDiscoversUnits) {
  constexpr std::uint16_t kUnits = 20;
  Harness h(sim_bus({}, true), {});
  ASSERT_EQ(h.worker().device_count(), 0u) << "nothing configured: every unit comes from discovery";

  std::atomic<bool> stop{false};
  std::thread worker([&] {
    // The units appear on the bus in two batches, one broadcast (10 s of bus time) apart,
    // so sessions are added while the other thread reads. The worker's turns, discovery
    // included, and the simulated units all run on this thread alone.
    for (int turn = 0; !stop; ++turn) {
      if (turn == 0 || turn == 150)
        for (std::uint16_t a = 1; a <= kUnits / 2; ++a)
          h.pmus().add(pmu(static_cast<std::uint16_t>(turn == 0 ? a : a + kUnits / 2)));
      h.run_for(100ms);
    }
  });
  // What the main thread's status line does once a second, here as often as it can.
  std::size_t seen = 0, reads = 0;
  bool shrank = false;
  const auto give_up = Clock::now() + 30s;  // liveness bound only: discovery takes a few turns
  while (seen < kUnits && Clock::now() < give_up) {
    const std::size_t n = h.worker().device_count();
    shrank = shrank || n < seen;
    seen = std::max(seen, n);
    ++reads;
    std::this_thread::yield();
  }
  stop = true;
  worker.join();

  EXPECT_EQ(seen, kUnits) << "after " << reads << " reads";
  EXPECT_FALSE(shrank) << "discovery only adds devices";
  // Now that the worker's thread has ended, its own view may be read here.
  EXPECT_EQ(h.worker().addresses().size(), h.worker().device_count());
}

// A verified CAN address change files the session under its new address (re-keying on the
// worker's thread): the published count follows the map.
TEST(WorkerThreads, DeviceCountFollowsAnAddressChange) {
  Harness h(sim_bus({device(1), device(2)}), {pmu(1), pmu(2)});
  std::vector<CommandReplyData> replies;
  CommandService commands({&h.worker()}, PolicyConfig{}, Timeouts{}, h.clock(),
                          [&](const CommandReplyData& r) { replies.push_back(r); });
  h.run_for(300ms);
  ASSERT_EQ(h.worker().device_count(), 2u);

  CommandSample r;
  r.request_id = "move-1";
  r.sender = "test";
  r.bus = "sim0";
  r.address = 1;
  r.kind = static_cast<std::uint32_t>(CommandKind::SetParameter);
  r.parameter = "can_address";
  r.value = 7;
  r.confirm = true;
  commands.submit(r);
  for (int i = 0; i < 100 && replies.empty(); ++i) h.run_for(10ms);
  ASSERT_EQ(replies.size(), 1u);
  ASSERT_EQ(replies[0].result, CommandResult::Completed) << replies[0].reason;
  h.run_for(50ms);
  EXPECT_EQ(h.worker().addresses(), (std::vector<std::uint16_t>{2, 7}));
  EXPECT_EQ(h.worker().device_count(), 2u);
}

// The threading model of pmu-service (main.cpp): the simulator's runner and the worker each
// turn in a thread of their own; work posted from another thread runs on the worker's; stop()
// from the main thread ends both, and the runner can be started again.
TEST(WorkerThreads, PostedWorkRunsOnTheWorkerThreadAndStopEndsBothLoops) {
  Harness h(sim_bus({device(1)}), {pmu(1)});
  h.pmus().start();
  std::atomic<bool> returned{false};
  std::thread::id worker_id;
  std::thread worker([&] {
    worker_id = std::this_thread::get_id();
    h.worker().run();
    returned = true;
  });
  std::atomic<bool> ran{false};
  std::thread::id ran_on;
  h.worker().post([&] {
    ran_on = std::this_thread::get_id();
    ran = true;
  });
  ASSERT_TRUE(pmu::test::wait_until([&] { return ran.load(); }, 10s));
  const auto progress = h.worker().progress();
  ASSERT_TRUE(pmu::test::wait_until([&] { return h.worker().progress() > progress; }, 10s))
      << "turns keep coming with nothing to do (the watchdog depends on it)";
  h.worker().stop();
  ASSERT_TRUE(pmu::test::wait_until([&] { return returned.load(); }, 10s)) << "stop() did not end run()";
  worker.join();
  EXPECT_EQ(ran_on, worker_id);
  h.pmus().stop();
  h.pmus().start();  // a runner stopped once runs again
  h.pmus().stop();
}

}  // namespace
}  // namespace pmu::service::test
