#pragma once
// CommandService: the front door for commands, callable from any thread (the DDS listener).
// It guarantees exactly one final reply per received sample:
//   * every sample is parsed once (parse_command, command.hpp); one that does not parse is
//     REJECTED with the reason, with nothing sent to a bus;
//   * a request id is remembered per sender (ids are unique per sender, not globally): a
//     resend with the same content is answered again with the first one's result, never
//     executed twice (while the first still runs, the answer is owed and sent when it ends);
//     the same id with other content is REJECTED, never answered with the other's reply;
//   * expired, unroutable or rate-limited requests are answered at once, with nothing sent
//     to a bus; the deny list and confirm rules judge a request on its bus worker's thread,
//     after the device check, since the rules judged by effect read what the device reports
//     now (policy.hpp's DeviceUse), which lives on that thread; a DENIED one sends nothing;
//   * while an apply holds a device's configuration (interface.md 2.8), another writer's
//     change to it is DENIED, naming the holder; a stop and a plain GET never are;
//   * valid ones run on their bus worker's thread (command_executor.hpp), serialised per
//     device by the device session, in parallel across devices and buses.
// Replies are handed to `reply` outside the service's lock. Every command and its result is
// logged as an audit trail (who, what, result, reason), with network text made printable.
// Resends that came long after their reply was out say the clients' link is slow: the
// service logs once that a link profile exists (slow_link_hint.hpp, interface.md 7.3).
//
// Hot standby (design.md "Hot standby", interface.md 2.4): with a role gate set, the service
// executes and answers only while the gate says this instance owns the bus. Otherwise a
// request is recorded, neither executed nor answered, and so are the owner's replies
// (peer_reply) and the command frames heard on CAN (heard_on_can) in a FailoverRecord; on
// took_over() each recorded request is answered from the owner's reply, answered FAILED
// "outcome unknown" when its frames were heard but no reply (when the client sends it again:
// the owner's reply may have reached the client already), run when it was never seen on the
// bus and has not expired, and an ENGINE_STOP always runs (docs/safety.md H4, H8). A request
// still running when the gate closes is not answered here: its reply is the new owner's
// (relinquished to the record, in case this instance takes the bus back).
//
// Memory: at most kRememberedRequests ids are kept (oldest forgotten first); no request
// lives longer than policy.lifetimes.max_lifetime, so at any rate below
// kRememberedRequests per max_lifetime no live request's id is ever forgotten.
//
// Lifetime: every BusWorker in `workers`, `clock`, and whatever `reply` refers to (main.cpp:
// the DdsCommandEndpoint) must outlive the service; it keeps pointers and a reference. Work
// it posts to a worker refers to the service, so the command source is stopped
// (DdsCommandEndpoint::stop) and the worker threads joined before it is destroyed: main.cpp's
// Shutdown does both.
// The gate is read on the caller's thread and the worker's, never under `mutex_`: it must
// not call into the service.
// Threads: submit(), counters(), remembered(), recorded(), peer_reply(), heard_on_can() and
// took_over() from any thread (in the daemon, a Fast DDS listener thread calls submit() and
// peer_reply(), the bus worker heard_on_can()); `mutex_` guards what they share. The stages
// after BusWorker::post run on that worker's thread. `reply` is called from both, never under
// `mutex_`.

#include <chrono>
#include <deque>
#include <functional>
#include <map>
#include <mutex>
#include <string>
#include <unordered_map>
#include <vector>

#include "pmu/command/command.hpp"
#include "pmu/command/config_holds.hpp"
#include "pmu/command/policy.hpp"
#include "pmu/codec/can_frame.hpp"
#include "pmu/dispatch/command_executor.hpp"
#include "pmu/dispatch/failover_record.hpp"
#include "pmu/dispatch/slow_link_hint.hpp"
#include "pmu/session/bus_worker.hpp"

namespace pmu::service {

inline constexpr std::size_t kRememberedRequests = 16384;

class CommandService {
 public:
  // `reply` publishes a reply; it is called from bus worker threads and the caller's thread.
  CommandService(std::vector<BusWorker*> workers, PolicyConfig policy, Timeouts timeouts, const transport::Clock& clock,
                 ReplyFn reply);

  void submit(const CommandSample& sample);

  struct Counters {
    std::uint64_t received = 0, duplicates = 0, reused_ids = 0, completed = 0, refused = 0, failed = 0;
    // Duplicates that arrived SlowLinkHint::kReplyOut or longer after their final reply.
    std::uint64_t resends_after_reply = 0;
    // Hot standby: the bus owner's replies kept while this instance did not execute.
    std::uint64_t peer_replies = 0;
  };
  Counters counters() const;
  // Request ids currently remembered for duplicate detection (at most kRememberedRequests).
  std::size_t remembered() const;
  // The config names the link (a profile or a round trip): no slow-link hint. Call before
  // the first submit().
  void link_configured();

