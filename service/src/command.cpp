#include "pmu/service/command.hpp"

#include <array>
#include <cstdio>

namespace pmu::service {
namespace {

constexpr std::array<std::string_view, kCommandKindCount> kKindNames{
    "get", "set_parameter", "set_outputs", "enable_outputs", "disable_outputs", "set_generation",
    "request_measurements", "engine_start", "engine_stop", "reset", "get_serial", "get_firmware"};

}  // namespace

std::string_view to_string(CommandKind k) noexcept { return kKindNames[static_cast<std::size_t>(k)]; }

std::optional<CommandKind> command_kind_from_name(std::string_view name) noexcept {
  for (std::size_t i = 0; i < kKindNames.size(); ++i)
    if (kKindNames[i] == name) return static_cast<CommandKind>(i);
  return std::nullopt;
}

std::string_view to_string(CommandResult r) noexcept {
  switch (r) {
    case CommandResult::Completed: return "COMPLETED";
    case CommandResult::Rejected: return "REJECTED";
    case CommandResult::Denied: return "DENIED";
    case CommandResult::Unsupported: return "UNSUPPORTED";
    case CommandResult::Timeout: return "TIMEOUT";
    case CommandResult::Failed: return "FAILED";
    case CommandResult::InProgress: return "IN_PROGRESS";
  }
  return "FAILED";
}

std::string describe(const CommandRequest& r) {
  std::string s(to_string(r.kind));
  char buf[64];
  switch (r.kind) {
    case CommandKind::Get: s += " " + r.parameter; break;
    case CommandKind::SetParameter:
      std::snprintf(buf, sizeof buf, "=%g", r.value);
      s += " " + r.parameter + buf;
      break;
    case CommandKind::SetOutputs:
    case CommandKind::EnableOutputs:
    case CommandKind::DisableOutputs:
      std::snprintf(buf, sizeof buf, " outputs=0x%02X", r.outputs);
      s += buf;
      break;
    case CommandKind::SetGeneration: s += r.enable ? " on" : " off"; break;
    case CommandKind::RequestMeasurements:
      std::snprintf(buf, sizeof buf, " groups=0x%02X", r.groups);
      s += buf;
      break;
    default: break;
  }
  s += " to " + r.bus + "/" + std::to_string(r.address);
  if (r.confirm) s += " (confirmed)";
  return s;
}

}  // namespace pmu::service
