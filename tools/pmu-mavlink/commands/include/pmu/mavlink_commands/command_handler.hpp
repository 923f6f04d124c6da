#pragma once
// COMMAND_LONG for the PMUs of one bridge (interface.md, "pmu-mavlink", "Commands"): what each
// command means to the service, and the COMMAND_ACKs that answer it. Pure: no I/O, no DDS, no
// clock (`now` comes with every call).
//
// - MAV_CMD_DO_ENGINE_CONTROL (param1 1 start, 0 stop), MAV_CMD_DO_SET_RELAY (instance 0..3
//   the outputs avionics_servo, payload, charger_a, charger_b; instance 4 generation),
//   MAV_CMD_PREFLIGHT_REBOOT_SHUTDOWN (param3 1 for this component: RESET) become service
//   commands for the program to send to PMU `pmu` (param7: PMU number 1..9, 0 for PMU 1),
//   answered from the service's replies with on_reply(tag, ...).
//   MAV_CMD_RUN_PREARM_CHECKS and MAV_CMD_SET_MESSAGE_INTERVAL are the bridge's own
//   (program/bridge.cpp answers them from its readiness and its scheduler before a command
//   comes here); this handler knows neither.
// - Acks: an engine start is answered IN_PROGRESS at once and with each of the service's
//   IN_PROGRESS replies (progress from its "cranking: E s of up to CT s"), then ACCEPTED only
//   when the service's start is COMPLETED (the engine runs, interface.md 2.7), FAILED
//   otherwise; between the service's replies the last IN_PROGRESS is repeated every
//   in_progress_every, so a ground station never waits long for a sign. Final results: COMPLETED -> ACCEPTED; REJECTED, DENIED -> DENIED (with the
//   service's reason as STATUSTEXT); UNSUPPORTED -> UNSUPPORTED; TIMEOUT, FAILED, and no reply
//   within the timeout -> FAILED.
// - Retransmissions (docs/safety.md H8): a command with the same sender, command and params
//   as one still running is answered with that one's state and never sent again, whatever
//   its `confirmation`; one that repeats an answered command within retransmission_window with
//   `confirmation` above 0 (MAVLink counts it up on each retransmission) gets that answer
//   again. `confirmation` 0 after the answer is a new command.
// - An engine stop always goes through (docs/safety.md H4): never refused by a rule, the
//   flood bound or a running start (a stop during a start is sent, and the start's reply
//   says it was cancelled); only a retransmission of a stop still running is merged into it,
//   which is going out. A stop after an answered stop is sent again.
// - Confirm rules (interface.md 2.2): a command under a rule the bridge is configured to
//   confirm (`--confirm RULE`) goes to the service confirmed; under another rule it is
//   DENIED here with a STATUSTEXT naming the rule. The ground station's own dialog is then
//   the confirmation. The service judges again and stays the authority.
// - Floods: at most max_pending commands run at once (stops not counted); beyond,
//   TEMPORARILY_REJECTED, counted. What is remembered for retransmissions is bounded.
// Not thread-safe: one thread (the program's MAVLink loop) calls everything.

#include <array>
#include <chrono>
#include <cstdint>
#include <deque>
#include <optional>
#include <string_view>
#include <vector>

#include "pmu/command/command.hpp"
#include "pmu/command/policy.hpp"
#include "pmu/mavlink/messages.hpp"
#include "pmu/mavlink_params/param_server.hpp"

namespace pmu::mavlink_commands {

using Time = std::chrono::steady_clock::time_point;
using mavlink_params::ConfirmSet;
using mavlink_params::Sender;

// DO_SET_RELAY's instance that switches generation (0..3 are the outputs' bits).
inline constexpr int kGenerationRelay = 4;

// A command for the program to send to the service as a pmu::v5::Command to PMU `pmu`
// (0-based), and to answer with on_reply(tag, ...).
struct ServiceCommand {
  std::uint64_t tag = 0;
  std::size_t pmu = 0;
  service::CommandAction action;
  bool confirm = false;
};

struct Output {
  std::vector<mavlink::CommandAck> acks;  // each addressed to its command's sender
  std::vector<mavlink::Statustext> texts;
  std::optional<ServiceCommand> command;
};

struct CommandConfig {
  std::size_t pmu_count = 1;
  ConfirmSet confirm{};
  std::uint8_t own_component = 180;  // PREFLIGHT_REBOOT_SHUTDOWN's param4 names it (or 0)
  // How long a command waits for the service's final reply: its default lifetime (10 s,
  // interface.md 2.3) and a margin; an engine start the longest verification (25.5 s of
  // cranking, the hold, 1 s) and the lifetime of its check.
  std::chrono::milliseconds reply_timeout{12000};
  std::chrono::milliseconds start_timeout{40000};
  std::chrono::milliseconds retransmission_window{10000};
  std::chrono::milliseconds in_progress_every{1000};
  std::size_t max_pending = 16;
  std::size_t max_remembered = 64;  // answered commands kept for retransmissions
};

struct CommandCounters {
  std::uint64_t received = 0;
  std::uint64_t retransmissions = 0;  // answered from the first, not sent again
  std::uint64_t sent = 0;             // service commands handed out
  std::uint64_t stops = 0;
  std::uint64_t unsupported = 0;
  std::uint64_t denied = 0;          // here: bad params, rule not confirmed, no such PMU
  std::uint64_t flood_rejected = 0;  // TEMPORARILY_REJECTED: max_pending
  std::uint64_t timed_out = 0;
  std::uint64_t replies_unmatched = 0;
};

// The progress of an engine start from the service's IN_PROGRESS reason
// ("cranking: 1.2 s of up to 5.0 s, 300 rpm" -> 24), at most 99; UINT8_MAX when unknown.
std::uint8_t start_progress(std::string_view reason) noexcept;

class CommandHandler {
 public:
  // Throws std::invalid_argument for a pmu_count outside 1..9 (start-up only).
  explicit CommandHandler(CommandConfig config);

  Output on_command_long(Sender from, const mavlink::CommandLong& m, Time now);
  // The service's reply to the command `tag`, IN_PROGRESS or final.
  Output on_reply(std::uint64_t tag, service::CommandResult result, std::string_view reason, Time now);
  // Commands whose reply is overdue are answered FAILED, a running engine start's
  // IN_PROGRESS is repeated when due; old answers are forgotten.
  Output poll(Time now);

  const CommandCounters& counters() const noexcept { return counters_; }

 private:
  struct Entry {
    Sender from;
    std::uint16_t command = 0;
    std::array<float, 7> param{};
    std::optional<std::uint64_t> tag;  // while the service works on it
    bool stop = false;
    bool final = false;
    std::uint8_t result = 0;
    std::uint8_t progress = 0;
    bool start = false;
    Time last_ack;     // an engine start's latest IN_PROGRESS
    Time deadline;     // of the reply, while not final
    Time answered_at;  // once final
  };
  Entry* find(Sender from, const mavlink::CommandLong& m);
  Entry* find(std::uint64_t tag);
  mavlink::CommandAck ack(const Entry& e) const;
  Output answer_here(Sender from, const mavlink::CommandLong& m, std::uint8_t result, std::string_view why, Time now);
  void remember(Entry e);
  std::size_t running() const;

  CommandConfig config_;
  std::deque<Entry> entries_;
  std::uint64_t next_tag_ = 1;
  std::uint16_t next_text_id_ = 1;
  CommandCounters counters_;
};

}  // namespace pmu::mavlink_commands
