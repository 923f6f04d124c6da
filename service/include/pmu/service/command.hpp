#pragma once
// Commands in the service's own terms (mirroring pmu::Command / pmu::CommandReply of
// interface.md); dds_commands.cpp converts at the DDS boundary, everything else uses these.

#include <chrono>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

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

struct CommandRequest {
  std::string request_id;
  std::string sender;  // who sent it, for the audit trail (the DDS writer's GUID)
  std::string bus;
  std::uint16_t address = 0;
  CommandKind kind = CommandKind::Get;
  std::string parameter;
  double value = 0;
  std::uint8_t outputs = 0;
  bool enable = false;
  std::uint8_t groups = 0;
  // Absolute expiry (wall clock); nullopt: the service's default lifetime from receipt.
  std::optional<std::chrono::system_clock::time_point> expires_at;
  bool confirm = false;
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

// "set_parameter avionics_voltage=24.0 to can0/1 (confirm)": for logs and the audit trail.
std::string describe(const CommandRequest& r);

}  // namespace pmu::service
