// The main of the test programs whose participants must talk as two hosts would: Fast DDS's
// in-process shortcut is off, so everything between participants of one process goes through
// the transport (UDP or shared memory), which is what a wire capture or a discovery test
// looks at.
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
