// `pmuctl agent` (interface.md section 3.2): calls made on its host go through it with the
// caller's arguments, environment, directory, output and exit status; a command through it
// is executed once; calls it must not serve (another domain, watch, --no-agent) run on their
// own; one agent per socket, a stale socket is taken over, and an agent that ends during a
// call leaves the caller with "no answer", never a second run. An engine stop never waits
// behind another call (docs/safety.md H4); a call whose caller left or whose wait ended
// while it waited for a worker is never run (H9); a call trusts no agent another user could
// have put on its socket path (H6).
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <regex>
#include <string>
#include <thread>
#include <vector>

#include "pmu/dds/dds_context.hpp"
#include "pmu/idl/topics.hpp"
#include "support/configured_service.hpp"
#include "support/domain.hpp"
#include "support/json_lines.hpp"
#include "support/process.hpp"
#include "support/wait.hpp"
#include "support/temp_dir.hpp"

namespace pmuctl_agent_test {  // named: the unity build joins this file with others that have an `sh`

using namespace std::chrono_literals;
namespace fs = std::filesystem;

pmu::test::RunResult sh(const std::string& cmd) { return pmu::test::run_capture(cmd, true); }

std::string read_file(const std::string& path) {
  std::ifstream in(path);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

std::size_t count(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (auto at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

// An agent on `socket`, its log in `log`; started from the test's main thread.
pmu::test::Child start_agent(int domain, const std::string& socket, const std::string& log,
                             const std::string& workers = "4") {
  pmu::test::ChildOptions o;
  o.stderr_path = log;
  o.stdout_path = log;
  pmu::test::Child agent(
      {PMUCTL_PATH, "--domain", std::to_string(domain), "agent", "--socket", socket, "--workers", workers}, o);
  return agent;
}

// `pmuctl config set payload_voltage 23` to VEHICLE through the agent on `socket`, in the
// background, its output in `out`.
pmu::test::Child command_through(const std::string& socket, int domain, const std::string& vehicle,
                                 const std::string& timeout, const std::string& out) {
  pmu::test::ChildOptions o;
  o.env = {"PMU_AGENT_SOCKET=" + socket};
  o.stdout_path = out;
  o.stderr_path = out;
  return pmu::test::Child({PMUCTL_PATH, "--domain", std::to_string(domain), "--timeout", timeout, "--vehicle", vehicle,
                           "config", "set", "payload_voltage", "23"},
                          o);
}

// Whether a worker took the call whose arguments end in `call`: the agent's log says so
// ("pmuctl agent: worker W: pid P: ARGS: started") before the call runs. Waits for that line
// (a bound for a loaded machine, not a measurement).
bool taken(const std::string& log, const std::string& call) {
  return pmu::test::wait_until([&] { return read_file(log).find(call + ": started") != std::string::npos; }, 60s);
}

bool wait_for_socket(const std::string& path) {
  for (int i = 0; i < 200; ++i) {
    struct stat st {};
    if (::lstat(path.c_str(), &st) == 0 && S_ISSOCK(st.st_mode)) return true;
    std::this_thread::sleep_for(50ms);
  }
  return false;
}

// True when something listens on the Unix socket at `path`.
bool connects(const std::string& path) {
  const int fd = ::socket(AF_UNIX, SOCK_SEQPACKET | SOCK_CLOEXEC, 0);
  sockaddr_un addr{};
  addr.sun_family = AF_UNIX;
  std::strncpy(addr.sun_path, path.c_str(), sizeof addr.sun_path - 1);
  const bool ok = ::connect(fd, reinterpret_cast<const sockaddr*>(&addr), sizeof addr) == 0;
  ::close(fd);
  return ok;
}

class Uav1 : public pmu::test::ConfiguredService {
 public:
  explicit Uav1(int domain)
      : ConfiguredService(PMU_SERVICE_PATH, "domain: " + std::to_string(domain) +
                                                "\nvehicle: uav1\nqos_file: " + PMU_QOS_FILE +
                                                "\nlog_level: info\nbuses:\n  - interface: sim\n    name: can0\n"
                                                "    devices:\n      - address: 1\n        period: 0.5\n") {}
};

// uav1 on a domain of its own, and an agent on that domain listening on its socket.
class PmuctlAgentWithUav1 : public ::testing::Test {
 protected:
  void SetUp() override { ASSERT_TRUE(wait_for_socket(socket)) << read_file(log); }

  const int domain = pmu::test::exclusive_dds_domain();
  Uav1 uav1{domain};
  pmu::test::TempDir dir{"pmu-agent-test"};
  const std::string socket = dir.path() + "/agent.sock", log = dir.path() + "/agent.log";
  pmu::test::Child agent = start_agent(domain, socket, log);

  // The start of a pmuctl call to uav1 through the agent, ready for its options and verb.
  std::string uav1_calls() const {
    return "PMU_AGENT_SOCKET=" + socket + " " + PMUCTL_PATH + " --domain " + std::to_string(domain) +
           " --vehicle uav1 ";
  }
};

TEST_F(PmuctlAgentWithUav1, CallsGoThroughItWithTheCallersOutputStatusAndDirectory) {
  EXPECT_EQ(fs::status(socket).permissions() & fs::perms::all, fs::perms::owner_read | fs::perms::owner_write)
      << "only the agent's user may call it";
  const std::string p = "cd " + dir.path() + " && PMU_AGENT_SOCKET=" + socket + " " + PMUCTL_PATH + " --domain " +
                        std::to_string(domain) + " ";

  // The first call waits for the service as long as a loaded run needs.
  bool listed = false;
  for (int attempt = 0; attempt < 10 && !listed; ++attempt) {
    const auto r = sh(p + "--timeout 10 --json list");
    for (const auto& j : pmu::test::json_lines(r.out))
      listed = listed || (!j.is_discarded() && j.contains("vehicle") && j["vehicle"] == "uav1");
  }
  ASSERT_TRUE(listed) << read_file(log) << uav1.describe();

  // A command: its reply on the caller's stdout, exit 0, executed once by the service.
  auto r = sh(p + "--timeout 30 --vehicle uav1 --json config set payload_voltage 23");
  EXPECT_EQ(r.status, 0) << r.out;
  std::smatch m;
  ASSERT_TRUE(std::regex_search(r.out, m, std::regex("\"request_id\":\"([^\"]+)\""))) << r.out;
  const std::string id = m[1];
  EXPECT_NE(r.out.find("\"result\":\"COMPLETED\""), std::string::npos) << r.out;
  // The variable reaches the call: PMU_VEHICLE instead of --vehicle.
  r = sh("export PMU_VEHICLE=uav1; " + p + "--timeout 20 config get payload_voltage");
  EXPECT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("uav1/can0/1 payload_voltage = 23.0"), std::string::npos) << r.out;
  // A failing call's message on the caller's stderr and its exit status.
  r = sh(p + "--timeout 2 --vehicle uav9 config set payload_voltage 23");
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_NE(r.out.find("no pmu-service of vehicle uav9"), std::string::npos) << r.out;
  // A relative path is the caller's: the snapshot lands in the caller's directory.
  r = sh(p + "--timeout 20 --vehicle uav1 config snapshot snap.yaml");
  EXPECT_EQ(r.status, 0) << r.out;
  EXPECT_NE(read_file(dir.path() + "/snap.yaml").find("payload_voltage: 23.0"), std::string::npos);

  // Not served: --no-agent, watch (runs until stopped), another domain (declined, said).
  r = sh(p + "--no-agent --timeout 10 --vehicle uav1 config get payload_voltage");
  EXPECT_EQ(r.status, 0) << r.out;
  r = sh(p + "--timeout 10 watch --count 1 --low-rate");
  EXPECT_EQ(r.status, 0) << r.out;
  // A neighbouring domain that is in range: this test's may be the highest, 232. It may be
  // another test's at the same time, with a service on it: the call's own result (listed, or
  // exit 3 for none) is not the point, only that it ran on its own.
  const int other_domain = domain > 0 ? domain - 1 : domain + 1;
  r = sh("PMU_AGENT_SOCKET=" + socket + " " + PMUCTL_PATH + " --domain " + std::to_string(other_domain) +
         " --timeout 1 list");
  EXPECT_TRUE(r.status == 0 || r.status == 3) << r.out;
  EXPECT_NE(r.out.find("pmuctl: the agent on " + socket +
                       " does not serve this call (its domain, QoS file, "
                       "security or network options are not the agent's); it runs on its own"),
            std::string::npos)
      << r.out;

  // Another QoS file in the caller's environment is another participant's tuning: declined too.
  // The agent's own file, named by the option instead, is the agent's to serve.
  fs::copy_file(PMU_QOS_FILE, dir.path() + "/other-qos.xml");
  r = sh("export PMU_QOS_FILE=other-qos.xml; " + p + "--timeout 20 --vehicle uav1 config get payload_voltage");
  EXPECT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("does not serve this call (its domain, QoS file"), std::string::npos) << r.out;
  r = sh(p + "--qos-file " + fs::relative(PMU_QOS_FILE, dir.path()).string() +
         " --timeout 20 --vehicle uav1 config get payload_voltage");
  EXPECT_EQ(r.status, 0) << r.out;
  EXPECT_EQ(r.out.find("does not serve"), std::string::npos) << r.out;

  ASSERT_TRUE(agent.signal(SIGTERM));
  const auto st = agent.wait_for(10s);
  ASSERT_TRUE(st);
  EXPECT_TRUE(WIFEXITED(*st) && WEXITSTATUS(*st) == 0);
  EXPECT_FALSE(fs::exists(socket)) << "an agent that ends removes its socket";
  const std::string agent_log = read_file(log);
  EXPECT_NE(agent_log.find("--vehicle uav1 --json config set payload_voltage 23: exit 0"), std::string::npos)
      << agent_log;
  EXPECT_NE(agent_log.find("--vehicle uav9 config set payload_voltage 23: exit 2"), std::string::npos) << agent_log;
  EXPECT_NE(agent_log.find("config snapshot snap.yaml: exit 0"), std::string::npos) << agent_log;
  EXPECT_EQ(count(agent_log, "--no-agent"), 0u) << agent_log;
  EXPECT_EQ(count(agent_log, "watch"), 0u) << agent_log;
  EXPECT_EQ(count(agent_log, ": declined (its domain"), 2u) << agent_log;
  // Executed once: one audit line for the command's id in the service's log.
  const std::string service_log = uav1.describe();
  EXPECT_EQ(count(service_log, "audit: command " + id + " "), 1u) << service_log;
}

// The pids of the agent's workers (its child processes).
std::vector<pid_t> workers_of(pid_t agent) {
  std::vector<pid_t> pids;
  std::ifstream children("/proc/" + std::to_string(agent) + "/task/" + std::to_string(agent) + "/children");
  for (pid_t pid = 0; children >> pid;) pids.push_back(pid);
  return pids;
}

// `pmuctl list` of uav1 through the agent until it shows uav1's PMU at address 1 (the first
// calls wait for the service as long as a loaded run needs); `p` as uav1_calls() gives it.
bool listed_through_agent(const std::string& p) {
  for (int attempt = 0; attempt < 10; ++attempt)
    for (const auto& j : pmu::test::json_lines(sh(p + "--timeout 10 --json list").out))
      if (!j.is_discarded() && j.contains("address") && j["address"] == 1) return true;
  return false;
}

// The agent's worker sends a vehicle's later commands to the PMU it found for the first
// (target_memory.hpp); when that PMU has moved, the service's "not seen" (nothing executed)
// makes the call find it again and send the command there, once.
TEST_F(PmuctlAgentWithUav1, ACommandFollowsTheRememberedPmuWhenItMoved) {
  const std::string p = uav1_calls();
  ASSERT_TRUE(listed_through_agent(p)) << read_file(log) << uav1.describe();
  const auto reply_of = [](const std::string& out) {
    for (const auto& j : pmu::test::json_lines(out))
      if (!j.is_discarded() && j.contains("result")) return j;
    return nlohmann::json();
  };

  auto r = sh(p + "--timeout 30 --json config set payload_voltage 23");
  auto j = reply_of(r.out);
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_EQ(j["address"], 1) << r.out;
  r = sh(p + "--timeout 30 --confirm config set can_address 7");
  ASSERT_EQ(r.status, 0) << r.out << uav1.describe();

  r = sh(p + "--timeout 30 --json config set payload_voltage 24");
  j = reply_of(r.out);
  EXPECT_EQ(r.status, 0) << r.out << uav1.describe();
  EXPECT_EQ(j["result"], "COMPLETED") << r.out;
  EXPECT_EQ(j["address"], 7) << r.out;
  const std::string service_log = uav1.describe();
  // The remembered PMU was tried first: the service said it has no device 1 and did nothing.
  EXPECT_EQ(count(service_log, "-> REJECTED: device 1 not seen on can0"), 1u) << service_log;
  ASSERT_TRUE(j.contains("request_id")) << r.out;
  EXPECT_EQ(count(service_log, "audit: command " + j["request_id"].get<std::string>()), 1u) << service_log;
}

// A list through the agent tells its worker each vehicle's one PMU: the next command goes
// there without reading the health again. Moved meanwhile by a call of its own, the PMU is
// found again.
TEST_F(PmuctlAgentWithUav1, AListTellsTheWorkerEachVehiclesOnePmu) {
  const std::string p = uav1_calls();
  ASSERT_TRUE(listed_through_agent(p)) << read_file(log) << uav1.describe();
  auto r = sh(p + "--no-agent --timeout 30 --confirm config set can_address 7");
  ASSERT_EQ(r.status, 0) << r.out << uav1.describe();

  r = sh(p + "--timeout 30 --json config set payload_voltage 24");
  EXPECT_EQ(r.status, 0) << r.out << uav1.describe();
  EXPECT_NE(r.out.find("\"address\":7,"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("\"result\":\"COMPLETED\""), std::string::npos) << r.out;
  const std::string service_log = uav1.describe();
  EXPECT_EQ(count(service_log, "-> REJECTED: device 1 not seen on can0"), 1u) << "the listed PMU was tried first\n"
                                                                              << service_log;
}

// After a list through the agent, its worker has made the command writer of each vehicle it
// showed, so the first command there finds it matched: over a radio link its discovery
// would otherwise cost the command seconds. Seen by another participant, before any command.
TEST_F(PmuctlAgentWithUav1, AListMakesTheCommandWriterOfEachVehicleItShowed) {
  pmu::dds::DdsContext probe(domain, PMU_QOS_FILE, "agent-test-probe");
  ASSERT_TRUE(listed_through_agent(uav1_calls())) << read_file(log) << uav1.describe();
  const auto uav1_command_writer = [&] {
    for (const auto& w : probe.remote_writers().writers_of(pmu::topics::kCommand))
      for (const auto& partition : w.partitions)
        if (partition.find("uav1") != std::string::npos) return true;
    return false;
  };
  EXPECT_TRUE(pmu::test::wait_until(uav1_command_writer, 20s, 50ms)) << "no command writer of uav1 after the list\n"
                                                                     << read_file(log);
}

// docs/safety.md H6: uav1's service stops answering (SIGSTOP: as killed, but it can be let go
// at the end). The agent's workers still hold it, matched, until its DDS lease ends; a call
// on its own never finds it. Each verb's answer through the agent is the answer of the
// same call on its own: the same output and exit status, never an all-clear.
TEST_F(PmuctlAgentWithUav1, ADeadServiceGetsTheAnswersOfACallOnItsOwn) {
  const std::string p = uav1_calls();
  ASSERT_TRUE(listed_through_agent(p)) << read_file(log) << uav1.describe();
  const char* verbs[] = {
      "alarms",     "--json alarms", "list", "energy", "preflight", "config snapshot -", "config get payload_voltage",
      "--json list"};
  // Every verb once while the service answers, so the workers know its writers.
  for (const char* verb : verbs) (void)sh(p + "--timeout 10 " + verb);

  ASSERT_EQ(::kill(uav1.pid(), SIGSTOP), 0);
  struct LetGo {
    pid_t pid;
    ~LetGo() { ::kill(pid, SIGCONT); }
  } let_go{uav1.pid()};
  for (const char* verb : verbs) {
    SCOPED_TRACE(verb);
    const auto through_agent = sh(p + "--timeout 2 " + std::string(verb));
    const auto on_its_own = sh(p + "--no-agent --timeout 2 " + std::string(verb));
    EXPECT_EQ(on_its_own.status, 3) << on_its_own.out;
    EXPECT_EQ(through_agent.status, on_its_own.status) << through_agent.out << "\non its own:\n" << on_its_own.out;
    EXPECT_EQ(through_agent.out, on_its_own.out);
  }
  EXPECT_EQ(read_file(log).find("--timeout 2 alarms: exit 0"), std::string::npos) << read_file(log);
}

// Agent workers use no Fast DDS shared-memory port: one a killed worker leaves behind, with
// a reader slot nobody empties, would be given to its replacement, which would then hear
// nothing a service on this host sends it and say "no pmu-service" while uav1 runs
// (docs/safety.md H6).
TEST_F(PmuctlAgentWithUav1, NoWorkerHoldsASharedMemoryPortAKilledOneWouldLeave) {
  ASSERT_TRUE(listed_through_agent(uav1_calls())) << read_file(log) << uav1.describe();
  const auto workers = workers_of(agent.pid());
  ASSERT_FALSE(workers.empty()) << read_file(log);
  for (const pid_t w : workers) {
    const std::string maps = read_file("/proc/" + std::to_string(w) + "/maps");
    ASSERT_FALSE(maps.empty()) << "worker " << w;
    EXPECT_EQ(maps.find("fastrtps_port"), std::string::npos) << "worker " << w << " maps a shared-memory port";
  }
}

TEST_F(PmuctlAgentWithUav1, ACallThatWaitsForASilentAircraftHoldsUpNoOtherAndADeadWorkerIsReplaced) {
  const std::string p = "PMU_AGENT_SOCKET=" + socket + " " + PMUCTL_PATH + " --domain " + std::to_string(domain) + " ";
  bool served = false;
  for (int attempt = 0; attempt < 10 && !served; ++attempt)
    served = sh(p + "--timeout 10 --vehicle uav1 config get payload_voltage").status == 0;
  ASSERT_TRUE(served) << read_file(log) << uav1.describe();

  // uav9 has no service: its command waits out its whole timeout inside one worker.
  const std::string silent_out = dir.path() + "/silent.out";
  auto silent = command_through(socket, domain, "uav9", "25", silent_out);
  ASSERT_TRUE(taken(log, "--vehicle uav9 config set payload_voltage 23")) << read_file(log) << read_file(silent_out);
  ASSERT_TRUE(silent.running()) << read_file(silent_out);
  // Meanwhile a command to uav1 goes through another worker and completes.
  auto r = sh(p + "--timeout 20 --vehicle uav1 --json config set payload_voltage 22");
  EXPECT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("\"result\":\"COMPLETED\""), std::string::npos) << r.out;
  EXPECT_TRUE(silent.running()) << "uav1's command waited for uav9's to end: " << read_file(log);
  const auto st = silent.wait_for(40s);
  ASSERT_TRUE(st);
  EXPECT_TRUE(WIFEXITED(*st) && WEXITSTATUS(*st) == 2) << read_file(silent_out);

  // A worker that dies is replaced; calls go on being served by the agent.
  auto workers = workers_of(agent.pid());
  ASSERT_EQ(workers.size(), 5u) << "four workers and the stop lane: " << read_file(log);
  ASSERT_EQ(::kill(workers.front(), SIGKILL), 0);
  bool replaced = false;
  for (int i = 0; i < 100 && !replaced; ++i) {
    std::this_thread::sleep_for(100ms);
    replaced = read_file(log).find("worker pid " + std::to_string(workers.front()) +
                                   " ended (signal 9); a new one takes its place") != std::string::npos &&
               workers_of(agent.pid()).size() == 5u;
  }
  EXPECT_TRUE(replaced) << read_file(log);
  for (int i = 0; i < 4; ++i) {
    r = sh(p + "--timeout 20 --vehicle uav1 config get payload_voltage");
    EXPECT_EQ(r.status, 0) << r.out << "the agent's log:\n" << read_file(log) << uav1.describe();
    EXPECT_NE(r.out.find("uav1/can0/1 payload_voltage = 22.0"), std::string::npos) << r.out;
  }

  // Stopping the agent stops every worker.
  workers = workers_of(agent.pid());
  ASSERT_TRUE(agent.signal(SIGTERM));
  ASSERT_TRUE(agent.wait_for(20s));
  for (const pid_t w : workers) EXPECT_NE(::kill(w, 0), 0) << "worker " << w << " outlived its agent";
  EXPECT_FALSE(fs::exists(socket));
}

// uav1 on a domain of its own, and an agent with one worker for calls on that domain.
class PmuctlAgentWithOneWorker : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_TRUE(wait_for_socket(socket)) << read_file(log);
    bool served = false;
    for (int attempt = 0; attempt < 10 && !served; ++attempt)
      served = sh(calls() + "--timeout 10 --vehicle uav1 config set payload_voltage 22").status == 0;
    ASSERT_TRUE(served) << read_file(log) << uav1.describe();
  }

