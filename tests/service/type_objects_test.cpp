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
  for (const char* t : {"pmu::v4::Voltages", "pmu::v4::Currents", "pmu::v4::BatteryEnergy", "pmu::v4::Temperatures", "pmu::v4::Status",
                        "pmu::v4::Config", "pmu::v4::DeviceInfo", "pmu::v4::Battery", "pmu::v4::Mppt", "pmu::v4::BatteryCell",
                        "pmu::v4::Baseline", "pmu::v4::BmsEnergy"})
    EXPECT_TRUE(type_object_is_self_contained(t)) << t;
  for (const char* t : {"pmu::v4::Health", "pmu::v4::BatteryCells", "pmu::v4::Command", "pmu::v4::CommandReply",
                        "pmu::v4::DeviceKind", "pmu::v4::Energy", "pmu::NoSuchType"})
    EXPECT_FALSE(type_object_is_self_contained(t)) << t;
}

TEST(TypeObjects, NeverTypeInformationAndTheObjectOnlyWhenSelfContained) {
  register_type_objects();
  TypeSupport voltages(new pmu::v4::VoltagesPubSubType());
  TypeSupport cells(new pmu::v4::BatteryCellsPubSubType());
  TypeSupport health(new pmu::v4::HealthPubSubType());
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
  TypeSupport voltages(new pmu::v4::VoltagesPubSubType());
  ASSERT_TRUE(voltages->auto_fill_type_object()) << "Fast DDS 2.9.1's default, which this changes";
  announce_type_object(voltages, false);
  EXPECT_FALSE(voltages->auto_fill_type_object());
  EXPECT_FALSE(voltages->auto_fill_type_information());
}

}  // namespace
}  // namespace pmu::dds
