#include "scale_bench.hpp"

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <memory>
#include <thread>

#include "proc_stats.hpp"
#include "telemetry_readers.hpp"

namespace pmu::bench {
namespace {

using nlohmann::json;
using std::chrono::seconds;

constexpr dds::Transport kShm = dds::Transport::ShmOnly;  // as the main rows (benchmarks.cpp says why)
constexpr std::uint32_t kTenHertz = 1;                    // PP in tenths of a second
constexpr int kSubscriberUnits = 10;                      // PMUs while subscribers are added
constexpr int kMaxUnits = 256;                            // instance limit of the bench readers

void progress(const std::string& what) { std::fprintf(stderr, "pmu_bench: %s\n", what.c_str()); }
void sleep_s(double s) { std::this_thread::sleep_for(std::chrono::duration<double>(s)); }

struct Timing {
  double settle, window;
};
Timing timing(const Settings& s) { return s.quick ? Timing{0.5, 1.0} : Timing{2.0, 10.0}; }

// CPU and memory of one process over a window, and what the driver's own readers got.
struct Cost {
  double cpu_percent = 0, rss_mib = 0;
  double samples_per_s = 0;  // at the driver's readers (0 when they are not used)
  std::size_t units = 0;     // distinct units those readers saw
};

Cost measure(pid_t pid, const Timing& t, const TelemetryReaders* readers) {
  sleep_s(t.settle);
  const auto a = proc_sample(pid);
  const auto r0 = readers ? readers->received() : 0;
  const auto t0 = std::chrono::steady_clock::now();
  sleep_s(t.window);
  const auto b = proc_sample(pid);
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  Cost c;
  c.cpu_percent = cpu_percent(a, b, wall);
  c.rss_mib = b.rss_mib;
  if (readers) {
    c.samples_per_s = static_cast<double>(readers->received() - r0) / wall;
    c.units = readers->units_seen();
  }
  return c;
}

std::vector<std::string> peer_args(const Settings& s, const char* what, int domain) {
  return {s.self_exe, what,       "--domain",    std::to_string(domain),
          "--qos",    s.qos_file, "--transport", transport_name(kShm)};
}

std::unique_ptr<ChildProcess> telemetry_peer(const Settings& s, int domain, int units, const std::string& tag) {
  auto args = peer_args(s, "peer-telemetry", domain);
  args.insert(args.end(), {"--units", std::to_string(units), "--period", "0.1"});
  return std::make_unique<ChildProcess>(args, std::vector<std::string>{}, transport::UniqueFd{},
                                        s.workdir + "/" + tag + ".log");
}

// Samples each subscriber process counted (it prints them when stopped).
std::vector<std::uint64_t> stop_readers(std::vector<std::unique_ptr<ChildProcess>>& readers,
                                        const std::vector<std::string>& logs) {
  std::vector<std::uint64_t> counts;
  for (std::size_t i = 0; i < readers.size(); ++i) {
    readers[i]->stop();
    std::ifstream in(logs[i]);
    unsigned long long n = 0;
    for (std::string line; std::getline(in, line);)
      if (std::sscanf(line.c_str(), "peer-reader: %llu samples", &n) == 1) break;
    counts.push_back(n);
  }
  readers.clear();
  return counts;
}

json row(const std::string& name, double value, const std::string& unit, double reference,
         const std::string& reference_name, const std::string& note) {
  return json{{"benchmark", name},
              {"value", value},
              {"unit", unit},
              {"reference", reference},
              {"reference_name", reference_name},
              {"ratio", reference > 0 ? json(value / reference) : json(nullptr)},
              {"target", ""},
              {"met", nullptr},
              {"note", note}};
}

void units_rows(const Settings& s, Rows& rows, int domain, int ref_domain, int units) {
  const Timing t = timing(s);
  const double expected = 50.0 * units;  // five packets at 10 Hz
  const std::string tag = std::to_string(units);
  progress("scale: " + tag + " PMU(s) at 10 Hz");
  Cost svc;
  {
    dds::DdsContext dds(domain, s.qos_file, "pmu-bench-scale", {}, kShm);
    TelemetryReaders readers(dds, kMaxUnits);
    ServiceRun run(s, domain, kShm, "service-scale-" + tag, FakePmuLoad{static_cast<std::uint16_t>(units), kTenHertz});
    if (!run.wait_ready(seconds(20))) throw std::runtime_error("pmu-service with " + tag + " PMUs did not start");
    // The note says how many came: with Fast DDS's default of 10 instances per writer, 10.
    (void)readers.wait_units(static_cast<std::size_t>(units), seconds(s.quick ? 5 : 30));
    svc = measure(run.pid(), t, &readers);
    run.check_alive();
  }
  progress("scale: bare writer, " + tag + " unit(s) at 10 Hz");
  Cost ref;
  {
    dds::DdsContext dds(ref_domain, s.qos_file, "pmu-bench-scale-ref", {}, kShm);
    TelemetryReaders readers(dds, kMaxUnits);
    auto peer = telemetry_peer(s, ref_domain, units, "peer-telemetry-" + tag);
    if (!readers.wait_units(static_cast<std::size_t>(units), seconds(20)))
      throw std::runtime_error("peer-telemetry: " + std::to_string(readers.units_seen()) + " of " + tag +
                               " units arrived: " + tail(s.workdir + "/peer-telemetry-" + tag + ".log"));
    ref = measure(peer->pid(), t, &readers);
  }
  const std::string what = tag + (units == 1 ? " PMU" : " PMUs") + " streaming 5 packets at 10 Hz";
  const std::string ref_name = "bare writer, " + std::to_string(50 * units) + " samples/s, same 8 writers";
  char note[256];
  std::snprintf(note, sizeof note,
                "one reader of the 5 topics in the driver, SHM; it received %.0f samples/s from %zu of the units "
                "(expected %.0f/s); from the bare writer %.0f samples/s",
                svc.samples_per_s, svc.units, expected, ref.samples_per_s);
  rows.push_back(row("scale: CPU, " + what, svc.cpu_percent, "%", ref.cpu_percent, ref_name, note));
  rows.push_back(row("scale: RSS, " + what, svc.rss_mib, "MiB", ref.rss_mib, ref_name, ""));
}

void subscriber_rows(const Settings& s, Rows& rows, int domain, int ref_domain, int subscribers) {
  const Timing t = timing(s);
  const std::string tag = std::to_string(subscribers);
  const auto start_readers = [&](int d, const std::string& who, std::vector<std::string>& logs) {
    std::vector<std::unique_ptr<ChildProcess>> readers;
    for (int i = 0; i < subscribers; ++i) {
      logs.push_back(s.workdir + "/peer-reader-" + who + "-" + std::to_string(i) + ".log");
      readers.push_back(std::make_unique<ChildProcess>(peer_args(s, "peer-reader", d), std::vector<std::string>{},
                                                       transport::UniqueFd{}, logs.back()));
    }
    return readers;
  };
  // Subscribers start, discover the writer and begin receiving before the window opens.
  const Timing with_discovery{t.settle + (s.quick ? 1.0 : 2.0), t.window};
  progress("scale: " + tag + " subscriber(s)");
  Cost svc;
  std::vector<std::uint64_t> svc_counts;
  {
    ServiceRun run(s, domain, kShm, "service-subs-" + tag,
                   FakePmuLoad{static_cast<std::uint16_t>(kSubscriberUnits), kTenHertz});
    if (!run.wait_ready(seconds(20))) throw std::runtime_error("pmu-service did not start");
    std::vector<std::string> logs;
    auto readers = start_readers(domain, "svc", logs);
    svc = measure(run.pid(), with_discovery, nullptr);
    run.check_alive();
    svc_counts = stop_readers(readers, logs);
  }
  progress("scale: bare writer, " + tag + " subscriber(s)");
  Cost ref;
  std::vector<std::uint64_t> ref_counts;
  {
    auto peer = telemetry_peer(s, ref_domain, kSubscriberUnits, "peer-telemetry-subs-" + tag);
    std::vector<std::string> logs;
    auto readers = start_readers(ref_domain, "ref", logs);
    ref = measure(peer->pid(), with_discovery, nullptr);
    ref_counts = stop_readers(readers, logs);
  }
  const auto least = [](const std::vector<std::uint64_t>& v) {
    return static_cast<double>(v.empty() ? 0 : *std::min_element(v.begin(), v.end()));
  };
  const std::string what = tag + (subscribers == 1 ? " subscriber process" : " subscriber processes") + ", " +
                           std::to_string(kSubscriberUnits) + " PMUs at 10 Hz";
  const std::string ref_name = "bare writer, 500 samples/s, same subscribers";
  char note[256];
  std::snprintf(note, sizeof note,
                "each subscriber: a participant with the 5 telemetry readers (pmu_bench peer-reader), SHM; the one "
                "that received least got %.0f samples from the service and %.0f from the bare writer in the same time",
                least(svc_counts), least(ref_counts));
  rows.push_back(row("scale: CPU, " + what, svc.cpu_percent, "%", ref.cpu_percent, ref_name, note));
  rows.push_back(row("scale: RSS, " + what, svc.rss_mib, "MiB", ref.rss_mib, ref_name, ""));
}

}  // namespace

void scale_rows(const Settings& s, Rows& rows, int domain, int ref_domain) {
  rows.push_back(json{{"section", "How cost grows (pmu-service vs a bare Fast DDS writer, same run)"}});
  for (int units : {1, 10, 100}) units_rows(s, rows, domain, ref_domain, units);
  for (int subscribers : {1, 4, 16}) subscriber_rows(s, rows, domain, ref_domain, subscribers);
}

}  // namespace pmu::bench