  // The start of a pmuctl call through the agent, ready for its options and verb.
  std::string calls() const {
    return "PMU_AGENT_SOCKET=" + socket + " " + PMUCTL_PATH + " --domain " + std::to_string(domain) + " ";
  }

  const int domain = pmu::test::exclusive_dds_domain();
  Uav1 uav1{domain};
  pmu::test::TempDir dir{"pmu-agent-test"};
  const std::string socket = dir.path() + "/agent.sock", log = dir.path() + "/agent.log";
  pmu::test::Child agent = start_agent(domain, socket, log, "1");
};

// docs/safety.md H4: the only worker for calls waits for an aircraft that does not answer;
// an engine stop meanwhile goes out on the stop lane, and completes while that call still waits.
TEST_F(PmuctlAgentWithOneWorker, AnEngineStopNeverWaitsBehindAnotherCall) {
  const std::string silent_out = dir.path() + "/silent.out";
  auto silent = command_through(socket, domain, "uav9", "60", silent_out);
  ASSERT_TRUE(taken(log, "--vehicle uav9 config set payload_voltage 23")) << read_file(log) << read_file(silent_out);
  ASSERT_TRUE(silent.running()) << read_file(silent_out);

  const auto r = sh(calls() + "--timeout 20 --vehicle uav1 engine stop");
  EXPECT_EQ(r.status, 0) << r.out << read_file(log);
  EXPECT_NE(r.out.find("COMPLETED"), std::string::npos) << r.out;
  EXPECT_TRUE(silent.running()) << "the stop waited for the call before it:\n" << read_file(log);
  EXPECT_NE(read_file(log).find("worker stop: pid "), std::string::npos) << read_file(log);
  EXPECT_NE(read_file(log).find("--vehicle uav1 engine stop: exit 0"), std::string::npos) << read_file(log);
}

