// Several operators at once against one pmu-service on its built-in simulator: random steps of
// calls (sets that would cut the avionics, force a shutdown or blind a rule, engine starts and
// stops, address changes, resets, two applies at once, calls given up midway, directly and
// through the agent, the service killed and started again), and after every step the
// invariants of docs/safety.md ("Invariants", I1..I7) checked against what the unit holds,
// what it streams and what the service logged.
//
// It prints its seed first. PMU_INTERLEAVING_SEED=N repeats a run; PMU_INTERLEAVING_SECONDS=S
// runs it for S seconds instead of kDefaultSeconds (a longer run by hand finds rarer
// interleavings; the steps are the same for a seed, their timing is the machine's).
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <csignal>
#include <cstdlib>
#include <ctime>
#include <fstream>
#include <iostream>
#include <iterator>
#include <optional>
#include <random>
#include <regex>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "support/domain.hpp"
#include "support/json_lines.hpp"
#include "support/process.hpp"
#include "support/wait.hpp"
#include "support/temp_dir.hpp"

namespace interleaving_test {  // named: the unity build joins this file with others

using namespace std::chrono_literals;
using Json = nlohmann::json;
using Clock = std::chrono::steady_clock;

constexpr int kDefaultSeconds = 90;
// The simulated PMU's internal temperature (degC): a T_U at or below it is a thermal shutdown.
constexpr int kInternalTemperature = 40;
// The unit's cranking time (s), set at every start of the service: long enough that a unit
// left cranking by a start that gave up is still cranking when the step is checked.
constexpr double kCrankingTime = 8.0;
// What may pass between a set's frame and its audit line: the read-back's reply timeout
// (timeouts.reply, 0.25 s; a set is never repeated) and the log's own delay on a busy host.
constexpr double kSetToAudit = 1.0;

std::string read_text(const std::string& path) {
  std::ifstream in(path);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

std::string env_or(const char* name, const std::string& fallback) {
  const char* v = std::getenv(name);
  return v && *v ? v : fallback;
}

// Wall-clock seconds of the audit line's "YYYY-MM-DD HH:MM:SS.mmm" prefix (the service's log
// pattern with no journal), local time.
std::optional<double> log_line_time(const std::string& line) {
  std::tm tm{};
  int ms = 0;
  if (line.size() < 23 || std::sscanf(line.c_str(), "%d-%d-%d %d:%d:%d.%d", &tm.tm_year, &tm.tm_mon, &tm.tm_mday,
                                      &tm.tm_hour, &tm.tm_min, &tm.tm_sec, &ms) != 7)
    return std::nullopt;
  tm.tm_year -= 1900;
  tm.tm_mon -= 1;
  tm.tm_isdst = -1;
  return static_cast<double>(std::mktime(&tm)) + ms / 1000.0;
}

double wall_now() { return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count(); }

// pmu-service on this test's config, started again after a kill; each start logs to a file of
// its own, and log() is all of them. Start and kill it from the test's main thread.
class Service {
 public:
  Service(int domain, std::string dir) : domain_(domain), dir_(std::move(dir)) {
    std::ofstream(dir_ + "/pmu-service.yaml")
        << "domain: " << domain_ << "\nqos_file: " << PMU_QOS_FILE << "\nlog_level: info\n"
        << "buses:\n  - interface: sim\n    devices:\n      - address: 1\n        period: 0.5\n"
        << "        sim: {engine: stopped, engine_starts_after: never, internal_temperature: " << kInternalTemperature
        << "}\n";
  }
  void start() {
    pmu::test::ChildOptions o;
    o.stdout_path = o.stderr_path = dir_ + "/service-" + std::to_string(starts_++) + ".log";
    // The moved-addresses record goes to the test's folder, not the host's /var/lib.
    o.env = {"STATE_DIRECTORY=" + dir_};
    child_ = pmu::test::Child({PMU_SERVICE_PATH, "--config", dir_ + "/pmu-service.yaml"}, o);
  }
  void kill() {
    child_.signal(SIGKILL);
    child_.wait_for(10s);
  }
  bool running() { return child_.running(); }
  std::string log() const {
    std::string all;
    for (int i = 0; i < starts_; ++i) all += read_text(dir_ + "/service-" + std::to_string(i) + ".log");
    return all;
  }

 private:
  int domain_;
  std::string dir_;
  int starts_ = 0;
  pmu::test::Child child_;
};

enum class Via { Own, Agent };

// One operator's call: pmuctl with `args`, on its own or through the agent, started `at` s
// into the step; given up (SIGINT, as Ctrl-C or `timeout -s INT`) at `give_up_at` if set.
struct Call {
  std::string what;
  std::vector<std::string> args;
  Via via = Via::Own;
  double at = 0;
  double timeout = 12;
  std::optional<double> give_up_at;
  // What the step learns when it ends.
  pmu::test::Child child;
  std::string out_path;
  double wall_started = 0;
  std::optional<int> status;  // exit status; nullopt when a signal ended it
  bool gave_up = false;
  std::string output;
};

const std::regex kFinal("^(COMPLETED|REJECTED|DENIED|UNSUPPORTED|TIMEOUT|FAILED)\\b");

std::vector<std::string> final_lines(const std::string& output) {
  std::vector<std::string> lines;
  std::istringstream in(output);
  for (std::string line; std::getline(in, line);)
    if (std::regex_search(line, kFinal)) lines.push_back(line);
  return lines;
}

// What the unit holds and streams after a step, read by calls of the test's own.
struct Observed {
  Json config;                    // pmu/config values
  std::optional<Json> status;     // the last pmu/status values, when it is streamed
  std::optional<Json> readiness;  // the unnamed vehicle's pmu/readiness
  std::string raw;                // for messages
};

class Interleavings : public ::testing::Test {
 protected:
  void SetUp() override {
    seed_ = std::stoull(env_or("PMU_INTERLEAVING_SEED", std::to_string(std::random_device{}())));
    seconds_ = std::stoi(env_or("PMU_INTERLEAVING_SECONDS", std::to_string(kDefaultSeconds)));
    std::cout << "seed " << seed_ << " (PMU_INTERLEAVING_SEED), " << seconds_ << " s" << std::endl;
    rng_.seed(seed_);
    domain_ = pmu::test::exclusive_dds_domain();
    socket_ = dir_.path() + "/agent.sock";
    service_ = std::make_unique<Service>(domain_, dir_.path());
  }

  // The pmuctl command line of a call, and how it reaches the agent.
  pmu::test::Child launch(Call& c, int index) {
    std::vector<std::string> argv{PMUCTL_PATH, "--domain", std::to_string(domain_), "--timeout",
                                  std::to_string(c.timeout)};
    if (c.via == Via::Own) argv.push_back("--no-agent");
    argv.insert(argv.end(), c.args.begin(), c.args.end());
    pmu::test::ChildOptions o;
    o.env = {"PMU_AGENT_SOCKET=" + socket_};
    c.out_path = dir_.path() + "/call-" + std::to_string(step_) + "-" + std::to_string(index) + ".out";
    o.stdout_path = o.stderr_path = c.out_path;
    o.stop_grace = 20000ms;
    return pmu::test::Child(argv, o);
  }

  std::string args_text(const Call& c) const {
    std::string s = c.via == Via::Agent ? "[agent] pmuctl" : "pmuctl --no-agent";
    s += " --timeout " + std::to_string(static_cast<int>(c.timeout));
    for (const auto& a : c.args) s += " " + a;
    if (c.give_up_at) s += " (given up at " + std::to_string(*c.give_up_at) + " s)";
    return s;
  }

  // Runs the calls of one step: each started at its time, given up at its time, all reaped.
  void run(std::vector<Call>& calls) {
    const auto t0 = Clock::now();
    struct Event {
      double at;
      std::size_t call;
      bool give_up;
    };
    std::vector<Event> events;
    for (std::size_t i = 0; i < calls.size(); ++i) {
      events.push_back({calls[i].at, i, false});
      if (calls[i].give_up_at) events.push_back({*calls[i].give_up_at, i, true});
    }
    std::stable_sort(events.begin(), events.end(), [](const Event& a, const Event& b) { return a.at < b.at; });
    for (const auto& e : events) {
      std::this_thread::sleep_until(t0 +
                                    std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(e.at)));
      Call& c = calls[e.call];
      if (!e.give_up) {
        c.wall_started = wall_now();
        c.child = launch(c, static_cast<int>(e.call));
      } else if (c.child.running()) {
        c.gave_up = true;
        c.child.signal(SIGINT);
      }
    }
    for (auto& c : calls) {
      const auto st = c.child.wait_for(
          std::chrono::duration_cast<std::chrono::milliseconds>(std::chrono::duration<double>(c.timeout + 30)));
      if (st && WIFEXITED(*st)) c.status = WEXITSTATUS(*st);
      c.output = read_text(c.out_path);
      history_ += "  " + args_text(c) + " at " + std::to_string(c.at) + " s -> " +
                  (c.status ? "exit " + std::to_string(*c.status) : std::string("signalled")) +
                  (c.gave_up ? " (given up)" : "") + "\n";
    }
  }

  pmu::test::RunResult own(const std::string& args) {
    return pmu::test::run_capture(
        std::string(PMUCTL_PATH) + " --domain " + std::to_string(domain_) + " --no-agent " + args, true);
  }
  pmu::test::RunResult through_agent(const std::string& args) {
    return pmu::test::run_capture(
        "PMU_AGENT_SOCKET=" + socket_ + " " + PMUCTL_PATH + " --domain " + std::to_string(domain_) + " " + args, true);
  }

  // The service answers for its PMU: up, configured as the steps expect (cranking time).
  bool service_ready() {
    const bool up =
        pmu::test::wait_until([&] { return own("--timeout 5 config get cranking_time").status == 0; }, 60s, 500ms);
    if (!up) return false;
    return own("--timeout 10 config set cranking_time " + std::to_string(kCrankingTime)).status == 0;
  }

  Observed observe() {
    Observed o;
    const auto config = own("--timeout 10 --json config get");
    for (const auto& j : pmu::test::json_lines(config.out))
      if (!j.is_discarded() && j.value("topic", "") == "config") o.config = j["values"];
    // Samples sent after the step ended: watch shows only what arrives while it runs.
    const auto watch = own("--timeout 10 --json watch --count 12");
    for (const auto& j : pmu::test::json_lines(watch.out)) {
      if (j.is_discarded()) continue;
      const auto topic = j.value("topic", "");
      if (topic == "status") o.status = j["values"];
    }
    const auto ready = own("--timeout 10 --json preflight");
    for (const auto& j : pmu::test::json_lines(ready.out))
      if (!j.is_discarded() && j.value("topic", "") == "readiness") o.readiness = j;
    o.raw = config.out + watch.out.substr(watch.out.size() > 2000 ? watch.out.size() - 2000 : 0) + ready.out;
    return o;
  }

  // Records a broken invariant with everything needed to repeat and read it.
  void broken(const std::string& invariant, const std::string& detail) {
    ADD_FAILURE() << invariant << ": " << detail << "\nseed " << seed_ << ", step " << step_ << "\nsteps:\n"
                  << history_ << "\nthe service's own log lines (end):\n"
                  << own_lines(service_->log(), 40);
    failed_ = true;
  }
  // The last `n` lines pmu-service wrote itself (they start with their date), without Fast
  // DDS's own.
  static std::string own_lines(const std::string& log, std::size_t n) {
    std::vector<std::string> lines;
    std::istringstream in(log);
    for (std::string line; std::getline(in, line);)
      if (!line.empty() && line[0] >= '0' && line[0] <= '9') lines.push_back(line);
    std::string out;
    for (std::size_t i = lines.size() > n ? lines.size() - n : 0; i < lines.size(); ++i) out += lines[i] + "\n";
    return out;
  }

  double uniform(double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(rng_); }
  int integer(int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng_); }
  bool chance(double p) { return std::bernoulli_distribution(p)(rng_); }
  Via via() { return chance(0.5) ? Via::Agent : Via::Own; }
  std::string tenths(int t) { return std::to_string(t / 10) + "." + std::to_string(t % 10); }

