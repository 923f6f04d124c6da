#include "writer_guid.hpp"

#include <sstream>

namespace pmu::service {

std::string writer_guid_text(const eprosima::fastdds::dds::SampleInfo& info) {
  std::ostringstream who;
  who << info.sample_identity.writer_guid();
  return who.str();
}

}  // namespace pmu::service
