#pragma once
// Which of the program's protocols each of its service requests belongs to, and when to
// write one again (interface.md 2.1, 2.4). The parameter server and the command handler each
// number their requests from 1, so a reply's request id, not their tag, says whose it is:
// every id this program writes is its prefix and a number never used before in the process,
// routed to (owner, tag) until the owner has given up on it. Pure: time passed in.
//
// - A reply is routed by its request id alone; an id with this program's prefix but no route
//   (late, after its owner's timeout, or never written) is counted, another client's reply
//   (the reply topic carries every client's) is counted apart and ignored.
// - A request that has heard no reply is written again with the same id every resend_after
//   until it expires (interface.md 2.4: answered again, never executed twice), since a
//   request written before the service's reader matched this writer is lost. Any reply,
//   IN_PROGRESS included, proves the match and ends the resends.
// Not thread-safe: one thread (the program's loop) calls everything.

#include <chrono>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace pmu::mavlink_commands {

using Time = std::chrono::steady_clock::time_point;

enum class Owner : std::uint8_t { Params, Commands };

struct Route {
  Owner owner = Owner::Commands;
  std::uint64_t tag = 0;
};

struct RouteCounters {
  std::uint64_t opened = 0;
  std::uint64_t resends = 0;
  std::uint64_t replies_routed = 0;
  std::uint64_t replies_unknown = 0;  // this program's prefix, no route: late or never sent
  std::uint64_t replies_others = 0;   // another client's request
};

class RequestRoutes {
 public:
  // `prefix` starts every id ("pmu-mavlink-HOST-PID-"); `first` is the first number (the
  // start's nanoseconds of the Unix epoch, so a restarted process with the same pid never
  // reuses an id the service still remembers).
  RequestRoutes(std::string prefix, std::uint64_t first,
                std::chrono::milliseconds resend_after = std::chrono::milliseconds(1000));

  // A new request's id, routed to (owner, tag) until `forget_at`; written again while
  // unanswered until `expires` (its expires_at).
  std::string open(Route route, Time expires, Time forget_at, Time now);
  // The route of a reply; nullopt for none (counted). A final reply closes the route.
  std::optional<Route> on_reply(std::string_view request_id, bool final);
  // The ids to write again at `now`; routes past their forget_at are dropped.
  std::vector<std::string> due(Time now);
  std::size_t open_count() const noexcept { return routes_.size(); }

  const RouteCounters& counters() const noexcept { return counters_; }

 private:
  struct Entry {
    Route route;
    Time expires;
    Time forget_at;
    Time next_write;
    bool heard = false;
  };
  std::string prefix_;
  std::uint64_t next_;
  std::chrono::milliseconds resend_after_;
  std::map<std::string, Entry, std::less<>> routes_;
  RouteCounters counters_;
};

}  // namespace pmu::mavlink_commands
