// The contract's major version in DDS type names (interface.md section 10.1): which contract
// a discovered writer's type belongs to, and the names the previous contract's participant uses.
#include "pmu/dds/contract_names.hpp"

#include <gtest/gtest.h>

#include "pmu/idl/statePubSubTypes.h"

namespace {

using pmu::dds::contract_of_type_name;
using pmu::dds::type_name_in_contract;

struct OfCase {
  const char* name;
  std::optional<int> contract;
};

TEST(ContractNames, TheContractOfATypeName) {
  const OfCase cases[] = {
      {"pmu::v4::Health", 4},
      {"pmu::v5::Health", 5},
      {"pmu::v12::Voltages", 12},
      {"pmu::Health", 3},                 // v1..v3: unversioned
      {"pmu::v3::Health", std::nullopt},  // no contract was named so
      {"pmu::vx::Health", std::nullopt},
      {"pmu::v5::", std::nullopt},
      {"pmu::", std::nullopt},
      {"std_msgs::msg::dds_::Header_", std::nullopt},
      {"Health", std::nullopt},
      {"", std::nullopt},
  };
  for (const auto& c : cases) EXPECT_EQ(contract_of_type_name(c.name), c.contract) << c.name;
}

TEST(ContractNames, ThisBuildsTypesCarryItsMajorVersion) {
  EXPECT_EQ(contract_of_type_name(pmu::v5::HealthPubSubType().getName()), pmu::dds::contract_major());
}

TEST(ContractNames, ACurrentNameAsAnotherContractNamesIt) {
  EXPECT_EQ(type_name_in_contract("pmu::v5::Health", 3), "pmu::Health");
  EXPECT_EQ(type_name_in_contract("pmu::v5::BatteryCells", 5), "pmu::v5::BatteryCells");
  EXPECT_EQ(type_name_in_contract("pmu::v5::Health", 4), "pmu::v4::Health");
  EXPECT_EQ(type_name_in_contract("other::Thing", 3), "other::Thing");
  EXPECT_EQ(contract_of_type_name(type_name_in_contract("pmu::v5::Config", 3)), 3);
}

TEST(ContractNames, Text) {
  EXPECT_EQ(pmu::dds::contract_text(4), "contract v4");
  EXPECT_EQ(pmu::dds::contract_text(5), "contract v5");
  EXPECT_EQ(pmu::dds::contract_text(3), "contract v3 (or older)");
}

}  // namespace
