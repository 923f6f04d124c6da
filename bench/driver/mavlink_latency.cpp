#include "mavlink_latency.hpp"

#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>
#include <memory>
#include <optional>
#include <stdexcept>
#include <thread>

#include "child_process.hpp"
#include "fake_pmu.hpp"
#include "pacer.hpp"
#include "pmu/dds/dds_context.hpp"
#include "pmu/idl/telemetry.h"
#include "pmu/idl/telemetryPubSubTypes.h"
#include "pmu/idl/topics.hpp"
#include "pmu/mavlink/messages.hpp"
#include "pmu/mavlink/parser.hpp"
#include "pmu/transport/unique_fd.hpp"

namespace pmu::bench {
// A named namespace: the release preset's unity build puts this file beside benchmarks.cpp.
namespace mavlink_latency_parts {

using nlohmann::json;

// The first arrival of each frame number (steady_clock ns, 0 = not yet): a BATTERY_STATUS
// at 50 Hz repeats the newest sample until the next one comes, and only its first carrier
// is the frame's latency. Written by one thread, read after it has stopped or atomically.
class FirstArrivals {
 public:
  FirstArrivals() : t_(std::make_unique<std::atomic<std::int64_t>[]>(kSlots)) {}
  void note(std::uint16_t seq, std::int64_t ns) noexcept {
    std::int64_t none = 0;
    t_[seq].compare_exchange_strong(none, ns, std::memory_order_acq_rel);
  }
  std::int64_t at(std::uint16_t seq) const noexcept { return t_[seq].load(std::memory_order_acquire); }

 private:
  static constexpr std::size_t kSlots = 65536;
  std::unique_ptr<std::atomic<std::int64_t>[]> t_;
};

// pmu/voltages at a reader made as pmu-mavlink makes its own (the telemetry profile, the
// default transports): the arrival of each injected frame's sample. Called on Fast DDS's
// listener thread.
class VoltagesArrivals : public eprosima::fastdds::dds::DataReaderListener {
 public:
  void on_data_available(eprosima::fastdds::dds::DataReader* reader) override {
    pmu::v5::Voltages v;
    eprosima::fastdds::dds::SampleInfo info;
    while (reader->take_next_sample(&v, &info) == ReturnCode_t::RETCODE_OK) {
      const std::int64_t now = steady_ns();
      if (!info.valid_data || std::lround(v.avionics() * 10.0f) != kMarkerRaw) continue;  // the model's own
      arrivals.note(static_cast<std::uint16_t>(std::lround(v.battery_a() * 10.0f) * kSeqBase +
                                               std::lround(v.battery_b() * 10.0f)),
                    now);
    }
  }
  FirstArrivals arrivals;
};

// One bridge's UDP endpoint: BATTERY_STATUS id 10 (PMU 1 battery A) then id 11 (battery B),
// sent by pmu-mavlink back to back from one view of the PMU, give a frame's number back.
class BatteryStatusSink {
 public:
  BatteryStatusSink() : fd_(::socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC | SOCK_NONBLOCK, 0)) {
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    socklen_t len = sizeof a;
    if (!fd_ || ::bind(fd_.get(), reinterpret_cast<const sockaddr*>(&a), sizeof a) != 0 ||
        ::getsockname(fd_.get(), reinterpret_cast<sockaddr*>(&a), &len) != 0)
      throw std::runtime_error("cannot bind a UDP socket on 127.0.0.1");
    port_ = ntohs(a.sin_port);
  }
  int fd() const noexcept { return fd_.get(); }
  int port() const noexcept { return port_; }

  // Reads every datagram waiting, each timed as it is read.
  void drain() {
    std::uint8_t buf[2048];
    for (;;) {
      const ssize_t n = ::recv(fd_.get(), buf, sizeof buf, 0);
      if (n <= 0) return;
      const std::int64_t now = steady_ns();
      parser_.push(buf, static_cast<std::size_t>(n));
      while (const auto r = parser_.next()) {
        const auto* frame = std::get_if<pmu::mavlink::Frame>(&*r);
        if (!frame) continue;
        if (const auto m = pmu::mavlink::decode<pmu::mavlink::BatteryStatus>(*frame)) on_battery(*m, now);
      }
    }
  }
  const FirstArrivals& arrivals() const noexcept { return arrivals_; }
  // BATTERY_STATUS of battery 10 with a voltage: the bridge has the PMU ONLINE.
  bool heard_pmu() const noexcept { return heard_.load(); }

