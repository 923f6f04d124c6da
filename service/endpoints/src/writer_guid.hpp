#pragma once
// A sample's sender as the service keys requests by it: its writer's GUID in Fast DDS's
// printed form. Commands and alarm acknowledgements use the same text, so the audit log names
// one sender alike on both.

#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <string>

namespace pmu::service {

std::string writer_guid_text(const eprosima::fastdds::dds::SampleInfo& info);

}  // namespace pmu::service
