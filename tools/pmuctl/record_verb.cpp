#include "pmuctl/record_verb.hpp"

#include <unistd.h>

#include <cstdio>
#include <memory>
#include <mutex>

#include "pmu/service/dds_context.hpp"
#include "pmuctl/mcap_recording.hpp"
#include "pmuctl/raw_topic_readers.hpp"
#include "pmuctl/stop_signals.hpp"

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
  if (!forwarded_topics(o, names, "record", topics)) return 2;

  const StopSignals stop;
  auto shared = std::make_unique<Shared>();  // outlives the participant and its listeners
  if (const auto why = shared->rec.open(path, topics); !why.empty()) {
    std::fprintf(stderr, "pmuctl record: %s\n", why.c_str());
    const bool created = shared->rec.created();
    shared->rec.close();
    if (created) ::unlink(path.c_str());  // nothing recorded: no file that looks like a recording
    return created ? 1 : 2;
  }
  Shared& s = *shared;
  RawTopicReaders readers([&s](const RawSampleInfo& info, RawSample& sample) {
    std::lock_guard<std::mutex> lock(s.mutex);
    if (s.closed || s.rec.failed()) return;
    s.rec.write(info.topic, info.time_ns, sample.bytes.data(), sample.bytes.size());
  });
  {
    pmu::dds::DdsContext dds(o.domain, o.qos_file, "pmuctl-record", o.security, pmu::dds::Transport::Default,
                             o.network, partitions_for(o));
    readers.open(dds, topics);
    std::fprintf(stderr, "pmuctl record: recording %zu topics on domain %d into %s; Ctrl-C stops\n", topics.size(),
                 o.domain, path.c_str());
    const bool tty = ::isatty(STDERR_FILENO) == 1;
    int ticks = 0;
    for (;;) {
      const bool signalled = stop.wait_one_second();
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