  // ---- steps ---------------------------------------------------------------------------

  // A confirmed engine start, waited for as long as a start that never fires runs.
  static Call engine_start(Via v) {
    Call c;
    c.what = "engine start";
    c.via = v;
    c.args = {"--confirm", "engine", "start"};
    c.timeout = kCrankingTime + 6;
    return c;
  }
  static Call engine_stop(Via v, double at) {
    Call c;
    c.what = "engine stop";
    c.via = v;
    c.at = at;
    c.args = {"engine", "stop"};
    return c;
  }

  // Sets an operator might make in a hurry, none of them confirmed: each either is harmless or
  // must be refused (I3, I4, I2), and the harmless ones put things back.
  std::vector<Call> step_sets() {
    std::vector<Call> calls;
    const int n = integer(1, 3);
    for (int i = 0; i < n; ++i) {
      Call c;
      c.via = via();
      c.at = uniform(0, 1.0);
      switch (integer(0, 7)) {
        case 0: c.args = {"config", "set", "avionics_voltage", tenths(integer(120, 179))}; break;
        case 1: c.args = {"config", "set", "upper_temperature_limit", std::to_string(integer(0, 100))}; break;
        case 2: c.args = {"outputs", "disable", "avionics_servo"}; break;
        case 3: c.args = {"outputs", "set", "payload"}; break;
        case 4: c.args = {"config", "set", "power_up_state", "payload"}; break;
        case 5: {
          static const char* kReduced[] = {
              "voltages", "voltages,currents", "voltages,currents,battery_energy", "temperatures",
              "status",   "voltages,status"};
          c.args = {"config", "set", "packets_streamed", kReduced[integer(0, 5)]};
          break;
        }
        case 6:
          c.args = {"config", "set", "packets_streamed", "voltages,currents,battery_energy,temperatures,status"};
          break;
        default: c.args = {"--confirm", "reset"}; break;
      }
      c.what = c.args[0] == "--confirm" ? "reset" : c.args[0] + " " + c.args[1];
      calls.push_back(std::move(c));
    }
    return calls;
  }

