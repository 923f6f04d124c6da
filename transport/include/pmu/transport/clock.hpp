#pragma once
// The time source of transport/ (and of anything above it that wants the same one).
// Injected so that send deadlines, reopen intervals and simulated receive timestamps can be
// driven by a test without sleeping (docs/design.md: the clock is injected).

#include <atomic>
#include <chrono>

namespace pmu::transport {

class Clock {
 public:
  virtual ~Clock() = default;
  // For deadlines and intervals: never jumps.
  virtual std::chrono::steady_clock::time_point steady_now() const noexcept = 0;
  // For timestamps that leave the process (DDS source timestamps, logs).
  virtual std::chrono::system_clock::time_point system_now() const noexcept = 0;
};

class SystemClock final : public Clock {
 public:
  std::chrono::steady_clock::time_point steady_now() const noexcept override {
    return std::chrono::steady_clock::now();
  }
  std::chrono::system_clock::time_point system_now() const noexcept override {
    return std::chrono::system_clock::now();
  }
};

// A clock that moves only when told to. Both readings advance together. Safe to read from
// several threads (a simulated network may be driven from more than one).
class ManualClock final : public Clock {
 public:
  // Starts at an arbitrary but fixed wall time so tests can print readable timestamps.
  ManualClock() noexcept = default;
  explicit ManualClock(std::chrono::system_clock::time_point wall_start) noexcept : wall_start_(wall_start) {}

  std::chrono::steady_clock::time_point steady_now() const noexcept override {
    return std::chrono::steady_clock::time_point{
        std::chrono::duration_cast<std::chrono::steady_clock::duration>(elapsed())};
  }
  std::chrono::system_clock::time_point system_now() const noexcept override {
    return wall_start_ + std::chrono::duration_cast<std::chrono::system_clock::duration>(elapsed());
  }
  void advance(std::chrono::nanoseconds step) noexcept { elapsed_ns_.fetch_add(step.count()); }

 private:
  std::chrono::nanoseconds elapsed() const noexcept { return std::chrono::nanoseconds{elapsed_ns_.load()}; }
  // 2023-11-14T22:13:20Z, the epoch second of the sample candump logs.
  std::chrono::system_clock::time_point wall_start_{std::chrono::seconds{1700000000}};
  std::atomic<std::chrono::nanoseconds::rep> elapsed_ns_{0};
};

}  // namespace pmu::transport
