#pragma once
// The parameter protocol's server side for the PMUs of one bridge (interface.md,
// "pmu-mavlink", "Parameters"): PARAM_REQUEST_LIST, PARAM_REQUEST_READ and PARAM_SET in,
// PARAM_VALUE and STATUSTEXT out, and each accepted set handed to the program as a request
// for the service. Pure: no I/O, no DDS, no clock (`now` comes with every call).
//
// - Values are the devices' own (set_device, from pmu/config samples). A value not known (a
//   PMU not read yet, or forgotten when it went OFFLINE) is never sent: a list skips it and a
//   read of it is not answered, so a ground station shows no made-up or stale value
//   (docs/safety.md H7); it asks again for what it lacks.
// - Lists and reads are paced (messages_per_second; the default, 10 PARAM_VALUEs of 37 bytes
//   a second, is 6 % of a 57.6 kbit/s radio): poll() emits what is due. A list marks every
//   parameter to send; a second list while one runs, from a sender it already serves, marks
//   nothing (counted); from another sender it marks what was sent already, so that sender
//   gets every parameter too, at the same pace. However many requests come, the link carries
//   at most the pace.
// - Exactly one PARAM_VALUE answers each PARAM_SET: the new value once the service's set is
//   COMPLETED (the service read the device back, interface.md 2.1), the device's current value
//   with a STATUSTEXT saying why when the set is refused here, refused by the service, failed
//   or not answered within set_timeout. A set equal to the device's value is answered at
//   once, nothing sent (a ground station's parameter file loads without traffic to the PMU).
//   The same set again while it runs (a ground station's retransmission) is merged into it:
//   it is neither sent twice nor answered twice. A name this table lacks is not answered at
//   all (counted): a PARAM_SET may be meant for another component.
// - Confirm rules (interface.md 2.2): a set is judged with the service's pure policy, taking
//   what the bridge does not know of the unit at its worst, as `pmuctl config apply` does. A
//   set under a rule the bridge is configured to confirm (`--confirm RULE`) goes to the
//   service confirmed; under another rule it is refused here, with a STATUSTEXT naming the
//   rule. The service judges again, knowing the unit, and stays the authority: it can only
//   refuse more, never less.
// Not thread-safe: one thread (the program's MAVLink loop) calls everything.

#include <array>
#include <chrono>
#include <cstdint>
#include <map>
#include <optional>
#include <string_view>
#include <variant>
#include <vector>

#include "pmu/baseline/settings.hpp"
#include "pmu/command/command.hpp"
#include "pmu/command/policy.hpp"
#include "pmu/mavlink/messages.hpp"
#include "pmu/mavlink_params/confirm_set.hpp"
#include "pmu/mavlink_params/param_table.hpp"

