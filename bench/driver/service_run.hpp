#pragma once
// One pmu-service under test: its config file, the socketpair whose far end is the fake
// PMU, and a NOTIFY_SOCKET that receives its READY=1, as systemd's would.

#include <chrono>
#include <memory>
#include <optional>
#include <string>

#include "child_process.hpp"
#include "fake_pmu.hpp"
#include "pmu/dds_settings/transport_choice.hpp"

namespace pmu::bench {

struct Settings {
  std::string service_exe;  // pmu-service
  std::string self_exe;     // this binary, for the peer processes
  std::string qos_file;
  std::string workdir;  // config, logs, sockets
  bool quick = false;   // one short pass of everything (the test command's smoke run)
  int domain_base = 0;
  double latency_seconds = 0;    // > 0: length of each 7,634 frames/s run (e.g. for profiling)
  int startups = 0;              // > 0: how many starts the start-up rows take the median of
  bool startup_only = false;     // the start-up rows alone (to study start-up)
  bool scale_only = false;       // the scale rows alone (scale_bench.hpp)
  bool latency_only = false;     // the latency rows over SHM alone, saturated and realistic (to profile)
  double realistic_seconds = 0;  // > 0: length of the realistic-rate runs (default 60, quick 2)
};

// The config file's name of a transport: default, udp, shm.
const char* transport_name(dds::Transport t) noexcept;

class ServiceRun {
 public:
  // Writes the config, starts pmu-service with `--bus fd:3` and the fake PMU(s): one PMU
  // streaming once a second unless `load` says otherwise. Throws std::runtime_error when
  // it cannot.
  ServiceRun(const Settings& s, int domain, dds::Transport transport, const std::string& tag, FakePmuLoad load = {});
  ~ServiceRun();

  pid_t pid() const noexcept { return process_->pid(); }
  SteadyTime spawned_at() const noexcept { return process_->spawned_at(); }
  FakePmu& pmu() noexcept { return *pmu_; }
  // steady_clock ns at which READY=1 arrived on the notify socket; nullopt after `timeout`.
  // Once READY=1 is read, the socket is closed. Called once.
  std::optional<std::int64_t> wait_ready(std::chrono::milliseconds timeout);
  // Throws with the service log's tail when the service has exited.
  void check_alive();
  // The last lines of the service's log (its stdout and stderr).
  std::string log_tail() const;
  int stop() { return process_->stop(); }

 private:
  std::string log_;
  std::string notify_path_;
  transport::UniqueFd notify_;
  std::unique_ptr<FakePmu> pmu_;
  std::unique_ptr<ChildProcess> process_;
};

}  // namespace pmu::bench