  // An engine start (confirmed) and, a moment later, the operator's stop, or an address
  // change while it cranks, or a start left to run to its end.
  std::vector<Call> step_engine() {
    std::vector<Call> calls;
    calls.push_back(engine_start(via()));
    const int how = integer(0, 3);
    if (how <= 1) {
      const Via v = via();
      calls.push_back(engine_stop(v, uniform(0.3, 4.0)));
    } else if (how == 2) {
      Call move;
      move.what = "address change";
      move.via = via();
      move.at = uniform(0.5, 3.0);
      move.args = {"--confirm", "config", "set", "can_address", address_ == 1 ? "7" : "1"};
      calls.push_back(std::move(move));
    }
    return calls;
  }

  // A call through the agent while its one worker is held by an engine start, given up before
  // the worker is free: the agent must drop it (I6). A stop ends the start after the given-up
  // call's wait has ended. A call on its own is given up too, midway.
  std::vector<Call> step_given_up() {
    std::vector<Call> calls;
    calls.push_back(engine_start(Via::Agent));
    for (const Via v : {Via::Agent, Via::Own}) {
      if (markers_.size() >= 60) break;
      Call late;
      late.what = "given-up set";
      late.via = v;
      late.at = uniform(0.4, 0.8);
      late.timeout = 2;
      late.give_up_at = late.at + uniform(0.2, 1.5);
      const int marker = 180 + static_cast<int>(markers_.size());  // 18.0 V .. 23.9 V: given-up calls only
      late.args = {"config", "set", "avionics_voltage", tenths(marker)};
      markers_.push_back(tenths(marker));
      calls.push_back(std::move(late));
    }
    calls.push_back(engine_stop(Via::Own, 4.0));
    return calls;
  }