// docs/safety.md H9: calls queued behind a call that holds the only worker. One whose caller
// gave up (killed by `timeout`) and one whose wait ended are never run, and the log says so;
// the second caller hears that it was not run (exit 3).
TEST_F(PmuctlAgentWithOneWorker, ACallWhoseCallerGaveUpIsNeverRun) {
  const std::string silent_out = dir.path() + "/silent.out";
  auto silent = command_through(socket, domain, "uav9", "15", silent_out);
  ASSERT_TRUE(taken(log, "--vehicle uav9 config set payload_voltage 23")) << read_file(log) << read_file(silent_out);
  ASSERT_TRUE(silent.running()) << read_file(silent_out);

  auto r = sh("timeout -s INT 2 env " + calls() + "--timeout 30 --vehicle uav1 config set payload_voltage 21");
  EXPECT_EQ(r.status, 124) << r.out;
  r = sh(calls() + "--timeout 2 --vehicle uav1 config set payload_voltage 20");
  EXPECT_EQ(r.status, 3) << r.out;
  EXPECT_NE(r.out.find("pmuctl: the agent on " + socket +
                       " did not run the call: its wait (--timeout) ended before "
                       "one of the agent's workers was free"),
            std::string::npos)
      << r.out;
  EXPECT_TRUE(silent.running()) << read_file(log);
  const auto st = silent.wait_for(40s);
  ASSERT_TRUE(st);

  // Neither ran: the value is the one set before.
  r = sh(calls() + "--timeout 20 --vehicle uav1 config get payload_voltage");
  EXPECT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("uav1/can0/1 payload_voltage = 22.0"), std::string::npos) << r.out << uav1.describe();
  const std::string agent_log = read_file(log);
  EXPECT_NE(agent_log.find("config set payload_voltage 21: dropped: its caller left before a worker was free"),
            std::string::npos)
      << agent_log;
  EXPECT_NE(agent_log.find("config set payload_voltage 20: dropped: its caller's wait ended before a worker was free"),
            std::string::npos)
      << agent_log;
  EXPECT_EQ(count(agent_log, "payload_voltage 21: started"), 0u) << agent_log;
  EXPECT_EQ(count(agent_log, "payload_voltage 20: started"), 0u) << agent_log;
  EXPECT_EQ(count(agent_log, "payload_voltage 21: exit"), 0u) << agent_log;
  EXPECT_EQ(count(agent_log, "payload_voltage 20: exit"), 0u) << agent_log;
}

