#pragma once
// What a standby instance of a hot-standby pair knows of the commands the bus owner carries
// out (design.md "Hot standby", interface.md 2.4, docs/safety.md H4 and H8), so that when it
// takes over every command still gets exactly one final reply and none runs twice:
//   * the requests it received and did not execute (the same pmu/command samples the owner
//     reads), with their arrival time;
//   * the replies the owner wrote (pmu/command_reply): a final one settles its request, a
//     progress one says it was running;
//   * the command frames it heard on CAN: a set, an output or generation change, an engine
//     start or stop, a reset, addressed to a PMU (command_frame below), matched to a pending
//     request by bus, address and packet.
// take_over() then says, for each request, what the new owner does with it (Verdict).
//
// A reply names no sender (interface.md 2.1: request id, bus, address, kind), so one is matched
// to every pending request with its id, bus, address and kind: a client that matches replies
// by id took it as its own anyway. A frame may be heard before the request arrives here (the
// two hosts receive the sample at different times), so a request also matches the frames heard
// up to `can_slack` before it that no request held then explains. Both err towards "outcome unknown", never towards a second run.
//
// Bounds: at most `max_requests` requests (oldest forgotten first), each kept for
// `lifetimes.max_lifetime` after its arrival (no request lives longer, interface.md 2.3); at
// most `max_frames` frames and open gets, each kept for `can_slack`; at most `max_requests`
// replies that matched no request yet, kept as long as a request.
//
// Pure: `now` is passed in, no clock, no lock, no I/O. Threads: one at a time (CommandService
// calls it under its lock).

#include <chrono>
#include <cstdint>
#include <deque>
#include <optional>
#include <string>
#include <unordered_map>
#include <vector>

#include "pmu/codec/can_frame.hpp"
#include "pmu/codec/ids.hpp"
#include "pmu/command/command.hpp"

namespace pmu::service {

using SteadyTime = std::chrono::steady_clock::time_point;

struct FailoverLimits {
  std::size_t max_requests = 4096;
  std::size_t max_frames = 1024;
  std::chrono::milliseconds can_slack{1000};
};

// A frame the bus owner sent to make a PMU do something (protocol v1.9 table 1): 0x10..0x1B,
// 0x20 and 0x23 with data, 0x21, 0x22, and the data-less 0x24..0x26, to one PMU's address.
// Polls, gets, measurement requests, telemetry and broadcasts are not. A frame with data on an
// id that also has a zero-length get is a set unless it answers a get: `answers_get` says
// whether one was heard on that id before it (FailoverRecord keeps that).
struct CommandFrame {
  std::uint16_t address = 0;
  codec::PacketId packet{};
};
enum class FrameRole : std::uint8_t { Other, Get, Command };
FrameRole frame_role(const codec::CanFrame& f) noexcept;

class FailoverRecord {
 public:
  explicit FailoverRecord(Lifetimes lifetimes, FailoverLimits limits = {});

  // A request this instance received while not executing. `key`: its sender and request id
  // (sender_key); a second sample under a key already held (a resend) changes nothing.
  void request(const std::string& key, const CommandSample& s, const Now& now);
  // A request this instance had taken and gives up unanswered because it stopped owning the
  // bus (`reply`: the request's reply with any result): its frames may be on the bus, so it is
  // held as heard.
  void relinquished(const std::string& key, std::uint64_t fingerprint, const CommandReplyData& reply, SteadyTime now);
  // A reply the bus owner wrote.
  void peer_reply(const CommandReplyData& reply, SteadyTime now);
  // A frame heard on `bus`.
  void heard(const std::string& bus, const codec::CanFrame& frame, SteadyTime now);

  enum class Action : std::uint8_t {
    Answered,  // the owner's final reply, `reply`: not executed, a resend gets it
    Unknown,   // FAILED, `reply.reason` says why its outcome is unknown: not executed, a resend gets it
    Expired,   // REJECTED: it expired here before anybody could run it
    Run,       // execute `sample` (its deadline from `arrived`; an ENGINE_STOP's at least `now` + default lifetime)
  };
  struct Verdict {
    std::string key;
    std::uint64_t fingerprint = 0;
    Action action = Action::Run;
    CommandReplyData reply;               // Answered, Unknown, Expired: the final reply
    std::optional<CommandSample> sample;  // Run
    Now arrived{};                        // Run: when it arrived here
  };
  // Every request held, in arrival order, with what the new owner does with it; the record is
  // empty afterwards.
  std::vector<Verdict> take_over(SteadyTime now);

  std::size_t size() const noexcept { return entries_.size(); }
  bool empty() const noexcept { return entries_.empty() && replies_.empty(); }

  static constexpr const char* kHeardReason =
      "outcome unknown: its frames were on the bus from the former owner, which failed over before it answered; "
      "read the state before sending it again";
  static constexpr const char* kInProgressReason =
      "outcome unknown: the former owner reported it in progress and failed over before it answered; read the "
      "state before sending it again";

 private:
  struct Entry {
    std::uint64_t fingerprint = 0;
    CommandReplyData reply;  // id, bus, address, kind: what a reply to it carries
    std::optional<CommandSample> sample;
    Now arrived{};
    std::optional<CommandReplyData> answer;  // the owner's final reply
    const char* heard = nullptr;             // why its outcome is unknown
  };
  struct Heard {
    std::string bus;
    CommandFrame frame;
    SteadyTime at;
  };
  struct OpenGet {
    std::string bus;
    std::uint32_t id = 0;
    SteadyTime at;
  };

  void forget_old(SteadyTime now);
  void add(const std::string& key, Entry e);
  static bool same_request(const CommandReplyData& a, const CommandReplyData& b);

  Lifetimes lifetimes_;
  FailoverLimits limits_;
  std::unordered_map<std::string, Entry> entries_;
  std::deque<std::string> order_;                                // oldest first
  std::deque<std::pair<CommandReplyData, SteadyTime>> replies_;  // final replies that matched no request yet
  std::deque<Heard> frames_;                                     // command frames, oldest first
  std::deque<OpenGet> gets_;                                     // zero-length gets not answered yet
};

// The packet whose frame carries out `s` on its device when it changes something; nullopt for
// the kinds that only read (a GET twice changes nothing, so it is never "outcome unknown").
std::optional<codec::PacketId> command_packet(const CommandSample& s) noexcept;

}  // namespace pmu::service
