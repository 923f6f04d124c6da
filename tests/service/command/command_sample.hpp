#pragma once
// A pmu/command sample as a ground station writes it, for PMU 1 on can0, before the boundary
// (parse_command) has looked at it; tests change the fields they are about.
#include <cstdint>

#include "pmu/command/command.hpp"

namespace pmu::service {

inline CommandSample command_sample(CommandKind kind, std::uint8_t outputs = 0, const char* parameter = "",
                                    double value = 0) {
  CommandSample s;
  s.request_id = "id-1";
  s.bus = "can0";
  s.address = 1;
  s.kind = static_cast<std::uint32_t>(kind);
  s.outputs = outputs;
  s.parameter = parameter;
  s.value = value;
  return s;
}

}  // namespace pmu::service