// docs/safety.md H6: a process of another user listening on the socket path, in a folder
// every user may write to, gets nothing of root's call, and cannot answer it: the call runs
// on its own and says why (no service here: exit 3, never the fake's READY).
TEST(PmuctlAgent, ACallTrustsNoAgentOfAnotherUser) {
  if (::geteuid() != 0) GTEST_SKIP() << "a listener of another user needs root to start";
  const int domain = pmu::test::exclusive_dds_domain();
  pmu::test::TempDir dir{"pmu-agent-test"};
  ASSERT_EQ(::chmod(dir.path().c_str(), 01777), 0);  // a shared folder, as /tmp
  const std::string socket = dir.path() + "/agent.sock";
  const pid_t fake = ::fork();
  ASSERT_GE(fake, 0);
  if (fake == 0) {
    // nobody's fake agent: prints READY on the caller's stdout and answers exit 0.
    if (::setgid(65534) != 0 || ::setuid(65534) != 0) ::_exit(1);
    const int fd = ::socket(AF_UNIX, SOCK_SEQPACKET, 0);
    sockaddr_un addr{};
    addr.sun_family = AF_UNIX;
    std::strncpy(addr.sun_path, socket.c_str(), sizeof addr.sun_path - 1);
    if (::bind(fd, reinterpret_cast<const sockaddr*>(&addr), sizeof addr) != 0 || ::listen(fd, 4) != 0) ::_exit(1);
    ::chmod(socket.c_str(), 0777);
    for (;;) {
      const int c = ::accept(fd, nullptr, nullptr);
      char buf[65536];
      char control[CMSG_SPACE(sizeof(int) * 3)];
      iovec iov{buf, sizeof buf};
      msghdr msg{};
      msg.msg_iov = &iov;
      msg.msg_iovlen = 1;
      msg.msg_control = control;
      msg.msg_controllen = sizeof control;
      if (::recvmsg(c, &msg, 0) > 0)
        if (cmsghdr* h = CMSG_FIRSTHDR(&msg)) {
          int fds[3];
          std::memcpy(fds, CMSG_DATA(h), sizeof fds);
          (void)!::write(fds[1], "uav1: READY\n", 12);
          for (const int f : fds) ::close(f);  // the caller's output ends with the call
        }
      (void)!::send(c, "exit 0", 6, 0);
      ::close(c);
    }
  }
  struct Reap {
    pid_t pid;
    ~Reap() {
      ::kill(pid, SIGKILL);
      ::waitpid(pid, nullptr, 0);
    }
  } reap{fake};
  ASSERT_TRUE(wait_for_socket(socket));
  ASSERT_TRUE(pmu::test::wait_until([&] { return connects(socket); }, 10s, 20ms));

  const auto r = sh("PMU_AGENT_SOCKET=" + socket + " " + PMUCTL_PATH + " --domain " + std::to_string(domain) +
                    " --timeout 1 preflight");
  EXPECT_EQ(r.status, 3) << r.out;
  EXPECT_EQ(r.out.find("READY"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("pmuctl: not using the agent on " + socket + ": its folder " + dir.path() +
                       " is writable by other users (mode 1777); the call runs on its own"),
            std::string::npos)
      << r.out;
}

TEST(PmuctlAgent, OneAgentPerSocketAndAStaleSocketIsTakenOver) {
  const int domain = pmu::test::exclusive_dds_domain();
  pmu::test::TempDir dir{"pmu-agent-test"};
  const std::string socket = dir.path() + "/agent.sock";
  {
    // What a killed agent leaves: a socket file nobody listens on.
    const int fd = ::socket(AF_UNIX, SOCK_SEQPACKET, 0);
    sockaddr_un addr{};
    addr.sun_family = AF_UNIX;
    std::strcpy(addr.sun_path, socket.c_str());
    ASSERT_EQ(::bind(fd, reinterpret_cast<const sockaddr*>(&addr), sizeof addr), 0);
    ::close(fd);
  }
  auto first = start_agent(domain, socket, dir.path() + "/first.log");
  // The stale file is replaced by a socket that is listened on.
  bool listening = false;
  for (int i = 0; i < 200 && !listening && first.running(); ++i) {
    listening = connects(socket);
    if (!listening) std::this_thread::sleep_for(50ms);
  }
  ASSERT_TRUE(listening) << read_file(dir.path() + "/first.log");
  // A second agent finds it taken (`timeout`: one that wrongly listened would never end).
  const auto second = sh("timeout 20 " + std::string(PMUCTL_PATH) + " --domain " + std::to_string(domain) +
                         " agent --socket " + socket);
  EXPECT_EQ(second.status, 2) << second.out;
  EXPECT_NE(second.out.find("pmuctl agent: another agent listens on " + socket), std::string::npos) << second.out;
  EXPECT_TRUE(first.running()) << read_file(dir.path() + "/first.log");

  // A path that is not a socket is never replaced.
  const std::string file = dir.path() + "/not-a-socket";
  std::ofstream(file) << "keep me\n";
  const auto r = sh("timeout 20 " + std::string(PMUCTL_PATH) + " agent --socket " + file);
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.out.find("pmuctl agent: " + file + " exists and is not a socket: not replaced"), std::string::npos)
      << r.out;
  EXPECT_EQ(read_file(file), "keep me\n");
}