  // Hot standby: whether this instance executes and answers commands now (it owns the bus).
  // Unset, it always does. Call before the first submit().
  void set_role_gate(std::function<bool()> executes_now);
  // A reply the bus owner wrote on pmu/command_reply (not this service's own), kept while
  // this instance does not execute.
  void peer_reply(const CommandReplyData& reply);
  // Every frame this instance's bus `bus` delivers, with its receive time; kept while this
  // instance does not execute.
  void heard_on_can(const std::string& bus, const codec::CanFrame& frame, SteadyTime at);
  // This instance owns the bus now (the gate says so): every recorded request is settled once
  // (failover_record.hpp). The first submit() after the gate opens does it too, so no request
  // runs ahead of the ones recorded before it; a later call finds nothing to do, unless a
  // request arrived as the gate opened and was recorded after the first: the holder calls it on
  // each of its ticks while ACTIVE, which costs a lock when there is nothing.
  void took_over(SteadyTime now);
  // Requests held for a takeover.
  std::size_t recorded() const;

 private:
  struct Entry {
    std::uint64_t fingerprint = 0;
    std::optional<CommandReplyData> final;
    SteadyTime final_at{};  // when `final` was published
    unsigned owed = 0;      // resends that arrived while it ran
  };
  enum class Seen { New, Resend, Reused };

  // Why a stage stopped a command: its final reply.
  struct Refusal {
    CommandResult result = CommandResult::Rejected;
    std::string reason;
  };

  // The stages of submit(), in order (each answers or lets the command on):
  void reject_without_id(const CommandSample& s);
  bool executes_now() const { return !executes_now_ || executes_now_(); }
  // Every reply goes out here, the gate asked once more right before it: an owner frozen after
  // it decided and woken after its peer took over writes nothing the new owner contradicts.
  void send_reply(const CommandReplyData& reply);
  // submit()'s stages after duplicate detection: parse (at `now`), route, limit, post.
  void admit(const std::string& key, const CommandSample& s, const Now& now);
  // The request under `key` ran while the gate closed: not answered here (its reply is the new
  // owner's), held as heard in the record.
  void relinquish(const std::string& key, const CommandReplyData& reply);
  // Duplicate detection: false when `s` is a resend (answered again) or reuses an id.
  bool first_time(const std::string& key, const CommandSample& s);
  // `slow_link`: this resend makes the slow-link hint due (log it, outside the lock), with the
  // time its reply had been out.
  Seen remember(const std::string& key, const CommandSample& s, std::optional<CommandReplyData>& again,
                std::optional<std::chrono::nanoseconds>& slow_link);
  // Routing: the bus is not one of this service's (when worker_for found none).
  Refusal not_served(const CommandRequest& r) const;
  // The deny list and confirm rules (policy.hpp), on the worker's thread: `use` is what the
  // session knows of the device now.
  std::optional<Refusal> judge(const CommandRequest& r, const DeviceUse& use) const;
  static DeviceUse device_use(const DeviceSession& session, SteadyTime now);
  // The per-device token bucket; never for engine stop.
  std::optional<Refusal> limit_rate(const CommandRequest& r);
  // ...and on the bus worker's thread:
  void run_on_worker(BusWorker& worker, const CommandRequest& r);
  void broadcast(BusWorker& worker, const CommandRequest& r);
  // An engine stop to the broadcast address with no bus named: sent on every bus served.
  void broadcast_on_every_bus(const CommandRequest& r);
  // A broadcast stop reaches every unit: it ends each engine start in progress on `worker`.
  void stop_engine_starts(BusWorker& worker, const std::string& request_id);
  // Known, read (firmware known) and, for an address change, the new address free.
  std::optional<Refusal> check_device(BusWorker& worker, const DeviceSession* session, const CommandRequest& r);
  // An apply's hold on the device (config_holds.hpp): checked on the worker's thread, in the
  // order the device's commands are queued, so nothing admitted before a hold lands after it.
  std::optional<Refusal> check_hold(const CommandRequest& r);

  // Records the final reply under `key`, logs it and publishes it (and the owed copies).
  void finish(const std::string& key, const std::string& sender, const std::string& what,
              const CommandReplyData& reply);
  void answer(const CommandRequest& r, CommandResult result, std::string reason);
  void refuse(const CommandRequest& r, const Refusal& refusal);
  BusWorker* worker_for(const std::string& bus) const;

  std::vector<BusWorker*> workers_;
  PolicyConfig policy_;
  Timeouts timeouts_;
  const transport::Clock& clock_;
  ReplyFn reply_;

  mutable std::mutex mutex_;
  std::unordered_map<std::string, Entry> seen_;  // by sender_key(sender, request_id)
  std::deque<std::string> order_;                // oldest first, to bound seen_
  std::map<std::pair<std::string, std::uint16_t>, RateLimiter> limiters_;
  ConfigHolds holds_;
  SlowLinkHint slow_link_;
  Counters counters_;
  std::function<bool()> executes_now_;  // set before start, then only read
  FailoverRecord record_;
};

}  // namespace pmu::service
