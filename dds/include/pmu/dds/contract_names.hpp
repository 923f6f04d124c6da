#pragma once
// The contract's major version in its DDS type names (docs/interface.md section 10): from v4
// every type is named pmu::vN::Type, so a consumer built from another major version's IDL
// matches nothing instead of misreading. Contracts before v4 named their types pmu::Type.
// Pure functions; any thread.

#include <optional>
#include <string>
#include <string_view>

namespace pmu::dds {

// The major version this build implements (cmake/install_dirs.cmake, the IDL's module vN).
int contract_major() noexcept;

// The contract a DDS type name belongs to: "pmu::v5::Health" -> 4; "pmu::Health" -> 3, the
// last contract whose names carried no version (v1 and v2 named theirs the same way); nullopt
// for a name that is not one of the contract's ("std_msgs::...", "pmu::vx::A").
std::optional<int> contract_of_type_name(std::string_view type_name);

// `current` (a type name of this build's contract, "pmu::v5::Health") as contract `major`
// names it: 3 -> "pmu::Health", 5 -> "pmu::v5::Health". Returns `current` unchanged when it
// is not one of the contract's names.
std::string type_name_in_contract(std::string_view current, int major);

// "contract v4"; for 3 "contract v3 (or older)", since v1..v3 share their type names.
std::string contract_text(int major);

// The participant property every pmu-service announces with the contract it serves there.
inline constexpr const char* kContractProperty = "pmu-dds.contract";

}  // namespace pmu::dds
