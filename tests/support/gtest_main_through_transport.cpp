// The main of every test program that has DDS participants talk to each other inside one
// process: Fast DDS's in-process shortcut (intraprocess delivery) is off, so everything between
// them goes through the transport (UDP or shared memory), as between pmu-service, pmuctl and a
// ground station, which are separate processes, and as a wire capture or a discovery test sees.
//
// The shortcut is also not dependable for a late joiner in Fast DDS 2.9 (tests/README.md,
// "In-process participants"): a ground station in the process of three services now and then
// matched the writers of only two of them for all of 30 s.
#include <gtest/gtest.h>
#include <signal.h>

#include <cstdlib>
#include <fastdds/dds/log/Log.hpp>
#include <fastrtps/xmlparser/XMLProfileManager.h>

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  eprosima::fastrtps::LibrarySettingsAttributes library;
  library.intraprocess_delivery = eprosima::fastrtps::INTRAPROCESS_OFF;
  eprosima::fastrtps::xmlparser::XMLProfileManager::library_settings(library);
  // A peer that goes away mid-write (pmuctl, pmu-service) must not end the test program.
  ::signal(SIGPIPE, SIG_IGN);
  // PMU_FASTDDS_WARNINGS=1 shows why Fast DDS rejected a participant (a failed security
  // handshake is a warning).
  if (std::getenv("PMU_FASTDDS_WARNINGS"))
    eprosima::fastdds::dds::Log::SetVerbosity(eprosima::fastdds::dds::Log::Warning);
  return RUN_ALL_TESTS();
}
