#pragma once
// Commands in the service's own terms (interface.md, Commands).
//
// Two stages, with one total function between them:
//   CommandSample   a pmu::v5::Command exactly as it arrived: any kind number, any double, any
//                   byte in a boolean, any expiry, strings of any length. Not trusted.
//   CommandRequest  what the rest of the service works on: one typed action per kind,
//                   values already in wire units (so policy judges what will be sent), the
//                   expiry as a steady-clock deadline.
// parse_command() turns every possible sample into a request or a rejection reason; it never
// throws, and nothing after it looks at the sample's strings again.
//
// Text from the network reaches logs only through printable(): a peer cannot start a line,
// move the cursor or forge an audit entry.

#include <chrono>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <variant>

#include "pmu/codec/ids.hpp"
#include "pmu/codec/parameters.hpp"
#include "pmu/codec/result.hpp"

namespace pmu::service {

enum class CommandKind : std::uint8_t {
  Get,
  SetParameter,
  SetOutputs,
  EnableOutputs,
  DisableOutputs,
  SetGeneration,
  RequestMeasurements,
  EngineStart,
  EngineStop,
  Reset,
  GetSerial,
  GetFirmware,
};
inline constexpr std::size_t kCommandKindCount = 12;

// "get", "set_parameter", ... "get_firmware": the names config files and logs use.
std::string_view to_string(CommandKind k) noexcept;
std::optional<CommandKind> command_kind_from_name(std::string_view name) noexcept;

enum class CommandResult : std::uint8_t { Completed, Rejected, Denied, Unsupported, Timeout, Failed, InProgress };
std::string_view to_string(CommandResult r) noexcept;  // "COMPLETED", ...
inline bool is_final(CommandResult r) noexcept { return r != CommandResult::InProgress; }
// The reason of a command REJECTED because its service has no device at `address` on `bus`:
// nothing was executed. pmuctl's agent compares a reply with it (target_memory.hpp).
std::string device_not_seen_reason(std::uint16_t address, std::string_view bus);
// The reason of a command REJECTED because its service serves no bus `bus` (`served`: the
// buses it does serve): nothing was executed.
std::string bus_not_served_reason(std::string_view bus, std::string_view served);
// Whether a REJECTED command's reason says its target is not there: no such bus, or no such
// device on it. pmuctl exits 2 for that (no such target), 1 for any other refusal
// (interface.md 3.2).
bool says_no_such_target(std::string_view reason, std::string_view bus, std::uint16_t address);

// The IDL's string bounds (idl/command.idl): longer strings are rejected, not truncated.
inline constexpr std::size_t kMaxRequestIdLength = 63;
inline constexpr std::size_t kMaxBusNameLength = 15;
inline constexpr std::size_t kMaxParameterLength = 31;

// A pmu::v5::Command as received (field for field), before anything is trusted.
struct CommandSample {
  std::string request_id;
  std::string vehicle;  // the endpoint passes on only its own vehicle's commands
  std::string bus;
  std::uint16_t address = 0;
  std::uint32_t kind = 0;  // a CommandKind if < kCommandKindCount
  std::string parameter;
  double value = 0;
  std::uint8_t outputs = 0;
  std::uint8_t enable = 0;  // a CDR boolean: only 0 and 1 are valid
  std::uint8_t groups = 0;
  std::uint64_t expires_at = 0;  // ns since the Unix epoch (UTC); 0 = the default lifetime
  std::uint8_t confirm = 0;      // a CDR boolean
  // Not part of the sample: who wrote it (the DDS writer's GUID), set by the endpoint.
  // Request ids are unique per sender, so duplicates are recognised per sender.
  std::string sender;
};

// Identical content: everything but the expiry (a resend with a fresh deadline is the same
// command), the id and the sender. Used to tell a resend from a reused id.
std::uint64_t content_fingerprint(const CommandSample& s) noexcept;

// One typed alternative per kind, in CommandKind's order.
namespace action {
struct Get {  // a stored parameter (0x10..0x1B), outputs (0x20), generation (0x23) or a group (0x00..0x04)
  codec::PacketId packet;
};
struct SetParameter {
  codec::Parameter parameter;
  std::uint32_t raw;  // exactly what goes on the wire
};
struct SetOutputs {
  std::uint8_t mask;
};
struct EnableOutputs {
  std::uint8_t mask;
};  // non-empty
struct DisableOutputs {
  std::uint8_t mask;
};  // non-empty
struct SetGeneration {
  bool enable;
};
struct RequestMeasurements {
  std::uint8_t groups;
};  // non-empty (0 on the wire means all)
struct EngineStart {};
struct EngineStop {};
struct Reset {};
struct GetSerial {};
struct GetFirmware {};
}  // namespace action

using CommandAction =
    std::variant<action::Get, action::SetParameter, action::SetOutputs, action::EnableOutputs, action::DisableOutputs,
                 action::SetGeneration, action::RequestMeasurements, action::EngineStart, action::EngineStop,
                 action::Reset, action::GetSerial, action::GetFirmware>;
static_assert(std::variant_size_v<CommandAction> == kCommandKindCount);

// An apply's hold on a device's configuration (interface.md 2.8, docs/safety.md H11). It rides
// in `groups`, which no kind but REQUEST_MEASUREMENTS reads, on bits outside its group mask
// (so a request that has none of them means what it always meant), and names its apply in
// the request id, `APPLY#N`: every command of one apply, whatever its kind, carries the same
// APPLY. The service admits it in command_service.cpp (config_holds.hpp).
namespace hold_bit {
inline constexpr std::uint8_t Hold = 0x80;     // the command is one of an apply's: it takes or renews the hold
inline constexpr std::uint8_t Release = 0x40;  // with Hold: the apply's last; the hold ends with it
}  // namespace hold_bit
struct ConfigHold {
  std::string apply;  // the request id before its last '#'
  bool release = false;
};
// The kinds a hold rides on: a GET, and every kind that changes a stored setting, an output
// or generation. The others ignore the bits, so nothing can make an engine stop refused.
bool may_hold(CommandKind k) noexcept;
// The kinds another writer's hold refuses: they change what an apply sets.
bool changes_configuration(CommandKind k) noexcept;

struct CommandRequest {
  std::string request_id;
  std::string sender;
  // The vehicle the command names (the endpoint passed on only this service's own): kept so
  // a fleet's audit lines say which vehicle executed what.
  std::string vehicle;
  std::string bus;
  std::uint16_t address = 0;
  CommandAction action;
  std::chrono::steady_clock::time_point expires;  // the first frame is not sent after this
  bool confirm = false;
  std::optional<ConfigHold> hold;  // set only for a kind that may_hold()

