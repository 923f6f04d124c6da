// standby_consumer: the consumer of the hot-standby suite (tests/standby/README.md).
//
// One DDS participant that reads the five telemetry topics, as any consumer of the contract
// does (the `telemetry` profile, the default partition), and prints one line per sample with
// the writer it came from, so that the suite can tell the two instances' streams apart
// without trusting either instance's own account of its role:
//   sample T TOPIC BUS ADDRESS WRITER
// T is CLOCK_BOOTTIME in seconds at the sample's arrival (the clock of /proc/uptime, which
// the suite's shell reads too), TOPIC the topic without `pmu/`, WRITER the writer's GUID
// (SampleInfo::sample_identity, as Fast DDS prints it). Each change of a reader's matched writers is a line
//   matched T TOPIC CURRENT CHANGE
// and `ready T` says that every reader exists. Lines are flushed one by one.
//
//   standby_consumer [--domain N] [--qos-file F] [--transport udp|default]
// Ends on SIGTERM or SIGINT with status 0; status 2 when DDS cannot be set up.

#include <signal.h>
#include <time.h>

#include <CLI/CLI.hpp>
#include <cstdio>
#include <fastdds/dds/core/status/SubscriptionMatchedStatus.hpp>
#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <memory>
#include <mutex>
#include <sstream>
#include <string>
#include <vector>

#include "pmu/dds/dds_context.hpp"
#include "pmu/idl/guarded_type.hpp"
#include "pmu/idl/telemetry.h"
#include "pmu/idl/telemetryPubSubTypes.h"
#include "pmu/idl/topics.hpp"

namespace {

using namespace eprosima::fastdds::dds;

double standby_boottime() {
  timespec ts{};
  ::clock_gettime(CLOCK_BOOTTIME, &ts);
  return static_cast<double>(ts.tv_sec) + static_cast<double>(ts.tv_nsec) / 1e9;
}

// The listener threads of every reader print; one line must never cut into another.
std::mutex g_print;

// The writer's GUID as Fast DDS prints it (prefix|entity id): one word, no spaces.
std::string writer_text(const SampleInfo& info) {
  std::ostringstream who;
  who << info.sample_identity.writer_guid();
  return who.str();
}

// What every topic's listener does; SampleListener<T> reads the generated sample type T.
class TopicListener : public DataReaderListener {
 public:
  explicit TopicListener(std::string topic) : topic_(std::move(topic)) {}
  void on_subscription_matched(DataReader*, const SubscriptionMatchedStatus& s) override {
    std::lock_guard<std::mutex> lock(g_print);
    std::printf("matched %.3f %s %d %d\n", standby_boottime(), topic_.c_str(), s.current_count, s.current_count_change);
    std::fflush(stdout);
  }

 protected:
  void print_sample(const std::string& bus, unsigned address, const SampleInfo& info) const {
    const double t = standby_boottime();
    std::lock_guard<std::mutex> lock(g_print);
    std::printf("sample %.3f %s %s %u %s\n", t, topic_.c_str(), bus.empty() ? "-" : bus.c_str(), address,
                writer_text(info).c_str());
    std::fflush(stdout);
  }

 private:
  std::string topic_;
};

template <typename T>
class SampleListener final : public TopicListener {
 public:
  using TopicListener::TopicListener;
  void on_data_available(DataReader* reader) override {
    T sample;
    SampleInfo info;
    while (reader->take_next_sample(&sample, &info) == ReturnCode_t::RETCODE_OK) {
      if (info.valid_data) print_sample(sample.bus().to_string(), sample.address(), info);
    }
  }
};

volatile sig_atomic_t g_stop = 0;
void on_stop_signal(int) { g_stop = 1; }

class Consumer {
 public:
  Consumer(int domain, const std::string& qos_file, pmu::dds::Transport transport)
      : dds_(domain, qos_file, "standby_consumer", {}, transport) {
    add<pmu::v5::Voltages, pmu::v5::VoltagesPubSubType>(pmu::topics::kVoltages);
    add<pmu::v5::Currents, pmu::v5::CurrentsPubSubType>(pmu::topics::kCurrents);
    add<pmu::v5::BatteryEnergy, pmu::v5::BatteryEnergyPubSubType>(pmu::topics::kBatteryEnergy);
    add<pmu::v5::Temperatures, pmu::v5::TemperaturesPubSubType>(pmu::topics::kTemperatures);
    add<pmu::v5::Status, pmu::v5::StatusPubSubType>(pmu::topics::kStatus);
  }
  ~Consumer() {
    // The readers die with dds_; no callback may reach a listener destroyed before them.
    for (auto* r : readers_) r->set_listener(nullptr);
  }
  Consumer(const Consumer&) = delete;
  Consumer& operator=(const Consumer&) = delete;

 private:
  template <typename T, typename PubSub>
  void add(const char* topic) {
    const std::string name(topic);
    listeners_.push_back(std::make_unique<SampleListener<T>>(name.substr(name.find('/') + 1)));
    readers_.push_back(&dds_.reader(dds_.topic(topic, TypeSupport(new pmu::idl::Guarded<PubSub>())),
                                    pmu::qos_profiles::kTelemetry, listeners_.back().get()));
  }

  // Declared first: destroyed last, after dds_ has deleted the readers that call them.
  std::vector<std::unique_ptr<TopicListener>> listeners_;
  pmu::dds::DdsContext dds_;
  std::vector<DataReader*> readers_;
};

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"standby_consumer: the hot-standby suite's consumer (tests/standby/README.md)"};
  int domain = 0;
  std::string qos_file, transport = "udp";
  app.add_option("--domain", domain)->check(CLI::Range(0, 232));
  app.add_option("--qos-file", qos_file, "QoS profiles (default: $PMU_QOS_FILE)");
  // udp: the consumer is another host than either instance; only what crosses the LAN counts.
  app.add_option("--transport", transport)->check(CLI::IsMember({"udp", "default"}))->capture_default_str();
  CLI11_PARSE(app, argc, argv);

  struct sigaction sa {};
  sa.sa_handler = on_stop_signal;
  ::sigaction(SIGTERM, &sa, nullptr);
  ::sigaction(SIGINT, &sa, nullptr);
  try {
    Consumer consumer(domain, qos_file,
                      transport == "udp" ? pmu::dds::Transport::UdpOnly : pmu::dds::Transport::Default);
    {
      std::lock_guard<std::mutex> lock(g_print);
      std::printf("ready %.3f\n", standby_boottime());
      std::fflush(stdout);
    }
    const timespec tick{0, 100'000'000};
    while (g_stop == 0) ::nanosleep(&tick, nullptr);
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "standby_consumer: %s\n", e.what());
    return 2;
  }
}
