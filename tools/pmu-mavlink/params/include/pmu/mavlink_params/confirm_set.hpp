#pragma once
// The confirm rules the bridge sends as confirmed (`--confirm RULE`, repeatable, and the same
// list in its config file; commands/README.md), read by a total function at start-up.

#include <array>
#include <string>
#include <vector>

#include "pmu/codec/result.hpp"
#include "pmu/command/policy.hpp"

namespace pmu::mavlink_params {

using ConfirmSet = std::array<bool, service::kConfirmRuleCount>;  // by service::ConfirmRule

// The set the names give, or "unknown confirm rule 'X' (rules: disable_avionics, reset, ...)"
// for the first name that is none (quoted printable).
codec::Result<ConfirmSet, std::string> confirm_set(const std::vector<std::string>& names);

}  // namespace pmu::mavlink_params