  CommandKind kind() const noexcept { return static_cast<CommandKind>(action.index()); }
};

struct CommandReplyData {
  std::string request_id;
  std::string bus;
  std::uint16_t address = 0;
  CommandKind kind = CommandKind::Get;
  CommandResult result = CommandResult::Completed;
  std::string reason;
  bool has_value = false;
  double value = 0;
  std::string value_text;
};

// How long a request may wait (config `policy`).
struct Lifetimes {
  std::chrono::milliseconds default_lifetime{10000};  // expires_at = 0
  // An expires_at further ahead than this is held to it: the service never keeps a request
  // (nor its duplicate-detection entry) for longer, whatever a peer's clock or intent.
  std::chrono::milliseconds max_lifetime{60000};
};

struct Now {
  std::chrono::system_clock::time_point wall;
  std::chrono::steady_clock::time_point steady;
};

// The steady deadline of a request's expires_at (0: the default lifetime; held to the
// maximum lifetime), or "expired N ms ago". Shared by every request a peer can send.
codec::Result<std::chrono::steady_clock::time_point, std::string> deadline(std::uint64_t expires_at, const Now& now,
                                                                           const Lifetimes& lifetimes);

// The boundary. A valid sample gives a request; anything else the reason to reject it, which
// quotes the sample's text through printable(). Firmware-dependent checks come later
// (check_firmware in command_executor.hpp), when the device is known.
codec::Result<CommandRequest, std::string> parse_command(const CommandSample& s, const Now& now,
                                                         const Lifetimes& lifetimes);

// "set_parameter avionics_voltage=24 to can0/1 (confirmed)": for logs and the audit trail.
std::string describe(const CommandRequest& r);
// The same for a sample that did not parse, with its text made printable.
std::string describe(const CommandSample& s);

// `text` with every byte outside printable ASCII, and the backslash, written as \xNN (\\),
// cut to `max` bytes of input (marked with "..."). Safe in a log line.
std::string printable(std::string_view text, std::size_t max = 64);

}  // namespace pmu::service
