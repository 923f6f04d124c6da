#include "pmuctl/record_verb.hpp"

#include <pthread.h>
#include <unistd.h>

#include <csignal>
#include <cstdio>
#include <ctime>
#include <algorithm>
#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <memory>
#include <mutex>

#include "pmu/idl/canopenPubSubTypes.h"
#include "pmu/idl/commandPubSubTypes.h"
#include "pmu/idl/statePubSubTypes.h"
#include "pmu/idl/telemetryPubSubTypes.h"
#include "pmu/service/dds_context.hpp"
#include "pmuctl/mcap_recording.hpp"
#include "pmuctl/raw_sample_type.hpp"

namespace pmu::tools {
namespace {

using namespace eprosima::fastdds::dds;

TypeSupport raw_type(const std::string& type_name) {
  if (type_name == "pmu::Voltages") return TypeSupport(new RawSampleType<pmu::VoltagesPubSubType>());
  if (type_name == "pmu::Currents") return TypeSupport(new RawSampleType<pmu::CurrentsPubSubType>());
  if (type_name == "pmu::BatteryEnergy") return TypeSupport(new RawSampleType<pmu::BatteryEnergyPubSubType>());
  if (type_name == "pmu::Temperatures") return TypeSupport(new RawSampleType<pmu::TemperaturesPubSubType>());
  if (type_name == "pmu::Status") return TypeSupport(new RawSampleType<pmu::StatusPubSubType>());
  if (type_name == "pmu::Config") return TypeSupport(new RawSampleType<pmu::ConfigPubSubType>());
  if (type_name == "pmu::DeviceInfo") return TypeSupport(new RawSampleType<pmu::DeviceInfoPubSubType>());
  if (type_name == "pmu::Health") return TypeSupport(new RawSampleType<pmu::HealthPubSubType>());
  if (type_name == "pmu::Battery") return TypeSupport(new RawSampleType<pmu::BatteryPubSubType>());
  if (type_name == "pmu::BatteryCells") return TypeSupport(new RawSampleType<pmu::BatteryCellsPubSubType>());
  if (type_name == "pmu::Mppt") return TypeSupport(new RawSampleType<pmu::MpptPubSubType>());
  if (type_name == "pmu::Command") return TypeSupport(new RawSampleType<pmu::CommandPubSubType>());
  return TypeSupport(new RawSampleType<pmu::CommandReplyPubSubType>());
}

// The recording, shared by the readers' listeners (Fast DDS threads) and the main thread.
struct Shared {
  std::mutex mutex;
  McapRecording rec;
  bool closed = false;
};

class TopicListener final : public DataReaderListener {
 public:
  TopicListener(Shared& shared, std::size_t topic) : shared_(shared), topic_(topic) {}
  void on_data_available(DataReader* reader) override {
    RawSample sample;
    SampleInfo info;
    while (reader->take_next_sample(&sample, &info) == ReturnCode_t::RETCODE_OK) {
      if (!info.valid_data) continue;
      const auto& t = info.source_timestamp;
      const std::uint64_t ns = static_cast<std::uint64_t>(t.seconds()) * std::uint64_t{1000000000} + t.nanosec();
      std::lock_guard<std::mutex> lock(shared_.mutex);
      if (shared_.closed || shared_.rec.failed()) return;
      shared_.rec.write(topic_, ns, sample.bytes.data(), sample.bytes.size());
    }
  }

 private:
  Shared& shared_;
  std::size_t topic_;
};

}  // namespace

int run_record(const GlobalOptions& o, const std::string& path, const std::vector<std::string>& names) {
  if (!o.bus.empty() || o.address) {
    // Selecting would mean reading the bytes pmuctl forwards unread; a vehicle is a partition.
    std::fprintf(stderr, "pmuctl record: records every device of the vehicle(s) it reads; --bus and --address do "
                         "not apply (--vehicle does)\n");
    return 2;
  }
  std::vector<const RecordedTopic*> topics;
  for (const auto& n : names) {
    const auto* t = find_recorded_topic(n);
    if (!t) {
      std::string known;
      for (const auto& k : recorded_topics()) known += (known.empty() ? "" : ", ") + std::string(k.topic);
      std::fprintf(stderr, "pmuctl record: --topic %s is not a topic of the contract (%s)\n", n.c_str(), known.c_str());
      return 2;
    }
    if (std::find(topics.begin(), topics.end(), t) == topics.end()) topics.push_back(t);
  }
  if (topics.empty())
    for (const auto& t : recorded_topics())
      if (t.by_default) topics.push_back(&t);

  // Signals are taken by sigtimedwait in this thread; blocked before Fast DDS starts its
  // threads, which inherit the mask, so no handler runs inside them.
  sigset_t stop;
  sigemptyset(&stop);
  sigaddset(&stop, SIGINT);
  sigaddset(&stop, SIGTERM);
  pthread_sigmask(SIG_BLOCK, &stop, nullptr);

  auto shared = std::make_unique<Shared>();  // outlives the participant and its listeners
  if (const auto why = shared->rec.open(path, topics); !why.empty()) {
    std::fprintf(stderr, "pmuctl record: %s\n", why.c_str());
    const bool created = shared->rec.created();
    shared->rec.close();
    if (created) ::unlink(path.c_str());  // nothing recorded: no file that looks like a recording
    return created ? 1 : 2;
  }
  std::vector<std::unique_ptr<TopicListener>> listeners;
  {
    pmu::dds::DdsContext dds(o.domain, o.qos_file, "pmuctl-record", o.security, pmu::dds::Transport::Default,
                             o.network, partitions_for(o));
    for (std::size_t i = 0; i < topics.size(); ++i) {
      listeners.push_back(std::make_unique<TopicListener>(*shared, i));
      dds.reader(dds.topic(topics[i]->topic, raw_type(topics[i]->type_name)), topics[i]->qos_profile,
                 listeners.back().get());
    }
    std::fprintf(stderr, "pmuctl record: recording %zu topics on domain %d into %s; Ctrl-C stops\n", topics.size(),
                 o.domain, path.c_str());
    const bool tty = ::isatty(STDERR_FILENO) == 1;
    int ticks = 0;
    for (;;) {
      const timespec second{1, 0};
      const int sig = sigtimedwait(&stop, nullptr, &second);
      std::lock_guard<std::mutex> lock(shared->mutex);
      if (sig == SIGINT || sig == SIGTERM) break;
      if (!shared->rec.flush() || shared->rec.failed()) break;
      if (tty)
        std::fprintf(stderr, "\r\033[Kpmuctl record: %s", shared->rec.progress().c_str());
      else if (++ticks % 10 == 0)
        std::fprintf(stderr, "pmuctl record: %s\n", shared->rec.progress().c_str());
    }
    std::lock_guard<std::mutex> lock(shared->mutex);
    shared->closed = true;
    if (tty) std::fprintf(stderr, "\n");
  }  // the participant and its readers end here: no listener runs after
  const std::string failure = shared->rec.error();
  const std::string progress = shared->rec.progress();
  const std::string closing = shared->rec.close();
  if (!failure.empty() || !closing.empty()) {
    std::fprintf(stderr, "pmuctl record: %s\n", (failure.empty() ? closing : failure + "; " + closing).c_str());
    return 1;
  }
  std::fprintf(stderr, "pmuctl record: %s written to %s\n", progress.c_str(), path.c_str());
  return 0;
}

}  // namespace pmu::tools