 private:
  void on_battery(const pmu::mavlink::BatteryStatus& m, std::int64_t now) {
    constexpr std::uint16_t kNotProvided = 65535;
    if (m.id == 10) {
      a_mv_ = m.voltages[0];
      if (m.voltages[0] != kNotProvided) heard_ = true;
      return;
    }
    if (m.id != 11 || !a_mv_) return;
    const std::uint16_t a = *a_mv_, b = m.voltages[0];
    a_mv_.reset();
    // Injected voltages are whole tenths of a volt (fake_pmu.hpp): 100 mV steps.
    if (a == kNotProvided || b == kNotProvided || a % 100 != 0 || b % 100 != 0) return;
    if (a / 100 >= kSeqBase || b / 100 >= kSeqBase) return;
    arrivals_.note(static_cast<std::uint16_t>(a / 100 * kSeqBase + b / 100), now);
  }

  transport::UniqueFd fd_;
  int port_ = 0;
  pmu::mavlink::Parser parser_;
  std::optional<std::uint16_t> a_mv_;
  FirstArrivals arrivals_;
  std::atomic<bool> heard_{false};
};

struct Quantiles {
  std::size_t count = 0;
  double p50 = 0, p95 = 0, p99 = 0;  // ms
};

// Nearest rank, as stats.hpp's percentiles().
Quantiles quantiles_ms(std::vector<std::int64_t> ns) {
  Quantiles q;
  q.count = ns.size();
  if (ns.empty()) return q;
  std::sort(ns.begin(), ns.end());
  const auto at = [&](double p) {
    auto rank = static_cast<std::size_t>(std::ceil(p * static_cast<double>(ns.size())));
    rank = std::clamp<std::size_t>(rank, 1, ns.size());
    return static_cast<double>(ns[rank - 1]) / 1e6;
  };
  q.p50 = at(0.50);
  q.p95 = at(0.95);
  q.p99 = at(0.99);
  return q;
}

json latency_row(const std::string& name, double value, std::optional<double> reference, const std::string& note) {
  json r{{"benchmark", name}, {"value", value}, {"unit", "ms"}, {"target", ""}, {"met", nullptr}};
  r["reference"] = reference ? json(*reference) : json(nullptr);
  r["reference_name"] = reference ? "the same frames' DDS samples" : "";
  r["ratio"] = (reference && *reference > 0) ? json(value / *reference) : json(nullptr);
  if (!note.empty()) r["note"] = note;
  return r;
}

void say(const std::string& what) { std::fprintf(stderr, "pmu_bench: %s\n", what.c_str()); }

std::string bridge_failure(const std::string& what, const std::string& log) { return what + ": " + tail(log); }

}  // namespace mavlink_latency_parts