  // Two applies at once, one through the agent, of two files that set the same three settings
  // to other values (I7).
  std::vector<Call> step_applies(std::vector<std::string>& names, std::vector<Json>& expected) {
    const std::string snapshot = dir_.path() + "/start-" + std::to_string(step_) + ".yaml";
    const auto r = own("--timeout 10 config snapshot --force " + snapshot);
    if (r.status != 0) {
      broken("I1", "config snapshot failed: " + r.out);
      return {};
    }
    const std::string text = read_text(snapshot);
    names = {"payload_voltage", "servo_voltage", "battery_voltage"};
    std::vector<Call> calls;
    for (int f = 0; f < 2; ++f) {
      Json values;
      std::string file = text;
      const std::vector<std::string> picked{tenths(integer(120, 240)), tenths(integer(50, 120)),
                                            tenths(integer(200, 252))};
      for (std::size_t i = 0; i < names.size(); ++i) {
        file = std::regex_replace(file, std::regex("(\\n  " + names[i] + ": )[^\\n#]*"), "$1" + picked[i] + " ");
        values[names[i]] = std::stod(picked[i]);
      }
      const std::string path = dir_.path() + "/apply-" + std::to_string(step_) + "-" + std::to_string(f) + ".yaml";
      std::ofstream(path) << file;
      expected.push_back(values);
      Call c;
      c.what = "config apply";
      c.via = f == 0 ? Via::Agent : Via::Own;
      c.at = uniform(0, 0.5);
      c.timeout = 15;
      c.args = {"config", "apply", path};
      calls.push_back(std::move(c));
    }
    return calls;
  }

