// pmu_bench: the service benchmarks (bench/run.sh runs them with the rest), and the bare
// Fast DDS peers they are compared with.
//   pmu_bench run --service PATH [--quick] [--domain-base N]   result rows on stdout
//   pmu_bench mavlink-latency --service PATH --bridge PATH [--seconds N]   CAN frame -> MAVLink rows
//   pmu_bench peer-writer|peer-echo|peer-pong|peer-telemetry|peer-reader ...   started by `run`
// PMU_BENCH_DEBUG=1 lists the numbers of injected frames whose samples never arrived.

#include <unistd.h>

#include <CLI/CLI.hpp>
#include <cstdio>
#include <filesystem>
#include <set>
#include <string>

#include "benchmarks.hpp"
#include "domain_pick.hpp"
#include "mavlink_latency.hpp"
#include "peers.hpp"
#include "scale_peers.hpp"
#include "pmu/dds/dds_context.hpp"

int main(int argc, char** argv) {
  using namespace pmu::bench;
  CLI::App app{"pmu_bench: pmu-service benchmarks against bare Fast DDS"};
  app.require_subcommand(1);
  Settings s;
  s.qos_file = pmu::dds::default_qos_file();
  s.domain_base = -1;  // chosen below
  auto* run = app.add_subcommand("run", "run every service benchmark, print result rows (JSON lines)");
  run->add_option("--service", s.service_exe, "pmu-service binary")->required()->check(CLI::ExistingFile);
  run->add_flag("--quick", s.quick, "one short pass (smoke test)");
  run->add_option("--domain-base", s.domain_base,
                  "first of four DDS domains used (default: four of 150..229 with no shared-memory port in /dev/shm)")
      ->check(CLI::Range(0, 228));
  run->add_option("--qos", s.qos_file, "QoS profiles (deploy/qos.xml)");
  run->add_option("--latency-seconds", s.latency_seconds, "length of each 7,634 frames/s run (default 10, quick 1)");
  run->add_option("--startups", s.startups, "starts of pmu-service for the start-up rows (default 5, quick 1)")
      ->check(CLI::Range(1, 1000));
  run->add_flag("--startup-only", s.startup_only, "measure start-up alone (each start is printed on stderr)");
  run->add_flag("--scale-only", s.scale_only, "only the rows of how CPU and memory grow with PMUs and subscribers");
  run->add_flag("--latency-only", s.latency_only,
                "only the latency and CPU rows over SHM, at 7,634 frames/s and at a realistic rate (to profile)");
  run->add_option("--realistic-seconds", s.realistic_seconds,
                  "length of each realistic-rate run (one PMU, 5 packets every 0.1 s; default 60, quick 2)")
      ->check(CLI::Range(1.0, 3600.0));

  MavlinkLatencyOptions mav;
  auto* mavlink = app.add_subcommand("mavlink-latency",
                                     "CAN frame -> BATTERY_STATUS at pmu-mavlink's UDP peer, beside its DDS sample");
  mavlink->add_option("--service", s.service_exe, "pmu-service binary")->required()->check(CLI::ExistingFile);
  mavlink->add_option("--bridge", mav.bridge_exe, "pmu-mavlink binary")->required()->check(CLI::ExistingFile);
  mavlink->add_option("--seconds", mav.seconds, "how long numbered frames are written (default 60)")
      ->check(CLI::Range(1.0, 3600.0));
  mavlink->add_option("--qos", s.qos_file, "QoS profiles (deploy/qos.xml)");

  PeerOptions p;
  std::string transport = "default";
  auto* writer = app.add_subcommand("peer-writer", "bare writer of timed pmu/voltages samples");
  auto* echo = app.add_subcommand("peer-echo", "bare request/reply on pmu/command");
  auto* pong = app.add_subcommand("peer-pong", "echo can_frame records on fd 3");
  auto* telemetry = app.add_subcommand("peer-telemetry", "bare writer of every telemetry topic for N units");
  auto* reader = app.add_subcommand("peer-reader", "subscriber to every telemetry topic, counting samples");
  telemetry->add_option("--units", p.units)->check(CLI::Range(1, 1000));
  telemetry->add_option("--period", p.period)->check(CLI::Range(0.01, 100.0));
  for (auto* sub : {writer, echo, telemetry, reader}) {
    sub->add_option("--domain", p.domain)->required();
    sub->add_option("--qos", p.qos_file)->required();
    sub->add_option("--transport", transport)->check(CLI::IsMember({"default", "udp", "shm"}));
  }
  writer->add_option("--rate", p.rate);
  writer->add_option("--seconds", p.seconds);
  CLI11_PARSE(app, argc, argv);
  p.transport = transport == "udp"   ? pmu::dds::Transport::UdpOnly
                : transport == "shm" ? pmu::dds::Transport::ShmOnly
                                     : pmu::dds::Transport::Default;

  try {
    if (*writer) return peer_writer(p);
    if (*echo) return peer_echo(p);
    if (*pong) return peer_pong();
    if (*telemetry) return peer_telemetry(p);
    if (*reader) return peer_reader(p);
    const std::set<int> taken = domains_with_shm_ports("/dev/shm");
    if (s.domain_base < 0) {
      // The pid spreads runs at once over the range; each skips the domains the others hold.
      s.domain_base = free_domain_base(static_cast<unsigned>(::getpid()), taken);
      if (s.domain_base < 0)
        throw std::runtime_error("every four domains of " + std::to_string(kDomainFirst) + ".." +
                                 std::to_string(kDomainLast) +
                                 " have a Fast DDS shared-memory port in /dev/shm (fastrtps_port*): other runs, or "
                                 "ports left by killed processes; name free ones with --domain-base");
    } else {
      for (int d = s.domain_base; d < s.domain_base + kDomainsPerRun; ++d)
        if (taken.count(d))
          std::fprintf(stderr,
                       "pmu_bench: domain %d has a Fast DDS shared-memory port in /dev/shm (port %d..%d): another "
                       "run, or one left by a killed process, which can keep SHM participants from matching\n",
                       d, first_port(d), first_port(d + 1) - 1);
    }
    std::fprintf(stderr, "pmu_bench: DDS domains %d..%d\n", s.domain_base, s.domain_base + kDomainsPerRun - 1);
    s.self_exe = std::filesystem::read_symlink("/proc/self/exe").string();
    s.service_exe = std::filesystem::absolute(s.service_exe).string();
    // The service reads it from a config file in the work folder: a relative path would not hold.
    s.qos_file = std::filesystem::absolute(s.qos_file).string();
    char tmpl[] = "/tmp/pmu-bench-XXXXXX";
    if (!::mkdtemp(tmpl)) throw std::runtime_error("mkdtemp failed");
    s.workdir = tmpl;
    const Rows rows = *mavlink ? mavlink_latency_rows(s, mav, s.domain_base) : run_all(s);
    for (const auto& r : rows) std::printf("%s\n", r.dump().c_str());
    std::filesystem::remove_all(s.workdir);
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "pmu_bench: %s\n", e.what());
    return 1;
  }
}