Rows mavlink_latency_rows(const Settings& s, const MavlinkLatencyOptions& o, int domain) {
  using namespace mavlink_latency_parts;
  using std::chrono::seconds;
  // The listener outlives the context whose reader calls it.
  VoltagesArrivals dds_side;
  dds::DdsContext participant(domain, s.qos_file, "pmu-bench", {}, dds::Transport::Default);
  participant.reader(
      participant.topic(topics::kVoltages, eprosima::fastdds::dds::TypeSupport(new pmu::v5::VoltagesPubSubType())),
      qos_profiles::kTelemetry, &dds_side);
  say("MAVLink latency: pmu-service on the fake PMU, default transports, domain " + std::to_string(domain));
  ServiceRun svc(s, domain, dds::Transport::Default, "service-mavlink");
  if (!svc.wait_ready(seconds(20))) throw std::runtime_error("pmu-service did not start: " + svc.log_tail());

  BatteryStatusSink fast, slow;
  std::atomic<bool> stop{false};
  std::thread receiver([&] {
    pollfd p[2] = {{fast.fd(), POLLIN, 0}, {slow.fd(), POLLIN, 0}};
    while (!stop.load()) {
      if (::poll(p, 2, 50) <= 0) continue;
      if (p[0].revents & POLLIN) fast.drain();
      if (p[1].revents & POLLIN) slow.drain();
    }
  });
  struct JoinAtExit {
    std::atomic<bool>& stop;
    std::thread& t;
    ~JoinAtExit() {
      stop = true;
      if (t.joinable()) t.join();
    }
  } join_receiver{stop, receiver};

  const auto bridge_args = [&](const BatteryStatusSink& sink) {
    return std::vector<std::string>{o.bridge_exe,           "--udp",      "127.0.0.1:" + std::to_string(sink.port()),
                                    "--system-id",          "1",          "--domain",
                                    std::to_string(domain), "--qos-file", s.qos_file};
  };
  auto fast_args = bridge_args(fast);
  fast_args.insert(fast_args.end(), {"--rate", "battery_status=50"});
  const std::string fast_log = s.workdir + "/bridge-50hz.log", slow_log = s.workdir + "/bridge-default.log";
  ChildProcess fast_bridge(fast_args, {}, {}, fast_log);
  ChildProcess slow_bridge(bridge_args(slow), {}, {}, slow_log);
  // Both bridges see PMU 1 ONLINE (a voltage in battery 10) before the first numbered frame.
  const auto until = steady_ns() + 30'000'000'000LL;
  while (!(fast.heard_pmu() && slow.heard_pmu())) {
    if (!fast_bridge.running()) throw std::runtime_error(bridge_failure("pmu-mavlink (50 Hz) exited", fast_log));
    if (!slow_bridge.running()) throw std::runtime_error(bridge_failure("pmu-mavlink (default) exited", slow_log));
    if (steady_ns() > until)
      throw std::runtime_error(bridge_failure("no BATTERY_STATUS with PMU 1's voltage within 30 s", fast_log));
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }

  say("injecting " + std::to_string(o.frame_rate) + " numbered frames/s for " + std::to_string(o.seconds) + " s");
  auto times = std::make_unique<WriteTimes>();
  const Injection inj = svc.pmu().inject(
      o.frame_rate, std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::duration<double>(o.seconds)),
      *times);
  std::this_thread::sleep_for(std::chrono::milliseconds(500));  // the last frame's messages in flight
  stop = true;
  receiver.join();
  svc.check_alive();
  if (!fast_bridge.running() || !slow_bridge.running())
    throw std::runtime_error(bridge_failure("a pmu-mavlink exited during the run", fast_log) + " / " + tail(slow_log));

  std::vector<std::int64_t> dds_ns, fast_ns, slow_ns;
  const auto frames = std::min<std::uint64_t>(inj.frames, kSeqSpace);
  for (std::uint64_t i = 0; i < frames; ++i) {
    const auto seq = static_cast<std::uint16_t>(i);
    const std::int64_t written = times->take(seq);
    if (written == 0) continue;
    if (const auto t = dds_side.arrivals.at(seq)) dds_ns.push_back(t - written);
    if (const auto t = fast.arrivals().at(seq)) fast_ns.push_back(t - written);
    if (const auto t = slow.arrivals().at(seq)) slow_ns.push_back(t - written);
  }
  if (dds_ns.empty() || fast_ns.empty())
    throw std::runtime_error("no injected frame reached " + std::string(dds_ns.empty() ? "the DDS reader" : "MAVLink"));
  const Quantiles d = quantiles_ms(dds_ns), f = quantiles_ms(fast_ns), w = quantiles_ms(slow_ns);

  char counts[400];
  std::snprintf(counts, sizeof counts,
                "%llu frames written at %.1f/s; samples at the DDS reader: %zu; frames carried by a BATTERY_STATUS "
                "pair (ids 10, 11): %zu at 50 Hz, %zu at the default 0.5 Hz (each message carries the newest "
                "sample, so most frames are never sent at 0.5 Hz)",
                static_cast<unsigned long long>(inj.frames), inj.rate(), d.count, f.count, w.count);
  Rows rows;
  rows.push_back(json{{"section", "CAN frame -> MAVLink, beside the same frame's DDS sample"}});
  const std::string dds_name = "CAN frame -> pmu/voltages sample at a DDS reader, ";
  rows.push_back(latency_row(dds_name + "p50", d.p50, std::nullopt, counts));
  rows.push_back(latency_row(dds_name + "p95", d.p95, std::nullopt, ""));
  rows.push_back(latency_row(dds_name + "p99", d.p99, std::nullopt, ""));
  const std::string fast_name = "CAN frame -> first BATTERY_STATUS carrying it, battery_status 50 Hz, ";
  rows.push_back(latency_row(fast_name + "p50", f.p50, d.p50,
                             "pmu-mavlink takes DDS samples and sends what is due once per pass of its 20 ms loop"));
  rows.push_back(latency_row(fast_name + "p95", f.p95, d.p95, ""));
  rows.push_back(latency_row(fast_name + "p99", f.p99, d.p99, ""));
  if (w.count > 0) {
    const std::string slow_name = "CAN frame -> first BATTERY_STATUS carrying it, default 0.5 Hz, ";
    rows.push_back(latency_row(slow_name + "p50", w.p50, d.p50,
                               "only the frames a message carries: the age of the newest sample when the message "
                               "goes, at most one frame interval plus the 50 Hz path"));
    rows.push_back(latency_row(slow_name + "p95", w.p95, d.p95, ""));
    rows.push_back(latency_row(slow_name + "p99", w.p99, d.p99, ""));
  }
  return rows;
}

}  // namespace pmu::bench
