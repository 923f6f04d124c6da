#pragma once
// The bus side of a fake-clock Harness (support/harness.hpp) run in a thread of its own
// while the DDS side runs in real time: 10 ms of bus time per 2 ms of real time, so bus time
// runs about five times faster. With `repeated` frames, a node on the same simulated bus sends
// them again every 200 ms of bus time, as a BMS and an MPPT repeat their values.
//
// The Harness must outlive the BusThread, and while one runs nothing else may drive the
// Harness (run_for, network()): the thread is its only caller until the destructor joins it.
#include <atomic>
#include <chrono>
#include <memory>
#include <thread>
#include <vector>

#include "support/harness.hpp"

namespace pmu::service::test {

class BusThread {
 public:
  explicit BusThread(Harness& h, std::vector<codec::CanFrame> repeated = {})
      : h_(h),
        node_(repeated.empty() ? nullptr : h.network().attach("repeating-node")),
        repeated_(std::move(repeated)),
        t_([this] { run(); }) {}
  ~BusThread() {
    stop_ = true;
    t_.join();
  }
  BusThread(const BusThread&) = delete;
  BusThread& operator=(const BusThread&) = delete;

 private:
  void run() {
    using namespace std::chrono_literals;
    auto next = h_.clock().steady_now();
    while (!stop_) {
      if (node_ && h_.clock().steady_now() >= next) {
        for (const auto& f : repeated_) (void)node_->send(f, 0ms);
        next += 200ms;
      }
      h_.run_for(10ms);
      // Meant: real time passes between steps of bus time (the DDS side runs in real time).
      std::this_thread::sleep_for(2ms);
    }
  }

  Harness& h_;
  std::unique_ptr<transport::SimBus> node_;
  std::vector<codec::CanFrame> repeated_;
  std::atomic<bool> stop_{false};
  std::thread t_;  // last: started once everything it uses is constructed
};

}  // namespace pmu::service::test
