// Every file a program reads whole must be a regular file within its bound (interface.md 4.3,
// docs/safety.md H12): pmu-service, its --check-config and pmuctl's config verbs refuse a
// device, a FIFO or a huge file at once, exit status 2, naming the file and, for a file a
// config names, the config's line. Before the fix /dev/zero ended them with std::bad_alloc
// (status 134) and a FIFO kept them waiting for ever. Also the firmware a simulated PMU may
// be, which --check-config judges as the start does (interface.md 4.4).
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstdlib>
#include <fstream>
#include <string>

#include "support/process.hpp"

namespace file_input_test {
namespace {

class Folder {
 public:
  Folder() {
    char templ[] = "/tmp/pmu-file-input-XXXXXX";
    if (::mkdtemp(templ) != nullptr) path_ = templ;
  }
  ~Folder() { (void)pmu::test::run_capture("rm -rf '" + path_ + "'"); }
  Folder(const Folder&) = delete;
  Folder& operator=(const Folder&) = delete;
  std::string write(const std::string& name, const std::string& text) const {
    std::ofstream(path_ + "/" + name) << text;
    return path_ + "/" + name;
  }
  // A FIFO nobody writes to.
  std::string fifo(const std::string& name) const {
    const std::string p = path_ + "/" + name;
    return ::mkfifo(p.c_str(), 0600) == 0 ? p : std::string();
  }

 private:
  std::string path_;
};

struct Case {
  std::string what;
  std::string command;  // run with stderr into stdout
  std::string says;     // part of the output
};

void expect_refused(const Case& c) {
  SCOPED_TRACE(c.what);
  // stdin from /dev/null: nothing a program might wait on but the file itself.
  const auto r = pmu::test::run_capture(c.command + " </dev/null 2>&1");
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_NE(r.out.find(c.says), std::string::npos) << r.out;
}

const std::string kSimBus = "buses:\n  - interface: sim\n    devices:\n      - address: 1\n";

TEST(FileInput, PmuServiceRefusesADeviceOrAFifoAsItsConfigOrABaseline) {
  Folder dir;
  const std::string fifo = dir.fifo("pmu1.yaml");
  ASSERT_FALSE(fifo.empty());
  const std::string zero_baseline = dir.write("zero.yaml", kSimBus + "        baseline: /dev/zero\n");
  const std::string fifo_baseline = dir.write("fifo.yaml", kSimBus + "        baseline: pmu1.yaml\n");
  const std::string service = std::string(PMU_SERVICE_PATH);
  const Case cases[] = {
      {"a baseline of /dev/zero, checked", service + " --check-config --config " + zero_baseline,
       zero_baseline + ":5: baseline /dev/zero cannot be read: it is a character device, not a regular file"},
      {"a baseline of /dev/zero, started", service + " --config " + zero_baseline,
       zero_baseline + ":5: baseline /dev/zero cannot be read: it is a character device, not a regular file"},
      {"a FIFO baseline, checked", service + " --check-config --config " + fifo_baseline,
       fifo_baseline + ":5: baseline " + fifo + " cannot be read: it is a FIFO, not a regular file"},
      {"a FIFO baseline, started", service + " --config " + fifo_baseline,
       fifo_baseline + ":5: baseline " + fifo + " cannot be read: it is a FIFO, not a regular file"},
      {"the config is /dev/zero", service + " --check-config --config /dev/zero",
       "/dev/zero: cannot read the config file: it is a character device, not a regular file"},
      {"the config is a FIFO", service + " --config " + fifo,
       fifo + ": cannot read the config file: it is a FIFO, not a regular file"},
  };
  for (const auto& c : cases) expect_refused(c);
}

TEST(FileInput, CheckConfigRefusesAFirmwareTheSimulatorCannotBe) {
  Folder dir;
  for (const char* firmware : {"9.9", "1.11"}) {
    const std::string config = dir.write("sim.yaml", kSimBus + "        sim: {firmware: \"" + firmware + "\"}\n");
    expect_refused({std::string("sim firmware ") + firmware,
                    std::string(PMU_SERVICE_PATH) + " --check-config --config " + config,
                    config + ":5: firmware '" + firmware + "': the simulator is firmware 1.12..1.17"});
  }
  const std::string good = dir.write("good.yaml", kSimBus + "        sim: {firmware: \"1.12\"}\n");
  const auto r = pmu::test::run_capture(std::string(PMU_SERVICE_PATH) + " --check-config --config " + good + " 2>&1");
  EXPECT_EQ(r.status, 0) << r.out;
}

// pmuctl reads its file before it joins the domain: no service is needed to refuse it.
TEST(FileInput, PmuctlConfigVerbsRefuseADeviceOrAFifo) {
  Folder dir;
  const std::string fifo = dir.fifo("pmu1.yaml");
  ASSERT_FALSE(fifo.empty());
  const std::string huge = dir.write("huge.yaml", "# " + std::string(64 * 1024, 'x') + "\noutputs: []\n");
  const std::string pmuctl = std::string(PMUCTL_PATH) + " --no-agent --timeout 1 ";
  const Case cases[] = {
      {"diff /dev/zero", pmuctl + "config diff /dev/zero",
       "/dev/zero: cannot be read: it is a character device, not a regular file"},
      {"diff a FIFO", pmuctl + "config diff " + fifo, fifo + ": cannot be read: it is a FIFO, not a regular file"},
      {"diff a huge file", pmuctl + "config diff " + huge,
       huge + ": cannot be read: it is 65551 bytes, larger than the 64 KiB bound"},
      {"apply /dev/zero", pmuctl + "config apply /dev/zero",
       "/dev/zero: cannot be read: it is a character device, not a regular file"},
      {"apply --dry-run a FIFO", pmuctl + "config apply --dry-run " + fifo,
       fifo + ": cannot be read: it is a FIFO, not a regular file"},
      {"diff /dev/zero, --json", pmuctl + "--json config diff /dev/zero", "\"exit_status\":2"},
  };
  for (const auto& c : cases) expect_refused(c);
}

}  // namespace
}  // namespace file_input_test
