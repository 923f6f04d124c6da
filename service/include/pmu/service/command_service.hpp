#pragma once
// CommandService: the front door for commands, callable from any thread (the DDS listener).
// It guarantees exactly one final reply per request id:
//   * a repeated request id is answered again with the first one's result, never executed
//     twice (while the first is still running, the answer is owed and sent when it ends);
//   * expired, malformed, unroutable, denied or rate-limited requests are answered at once,
//     with nothing sent to a bus;
//   * valid ones run on their bus worker's thread (command_executor.hpp), serialised per
//     device by the device session, in parallel across devices and buses.
// Every command and its result is logged as an audit trail (who, what, result, reason).

#include <chrono>
#include <deque>
#include <map>
#include <mutex>
#include <string>
#include <unordered_map>
#include <vector>

#include "pmu/service/bus_worker.hpp"
#include "pmu/service/command.hpp"
#include "pmu/service/command_executor.hpp"
#include "pmu/service/policy.hpp"

namespace pmu::service {

class CommandService {
 public:
  // `reply` publishes a reply; it is called from bus worker threads and the caller's thread.
  CommandService(std::vector<BusWorker*> workers, PolicyConfig policy, Timeouts timeouts,
                 const transport::Clock& clock, ReplyFn reply);

  void submit(CommandRequest request);

  struct Counters {
    std::uint64_t received = 0, duplicates = 0, completed = 0, refused = 0, failed = 0;
  };
  Counters counters() const;

 private:
  struct Entry {
    std::optional<CommandReplyData> final;
    unsigned owed = 0;  // duplicates that arrived while it ran
    std::string what;   // describe(request), for the audit trail
    std::string sender;
  };

  void finish(const CommandReplyData& reply);
  void answer_now(const CommandRequest& r, CommandResult result, std::string reason);
  BusWorker* worker_for(const std::string& bus) const;

  std::vector<BusWorker*> workers_;
  PolicyConfig policy_;
  Timeouts timeouts_;
  const transport::Clock& clock_;
  ReplyFn reply_;

  mutable std::mutex mutex_;
  std::unordered_map<std::string, Entry> seen_;
  std::deque<std::string> order_;  // oldest first, to bound seen_
  std::map<std::pair<std::string, std::uint16_t>, RateLimiter> limiters_;
  Counters counters_;
};

}  // namespace pmu::service