  // ---- invariants ----------------------------------------------------------------------

  // I1: every call that was not given up ended with a documented status and at most one final
  // result, and a stop is never refused.
  void check_calls(const std::vector<Call>& calls) {
    const bool moved =
        std::any_of(calls.begin(), calls.end(), [](const Call& c) { return c.what == "address change"; });
    for (const auto& c : calls) {
      if (c.gave_up) continue;
      // A call that found the PMU at the address it was just moved from is refused by the
      // service, not executed elsewhere (docs/safety.md H10): exit 2, "no such target".
      if (moved && c.what != "address change" && c.what != "engine stop" && c.status == 2) {
        const auto finals = final_lines(c.output);
        if (finals.size() == 1 && finals[0].rfind("REJECTED", 0) == 0 &&
            finals[0].find(" not seen on ") != std::string::npos)
          continue;
      }
      if (!c.status || *c.status > 1) {
        broken("I1", args_text(c) + " ended with " + (c.status ? "exit " + std::to_string(*c.status) : "a signal") +
                         "\n" + c.output);
        return;
      }
      if (c.what == "config apply") continue;  // one line per change and per restore
      const auto finals = final_lines(c.output);
      if (finals.size() != 1 || (*c.status == 0) != (finals[0].rfind("COMPLETED", 0) == 0)) {
        broken("I1", args_text(c) + ": exit " + std::to_string(*c.status) + " with final lines:\n" + c.output);
        return;
      }
      if (c.what == "engine stop" && *c.status != 0) {
        broken("I1", "an engine stop was not COMPLETED: " + c.output);
        return;
      }
    }
  }

  void check_state(const Observed& o) {
    if (o.config.is_null()) {
      broken("H12", "no pmu/config from the service:\n" + o.raw);
      return;
    }
    const auto outputs = o.config.value("outputs", 0);
    const auto streamed = o.config.value("packets_streamed", 0);
    const auto limit = o.config.value("upper_temperature_limit", 0.0);
    // I3: nothing here confirms an avionics cut.
    if (!(outputs & 1) || (o.status && !o.status->value("avionics_servo_on", true)))
      broken("I3", "the avionics/servo output is off:\n" + o.raw);
    // I4: nothing here confirms a T_U at or below the internal temperature.
    if (limit <= kInternalTemperature || (o.status && o.status->value("thermal_shutdown", false)))
      broken("I4", "upper_temperature_limit " + std::to_string(limit) + " with the unit at " +
                       std::to_string(kInternalTemperature) + " degC:\n" + o.raw);
    // I2: READY needs the temperatures (bit 3) and the status (bit 4) the rules read.
    const bool blind = !(streamed & 0x08) || !(streamed & 0x10);
    if (o.readiness && o.readiness->value("ready", false) && blind)
      broken("I2", "READY while packets_streamed is " + std::to_string(streamed) + ":\n" + o.raw);
    // I5: the engine here never fires, so any speed is a starter still cranking.
    if (o.status && o.status->value("generator_rpm", 0.0) != 0.0)
      broken("I5", "the starter still turns after every start and stop ended:\n" + o.raw);
    address_ = static_cast<int>(o.config.value("can_address", 1.0));
  }

  // I6: a given-up call's set never reached the unit after its caller's wait ended.
  void check_given_up(const std::vector<Call>& calls) {
    const std::string log = service_->log();
    for (const auto& c : calls) {
      if (c.what != "given-up set" || !c.gave_up) continue;
      const std::string& value = c.args.back();
      const double wait_end = c.wall_started + c.timeout;
      std::istringstream in(log);
      for (std::string line; std::getline(in, line);) {
        // "audit: command ID from SENDER: set_parameter avionics_voltage=18 to sim/1 -> COMPLETED"
        const auto at = line.find("set_parameter avionics_voltage=");
        if (line.find("audit: command") == std::string::npos || at == std::string::npos ||
            line.find("-> COMPLETED") == std::string::npos)
          continue;
        const double set =
            std::strtod(line.c_str() + at + std::string("set_parameter avionics_voltage=").size(), nullptr);
        if (std::abs(set - std::stod(value)) > 0.05) continue;
        const auto t = log_line_time(line);
        if (t && *t > wait_end + kSetToAudit)
          broken("I6", args_text(c) + ": its caller's wait ended at " + std::to_string(wait_end) +
                           ", the service completed it at " + std::to_string(*t) + ":\n" + line);
      }
    }
  }

