#pragma once
// Which PMU a command without --bus and --address went to, remembered by one of `pmuctl
// agent`'s workers for its later calls to the same vehicle. Finding "the only PMU" means
// reading the vehicle's pmu/health: over a radio link that reader's discovery and the
// service's repair of its history cost two round trips and more than the command itself
// (interface.md 7.3). A remembered PMU is tried first; when the service answers that it no
// longer has it ("device A not seen on BUS": moved, or the service restarted without it),
// nothing was executed, the call forgets it and finds the PMU afresh.
//
// Threads: one worker's verb thread at a time (ContextPool owns it).

#include <chrono>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <tuple>

namespace pmu::tools {

// A call's choice of PMU: its vehicle, and its --bus and --address when given.
struct TargetQuery {
  std::string vehicle;
  std::string bus;
  std::optional<std::uint16_t> address;
};

struct Target {
  std::string bus;
  std::uint16_t address = 0;
};

class TargetMemory {
 public:
  using Clock = std::chrono::steady_clock;
  // How long a PMU found is taken for the vehicle's only one without reading its health
  // again: a second PMU that came up on the vehicle meanwhile is noticed once this passes.
  static constexpr std::chrono::seconds kKeptFor{300};

  std::optional<Target> recall(const TargetQuery& query, Clock::time_point now) const;
  void remember(const TargetQuery& query, const Target& target, Clock::time_point now);
  void forget(const TargetQuery& query);

 private:
  using Key = std::tuple<std::string, std::string, int>;
  static Key key_of(const TargetQuery& query);
  std::map<Key, std::pair<Target, Clock::time_point>> found_;
};

// True when `reason`, a REJECTED reply's, says the service has no device at `target`: the
// command was not executed and may be sent again to the PMU found afresh.
bool says_target_gone(const std::string& reason, const Target& target);

}  // namespace pmu::tools