TEST(PmuctlAgent, AnAgentThatEndsDuringACallLeavesNoAnswerAndNoSecondRun) {
  const int domain = pmu::test::exclusive_dds_domain();
  pmu::test::TempDir dir{"pmu-agent-test"};
  const std::string socket = dir.path() + "/agent.sock", log = dir.path() + "/agent.log";
  auto agent = start_agent(domain, socket, log);
  ASSERT_TRUE(wait_for_socket(socket)) << read_file(log);
  // No service on the domain: the call waits its whole timeout inside the agent.
  const std::string call_out = dir.path() + "/call.out";
  auto call = command_through(socket, domain, "uav1", "20", call_out);
  // Ended once a worker holds the call: before, the call would find no agent and run on its own.
  ASSERT_TRUE(taken(log, "--vehicle uav1 config set payload_voltage 23")) << read_file(log) << read_file(call_out);
  ASSERT_TRUE(agent.signal(SIGKILL));
  const auto st = call.wait_for(15s);
  ASSERT_TRUE(st) << "the call did not end when its agent did";
  EXPECT_TRUE(WIFEXITED(*st) && WEXITSTATUS(*st) == 3) << read_file(call_out);
  // Had it run the call again on its own, that run would have said there is no service.
  EXPECT_EQ(read_file(call_out).find("no pmu-service"), std::string::npos) << read_file(call_out);
  EXPECT_NE(read_file(call_out).find("pmuctl: the agent on " + socket +
                                     " ended during the call: it may have been carried out (see the agent's "
                                     "log), so it is not run again"),
            std::string::npos)
      << read_file(call_out);
}

}  // namespace pmuctl_agent_test
