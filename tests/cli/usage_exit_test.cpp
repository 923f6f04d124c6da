// Bad usage of each program (an unknown option, a value out of range, a missing argument)
// exits with status 2 and says what is wrong, as the man pages and interface.md 3.2 say; the
// help exits 0. CLI11 alone would exit with its own codes (105 for a value out of range).
#include <gtest/gtest.h>

#include <fstream>
#include <string>

#include "support/process.hpp"

namespace {

struct Case {
  const char* program;
  const char* args;
  const char* message;  // part of stderr naming what is wrong
};

const Case kBad[] = {
    {PMUCTL_PATH, "--domain 999 list", "--domain: Value 999 not in range 0 to 232"},
    {PMUCTL_PATH, "--no-such-option list", "--no-such-option"},
    {PMUCTL_PATH, "list --no-such-option", "--no-such-option"},
    {PMUCTL_PATH, "decode --firmware", "--firmware"},
    {PMUCTL_PATH, "", "A subcommand is required"},
    {PMU_SERVICE_PATH, "--domain 999", "--domain: Value 999 not in range 0 to 232"},
    {PMU_SERVICE_PATH, "--no-such-option", "--no-such-option"},
    {PMU_SIM_PATH, "vcan0 --battery 0", "--battery: Value 0 not in range 1 to 127"},
    {PMU_SIM_PATH, "--no-such-option vcan0", "--no-such-option"},
};

TEST(Usage, BadUsageExitsTwoSayingWhat) {
  for (const auto& c : kBad) {
    SCOPED_TRACE(std::string(c.program) + " " + c.args);
    const auto r = pmu::test::run_capture(std::string(c.program) + " " + c.args + " 2>&1 >/dev/null");
    EXPECT_EQ(r.status, 2) << r.out;
    EXPECT_NE(r.out.find(c.message), std::string::npos) << r.out;
  }
}

TEST(Usage, HelpExitsZero) {
  for (const char* program : {PMUCTL_PATH, PMU_SERVICE_PATH, PMU_SIM_PATH}) {
    SCOPED_TRACE(program);
    const auto r = pmu::test::run_capture(std::string(program) + " --help");
    EXPECT_EQ(r.status, 0);
    EXPECT_NE(r.out.find("--help"), std::string::npos) << r.out;
  }
}

// --version names the program, the release of CMakeLists.txt (and debian/changelog, which
// the configure step holds to it) and the contract version of docs/interface.md's head.
// The help says what the protocol's stop does: 0x25 stops the starter cranking, and no PMU
// command stops a running engine (v1.9 5.23; docs/safety.md H4). The agent's help gives the
// spill-over the agent waits (interface.md 3.2).
TEST(Usage, TheHelpSaysWhatAStopAndTheAgentDo) {
  const auto engine = pmu::test::run_capture(std::string(PMUCTL_PATH) + " engine --help");
  EXPECT_EQ(engine.status, 0);
  EXPECT_NE(engine.out.find("stops the starter cranking; a running engine keeps running"), std::string::npos)
      << engine.out;
  const auto agent = pmu::test::run_capture(std::string(PMUCTL_PATH) + " agent --help");
  EXPECT_EQ(agent.status, 0);
  EXPECT_NE(agent.out.find("have been on theirs for 5 s"), std::string::npos) << agent.out;
}

TEST(Usage, VersionNamesTheReleaseAndTheContract) {
  const struct {
    const char* path;
    const char* name;
  } programs[] = {{PMUCTL_PATH, "pmuctl"}, {PMU_SERVICE_PATH, "pmu-service"}, {PMU_SIM_PATH, "pmu-sim"}};
  for (const auto& p : programs) {
    SCOPED_TRACE(p.name);
    const auto r = pmu::test::run_capture(std::string(p.path) + " --version");
    EXPECT_EQ(r.status, 0);
    EXPECT_EQ(r.out, std::string(p.name) + " " PMU_RELEASE " (pmu-dds contract v" PMU_CONTRACT ")\n");
  }
}

TEST(Usage, TheContractsHeadNamesTheVersionTheProgramsPrint) {
  std::ifstream in(PMU_INTERFACE_MD);
  std::string head;
  ASSERT_TRUE(std::getline(in, head)) << PMU_INTERFACE_MD;
  EXPECT_NE(head.find("(contract v" PMU_CONTRACT ")"), std::string::npos) << head;
}

}  // namespace
