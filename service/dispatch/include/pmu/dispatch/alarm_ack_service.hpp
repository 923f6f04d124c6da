#pragma once
// Acknowledging an alarm from outside (pmu/alarm_ack -> pmu/alarm_ack_reply, interface.md
// 1.6): the raw sample as it arrived, the typed request parse_alarm_ack makes of it once, and
// AlarmAckService, which applies it on the bus worker's thread and answers exactly once.
//
// An acknowledgement is a request of its own, not a CommandKind: adding a kind to the command
// enum would break every client of contract v4 (interface.md 10.2), a new topic does not.
// It shares the command path's rules: ids are per sender, a resend is answered again and never
// applied twice, the same id with other content is REJECTED, every request and its result is
// an `audit:` line with network text through printable().
//
// Hot standby (design.md "Hot standby"): with a role gate set, only the instance that owns the
// bus applies and answers acknowledgements; the other neither applies nor answers one, and one
// still on its way when the gate closes is not answered here (a resend reaches the new owner,
// where acknowledging again is harmless: "nothing to acknowledge").
//
// Lifetime: every BusWorker in `workers`, `clock` and what `reply` refers to outlive the
// service; the source (DdsAlarmAckEndpoint::stop) is stopped and the workers joined before it
// is destroyed, as for CommandService.
// Threads: submit() from any thread (a Fast DDS listener); the acknowledgement itself on the
// bus's worker; `reply` from both, never under the service's lock.

#include <cstdint>
#include <deque>
#include <functional>
#include <mutex>
#include <optional>
#include <string>
#include <unordered_map>
#include <vector>

#include "pmu/alarms/alarm.hpp"
#include "pmu/alarms/alarm_table.hpp"
#include "pmu/codec/result.hpp"
#include "pmu/command/command.hpp"
#include "pmu/dispatch/command_service.hpp"
#include "pmu/session/bus_worker.hpp"

namespace pmu::service {

inline constexpr std::size_t kMaxAlarmCodeLength = 31;
inline constexpr std::size_t kMaxAckReasonLength = 127;

// A pmu/alarm_ack sample as it arrived: nothing in it is trusted.
struct AlarmAckSample {
  std::string sender;  // the DDS writer's GUID
  std::string request_id;
  std::string vehicle;
  std::string bus;
  std::int64_t kind = 0;  // AlarmSource as a number: any value a peer can send
  std::uint16_t device = 0;
  std::string code;
  std::uint64_t expires_at = 0;  // ns since the Unix epoch; 0 = the default lifetime
};

struct AlarmAckRequest {
  std::string sender;
  std::string request_id;
  std::string bus;
  alarms::DeviceKind kind = alarms::DeviceKind::Pmu;  // Pmu, Battery, Mppt or Bus
  std::uint16_t device = 0;                           // 0 for the bus's own
  alarms::Code code{};
  std::chrono::steady_clock::time_point expires;
};

enum class AckReplyResult : std::uint8_t { Completed, Rejected };
std::string_view to_string(AckReplyResult r) noexcept;  // "COMPLETED", "REJECTED"

struct AlarmAckReplyData {
  std::string request_id;
  std::string bus;
  std::int64_t kind = 0;  // as asked (AlarmSource's number), so the sender can match it
  std::uint16_t device = 0;
  std::string code;
  AckReplyResult result = AckReplyResult::Rejected;
  std::string reason;
  alarms::AlarmState state = alarms::AlarmState::Normal;  // after the acknowledgement
};

using AckReplyFn = std::function<void(const AlarmAckReplyData&)>;

// Total: a request, or the reason naming the field that is wrong. `vehicle` is this service's.
codec::Result<AlarmAckRequest, std::string> parse_alarm_ack(const AlarmAckSample& s, const std::string& vehicle,
                                                            const Now& now, const Lifetimes& lifetimes);

class AlarmAckService {
 public:
  AlarmAckService(std::vector<BusWorker*> workers, std::string vehicle, Lifetimes lifetimes,
                  const transport::Clock& clock, AckReplyFn reply);

  void submit(const AlarmAckSample& sample);

  // Hot standby: whether this instance applies and answers acknowledgements now. Unset, it
  // always does. Call before the first submit(); read on the caller's thread and the worker's,
  // never under the service's lock.
  void set_role_gate(std::function<bool()> applies_now);

  // Request ids remembered for duplicate detection (at most kRememberedRequests).
  std::size_t remembered() const;

 private:
  struct Entry {
    std::string content;  // what was asked, but the expiry: a resend with a new deadline is the same
    std::optional<AlarmAckReplyData> final;
    unsigned owed = 0;  // resends that arrived while it was applied
  };

  bool first_time(const std::string& key, const AlarmAckSample& s);
  void apply(BusWorker& worker, const AlarmAckRequest& r);
  void finish(const std::string& key, const AlarmAckSample& s, AlarmAckReplyData reply);
  bool applies_now() const { return !applies_now_ || applies_now_(); }
  // Every reply goes out here, the gate asked once more right before it (command_service.hpp).
  void send_reply(const AlarmAckReplyData& reply);
  // Not answered here: the gate closed while it was on its way. Forgotten, so that a resend
  // after this instance takes the bus back is applied.
  void let_go(const std::string& key, const AlarmAckSample& s);

  std::vector<BusWorker*> workers_;
  std::string vehicle_;
  Lifetimes lifetimes_;
  const transport::Clock& clock_;
  AckReplyFn reply_;

  mutable std::mutex mutex_;
  std::unordered_map<std::string, Entry> seen_;
  std::deque<std::string> order_;      // oldest first, to bound seen_
  std::function<bool()> applies_now_;  // set before start, then only read
};

}  // namespace pmu::service
