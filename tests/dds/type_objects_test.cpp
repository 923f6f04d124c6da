// Which of the contract's types announce their type object (dds_type_objects.hpp): those a
// Fast DDS 2.9.1 participant can turn into a DynamicType from the object alone. The others
// name a member's type only by hash, which made such a participant drop the member (enums)
// or crash (BatteryCells' sequence of BatteryCell; tests/integration/type_object_test.cpp runs a
// service with every kind of device against one).
#include <gtest/gtest.h>

#include <fastdds/dds/topic/TypeSupport.hpp>

#include "pmu/dds/dds_type_objects.hpp"
#include "pmu/idl/canopenPubSubTypes.h"
#include "pmu/idl/commandPubSubTypes.h"
#include "pmu/idl/statePubSubTypes.h"
#include "pmu/idl/telemetryPubSubTypes.h"

namespace pmu::dds {
namespace {

using eprosima::fastdds::dds::TypeSupport;

TEST(TypeObjects, SelfContainedAreExactlyTheTypesWithoutMembersNamedByHash) {
  register_type_objects();
  register_type_objects();  // idempotent
  for (const char* t :
       {"pmu::v5::Voltages", "pmu::v5::Currents", "pmu::v5::BatteryEnergy", "pmu::v5::Temperatures", "pmu::v5::Status",
        "pmu::v5::Config", "pmu::v5::DeviceInfo", "pmu::v5::Battery", "pmu::v5::Mppt", "pmu::v5::BatteryCell",
        "pmu::v5::Baseline", "pmu::v5::BmsEnergy", "pmu::v5::RoleMove", "pmu::v5::RoleMoveReply"})
    EXPECT_TRUE(type_object_is_self_contained(t)) << t;
  for (const char* t : {"pmu::v5::Health", "pmu::v5::BatteryCells", "pmu::v5::Command", "pmu::v5::CommandReply",
                        "pmu::v5::DeviceKind", "pmu::v5::Energy", "pmu::v5::RoleHeartbeat", "pmu::NoSuchType"})
    EXPECT_FALSE(type_object_is_self_contained(t)) << t;
}

TEST(TypeObjects, NeverTypeInformationAndTheObjectOnlyWhenSelfContained) {
  register_type_objects();
  TypeSupport voltages(new pmu::v5::VoltagesPubSubType());
  TypeSupport cells(new pmu::v5::BatteryCellsPubSubType());
  TypeSupport health(new pmu::v5::HealthPubSubType());
  for (TypeSupport* t : {&voltages, &cells, &health}) {
    ASSERT_TRUE((*t)->auto_fill_type_information()) << "Fast DDS 2.9.1's default, which this changes";
    announce_type_object(*t, true);
    EXPECT_FALSE((*t)->auto_fill_type_information()) << t->get_type_name();
  }
  EXPECT_TRUE(voltages->auto_fill_type_object());
  EXPECT_FALSE(cells->auto_fill_type_object());
  EXPECT_FALSE(health->auto_fill_type_object());
}

// Off (dds_type_objects absent): nothing, though the objects are registered in this process.
TEST(TypeObjects, NothingAnnouncedWhenNotEnabled) {
  register_type_objects();
  TypeSupport voltages(new pmu::v5::VoltagesPubSubType());
  ASSERT_TRUE(voltages->auto_fill_type_object()) << "Fast DDS 2.9.1's default, which this changes";
  announce_type_object(voltages, false);
  EXPECT_FALSE(voltages->auto_fill_type_object());
  EXPECT_FALSE(voltages->auto_fill_type_information());
}

}  // namespace
}  // namespace pmu::dds