  // I7: the settings two applies at once name hold, together, their starting values or one
  // file's values.
  void check_applies(const std::vector<std::string>& names, const Json& before, const std::vector<Json>& files,
                     const Observed& o) {
    auto same = [&](const Json& a, const Json& b) {
      for (const auto& n : names)
        if (std::abs(a.value(n, -1.0) - b.value(n, -1.0)) > 0.05) return false;
      return true;
    };
    if (same(o.config, before)) return;
    for (const auto& f : files)
      if (same(o.config, f)) return;
    broken("I7", "a mixed configuration: before " + before.dump() + ", files " + files[0].dump() + " and " +
                     files[1].dump() + ", now " + o.config.dump());
  }

  // The service killed as a crash: through the agent, no all-clear and no READY comes from it
  // (I2), then it is started again.
  void step_kill() {
    history_ += "  kill -9 pmu-service\n";
    service_->kill();
    for (const char* verb : {"alarms", "preflight"}) {
      const auto r = through_agent(std::string("--timeout 3 ") + verb);
      if (r.status == 0)
        broken("I2", std::string("[agent] pmuctl ") + verb + " exits 0 with its service killed:\n" + r.out);
    }
    service_->start();
    history_ += "  pmu-service started again\n";
    address_ = 1;
    if (!service_ready()) broken("H12", "the service did not come back after a restart");
  }

  std::uint64_t seed_ = 0;
  int seconds_ = kDefaultSeconds;
  std::mt19937_64 rng_;
  int domain_ = 0;
  pmu::test::TempDir dir_{"pmu-interleaving"};
  std::string socket_;
  std::unique_ptr<Service> service_;
  int step_ = 0;
  int address_ = 1;
  std::string history_;
  bool failed_ = false;
  std::vector<std::string> markers_;  // the values given-up calls set, each once
};

TEST_F(Interleavings, RandomOperatorsKeepEveryInvariantOfTheHazardLog) {
  service_->start();
  pmu::test::ChildOptions agent_options;
  agent_options.stdout_path = agent_options.stderr_path = dir_.path() + "/agent.log";
  // One worker: a call waits behind another, as on a ground station whose workers are busy.
  pmu::test::Child agent(
      {PMUCTL_PATH, "--domain", std::to_string(domain_), "agent", "--socket", socket_, "--workers", "1"},
      agent_options);
  ASSERT_TRUE(service_ready()) << service_->log();

  const auto end = Clock::now() + std::chrono::seconds(seconds_);
  int kinds[5] = {};
  while (Clock::now() < end && !failed_) {
    ++step_;
    const int kind = step_ % 9 == 0 ? 4 : integer(0, 3);
    ++kinds[kind];
    history_ += "step " + std::to_string(step_) + ":\n";
    if (kind == 4) {
      step_kill();
      continue;
    }
    std::vector<std::string> names;
    std::vector<Json> files;
    Json before;
    std::vector<Call> calls;
    if (kind == 0) calls = step_sets();
    if (kind == 1) calls = step_engine();
    if (kind == 2) calls = step_given_up();
    if (kind == 3) {
      before = observe().config;
      calls = step_applies(names, files);
    }
    if (failed_) break;
    run(calls);
    check_calls(calls);
    check_given_up(calls);
    const Observed o = observe();
    check_state(o);
    if (kind == 3 && !failed_) check_applies(names, before, files, o);
  }
  std::cout << "seed " << seed_ << ": " << step_ << " steps (sets " << kinds[0] << ", engine " << kinds[1]
            << ", given up " << kinds[2] << ", applies " << kinds[3] << ", restarts " << kinds[4] << ")" << std::endl;
  EXPECT_FALSE(failed_);
  EXPECT_GT(step_, 3) << "too few steps to interleave anything";
  EXPECT_TRUE(agent.running()) << read_text(dir_.path() + "/agent.log");
}

}  // namespace interleaving_test
