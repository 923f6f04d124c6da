#include "pmuctl/record/record_verb.hpp"

#include <unistd.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <memory>
#include <mutex>

#include "pmu/dds/dds_context.hpp"
#include "pmuctl/record/mcap_recording.hpp"
#include "pmuctl/record/raw_topic_readers.hpp"
#include "pmu/transport/stop_signals.hpp"

namespace pmu::tools {
namespace {

// The recording, shared by the readers' listeners (Fast DDS threads) and the main thread.
struct Shared {
  std::mutex mutex;
  McapRecording rec;
  bool closed = false;
};

}  // namespace

int run_record(const GlobalOptions& o, const std::string& path, const std::vector<std::string>& names) {
  std::vector<const RecordedTopic*> topics;
  Ros2Selection ros2;
  if (!forwarded_topics(o, names, "record", topics, ros2)) return 2;

  pmu::transport::StopSignals stop;
  // A reader of a pipe or FIFO that goes away gives EPIPE, said and exit status 1, instead
  // of a silent death by SIGPIPE.
  std::signal(SIGPIPE, SIG_IGN);
  auto shared = std::make_unique<Shared>();  // outlives the participant and its listeners
  // Before any participant exists: a path that cannot be written is refused at once.
  if (const auto why = shared->rec.open(path, topics); !why.empty()) {
    std::fprintf(stderr, "pmuctl record: %s\n", why.c_str());
    const bool created = shared->rec.created();
    shared->rec.close();
    shared->rec.discard();  // nothing recorded: no file that looks like a recording (only its own)
    return created ? 1 : 2;
  }
  // The recording starts now: before this no message is logged (state that DDS gives the late
  // reader keeps its own time as publish time).
  shared->rec.start_log_times_at(static_cast<std::uint64_t>(
      std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::system_clock::now().time_since_epoch())
          .count()));
  Shared& s = *shared;
  RawTopicReaders readers([&s](const RawSampleInfo& info, RawSample& sample) {
    std::lock_guard<std::mutex> lock(s.mutex);
    if (s.closed || s.rec.failed()) return;
    s.rec.write(info.topic, info.time_ns, sample.bytes.data(), sample.bytes.size());
  });
  {
    pmu::dds::DdsContext dds(o.domain, o.qos_file, "pmuctl-record", o.security, pmu::dds::Transport::Default, o.network,
                             partitions_for(o));
    readers.open(dds, topics);
    // A ROS 2 topic's channel is added before its reader exists, so before its first message.
    Ros2Readers ros2_readers(std::move(ros2), o.vehicle, "record");
    const auto add_channel = [&s](const RecordedTopic& t) {
      std::lock_guard<std::mutex> lock(s.mutex);
      return s.rec.add_topic(&t);
    };
    ros2_readers.update(dds, readers, add_channel);
    std::fprintf(stderr, "pmuctl record: recording %zu topics on domain %d into %s; Ctrl-C stops\n", topics.size(),
                 o.domain, shared->rec.name().c_str());
    const bool tty = ::isatty(STDERR_FILENO) == 1;
    int ticks = 0;
    for (;;) {
      const bool signalled = stop.wait_for(std::chrono::seconds(1)) != 0;
      if (!signalled) ros2_readers.update(dds, readers, add_channel);
      std::lock_guard<std::mutex> lock(shared->mutex);
      if (signalled) break;
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
  const std::string closing = shared->rec.close();
  // Also after a write error: the file is ended and holds what was recorded before it.
  const std::string committing = shared->rec.commit();
  std::string why;
  for (const std::string* part : {&failure, &closing, &committing})
    if (!part->empty()) why += (why.empty() ? "" : "; ") + *part;
  if (!why.empty()) {
    std::fprintf(stderr, "pmuctl record: %s\n", why.c_str());
    return 1;
  }
  std::fprintf(stderr, "pmuctl record: %s written to %s (%llu bytes)\n", shared->rec.progress().c_str(),
               shared->rec.name().c_str(), static_cast<unsigned long long>(shared->rec.bytes()));
  return 0;
}

namespace {

class RecordVerb : public Verb {
 public:
  explicit RecordVerb(CLI::App& app) {
    record_ = app.add_subcommand(
        "record", "Record the topics into an MCAP file (Foxglove, Lichtblick, PlotJuggler) until Ctrl-C or SIGTERM");
    record_
        ->add_option("file", path_,
                     "The MCAP file (a regular file is replaced when the recording ends), a FIFO or a "
                     "character device (written in place), or - for standard output")
        ->required();
    record_
        ->add_option("--topic", topics_,
                     "Only this topic (pmu/voltages or voltages; also low_rate/..., command, command_reply); "
                     "repeat for more (default: telemetry, state, health, battery and MPPT topics)")
        ->allow_extra_args(false);
  }
  bool chosen() const override { return record_->parsed(); }
  bool ends_by_itself() const override { return false; }
  int run(GlobalOptions& g) override { return run_record(g, path_, topics_); }

 private:
  CLI::App* record_;
  std::string path_;
  std::vector<std::string> topics_;
};

}  // namespace

std::unique_ptr<Verb> add_record_verb(CLI::App& app) { return std::make_unique<RecordVerb>(app); }

}  // namespace pmu::tools