namespace pmu::mavlink_params {

using Time = std::chrono::steady_clock::time_point;

// Who sent a message (its frame's system and component id).
struct Sender {
  std::uint8_t system = 0;
  std::uint8_t component = 0;
  bool operator<(const Sender& o) const noexcept {
    return system != o.system ? system < o.system : component < o.component;
  }
};

// A set for the program to send to the service as a pmu::v5::Command to PMU `param.pmu`,
// and to answer with on_set_reply(tag, ...).
struct SetRequest {
  std::uint64_t tag = 0;
  ParamRef param;
  std::uint32_t raw = 0;  // the wire value
  bool confirm = false;   // send with `confirm`: its rule is one the bridge confirms
  // SET_PARAMETER, SET_OUTPUTS or SET_GENERATION with the wire value.
  service::CommandAction action() const;
};

using Message = std::variant<mavlink::ParamValue, mavlink::Statustext>;

struct Output {
  std::vector<Message> send;
  std::optional<SetRequest> request;
};

struct ParamServerConfig {
  std::size_t pmu_count = 1;  // 1..kMaxPmus; grow() adds more
  double messages_per_second = 10;
  // How long a set waits for the service's final reply: the service's default command
  // lifetime (10 s, interface.md 2.3) and its read-back.
  std::chrono::milliseconds set_timeout{12000};
  ConfirmSet confirm{};
  std::size_t max_pending_sets = 16;  // beyond: refused, counted
  std::size_t max_list_senders = 8;   // senders remembered per list; beyond: merged, counted
};

struct ParamCounters {
  std::uint64_t list_requests = 0;
  std::uint64_t list_requests_merged = 0;  // a list already running for that sender
  std::uint64_t reads = 0;
  std::uint64_t reads_unanswered = 0;  // no such parameter, or its value not known
  std::uint64_t values_sent = 0;       // PARAM_VALUEs of lists and reads
  std::uint64_t values_skipped = 0;    // list entries whose value is not known
  std::uint64_t sets = 0;
  std::uint64_t sets_unknown_name = 0;
  std::uint64_t sets_refused = 0;  // refused here: value, read-only, rule, busy, value not known
  std::uint64_t sets_merged = 0;   // the same set while it ran
  std::uint64_t sets_sent = 0;
  std::uint64_t sets_timed_out = 0;
  std::uint64_t replies_unmatched = 0;  // a reply for no running set (late, or unknown tag)
};

class ParamServer {
 public:
  // Throws std::invalid_argument for a pmu_count outside 1..kMaxPmus (start-up only).
  explicit ParamServer(ParamServerConfig config);

  // PMU `pmu`'s settings as its latest pmu/config sample has them; nullopt values unknown.
  // A known value that changes is sent again (paced), so a ground station's copy follows a
  // change made by another client.
  void set_device(std::size_t pmu, const baseline::Settings& settings);
  // Every value of `pmu` unknown (its PMU went OFFLINE or its config sample was disposed).
  void forget_device(std::size_t pmu);
  // The bridge's PMUs are now `pmu_count` (at most kMaxPmus): the program numbers PMUs as it
  // first hears them, so the count only grows, and each PMU's parameters keep their index
  // (PMU by PMU). PARAM_VALUEs from then on carry the new param_count, from which a ground
  // station learns to ask for the rest. A smaller count changes nothing.
  void grow(std::size_t pmu_count);

  void on_request_list(Sender from, Time now);
  void on_request_read(Sender from, const mavlink::ParamRequestRead& m, Time now);
  Output on_param_set(Sender from, const mavlink::ParamSet& m, Time now);
  // The service's reply to the set `tag`. IN_PROGRESS is not final and changes nothing.
  Output on_set_reply(std::uint64_t tag, service::CommandResult result, std::string_view reason);

  // What is due at `now`: paced PARAM_VALUEs, and the answers of sets that timed out.
  Output poll(Time now);
  // When poll() has something next, if anything waits.
  std::optional<Time> next_due() const;

  const ParamCounters& counters() const noexcept { return counters_; }
  std::size_t param_count() const noexcept { return mavlink_params::param_count(config_.pmu_count); }

 private:
  struct PendingSet {
    ParamRef param;
    std::uint32_t raw;
    Time deadline;
  };
  std::optional<std::uint32_t> value(ParamRef p) const;
  mavlink::ParamValue param_value(ParamRef p, std::uint32_t raw) const;
  Output refuse(ParamRef p, std::string_view why);
  void add_text(Output& out, std::uint8_t severity, std::string_view text);
  std::optional<std::size_t> next_marked() const;

  ParamServerConfig config_;
  std::vector<baseline::Settings> devices_;
  std::vector<bool> urgent_;  // reads and changed values, sent first
  std::vector<bool> listed_;  // a list's entries still to send
  std::size_t cursor_ = 0;    // where the list goes on
  std::vector<Sender> list_senders_;
  double tokens_ = 1;
  std::optional<Time> last_refill_;
  std::map<std::uint64_t, PendingSet> pending_;
  std::uint64_t next_tag_ = 1;
  std::uint16_t next_text_id_ = 1;
  ParamCounters counters_;
};

}  // namespace pmu::mavlink_params
