#include "pmuctl/record/mcap_decode.hpp"

#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <unordered_map>
#include <vector>

#include "pmu/codec/candump.hpp"
#include "pmu/codec/canopen.hpp"
#include "pmu/codec/decode.hpp"
#include "pmu/dds/telemetry_samples.hpp"
#include "pmuctl/record/mcap_recording.hpp"

namespace pmu::tools {
namespace {

struct FileCloser {
  void operator()(std::FILE* f) const {
    if (f && f != stdin) std::fclose(f);
  }
};

// The channels decode can fill: the PMU telemetry topics.
std::vector<const RecordedTopic*> telemetry_topics() {
  std::vector<const RecordedTopic*> out;
  for (const char* name : {"voltages", "currents", "battery_energy", "temperatures", "status"})
    out.push_back(find_recorded_topic(name));
  return out;
}

std::size_t index_of(const std::vector<const RecordedTopic*>& topics, const char* topic) {
  for (std::size_t i = 0; i < topics.size(); ++i)
    if (std::strcmp(topics[i]->topic, topic) == 0) return i;
  return topics.size();
}

}  // namespace

int run_decode_mcap(const std::string& log, const std::string& out, std::optional<codec::FirmwareVersion> firmware) {
  std::unique_ptr<std::FILE, FileCloser> in(log == "-" ? stdin : std::fopen(log.c_str(), "r"));
  if (!in) {
    std::fprintf(stderr, "pmuctl decode: cannot open %s: %s\n", log.c_str(), std::strerror(errno));
    return 2;
  }
  const auto topics = telemetry_topics();
  // A reader of a pipe or FIFO that goes away gives EPIPE, said and exit status 1.
  std::signal(SIGPIPE, SIG_IGN);
  McapRecording rec;
  if (const auto why = rec.open(out, topics); !why.empty()) {
    std::fprintf(stderr, "pmuctl decode --mcap: %s; %s not written\n", why.c_str(), rec.name().c_str());
    const bool created = rec.created();
    rec.close();
    rec.discard();
    return created ? 1 : 2;  // created, then the disk was full: not the caller's input
  }
  auto give_up = [&](const std::string& why) {
    std::fprintf(stderr, "pmuctl decode --mcap: %s; %s %s\n", why.c_str(), rec.name().c_str(),
                 rec.streaming() ? "got an incomplete file" : "not written");
    rec.close();
    rec.discard();  // its own temporary file only; a stream keeps what it got
    return 1;
  };

  std::unordered_map<std::uint16_t, codec::FirmwareVersion> learned;
  std::uint64_t lines = 0, written = 0, skipped = 0, errors = 0, untimed = 0;
  char* line = nullptr;
  std::size_t cap = 0;
  ssize_t len = 0;
  service::TelemetryCdr sample;
  while ((len = ::getline(&line, &cap, in.get())) >= 0) {
    ++lines;
    std::size_t n = static_cast<std::size_t>(len);
    while (n > 0 && (line[n - 1] == '\n' || line[n - 1] == '\r')) --n;
    const auto parsed = codec::parse_candump_line(std::string_view(line, n));
    if (!parsed) {
      if (errors++ < 10)
        std::fprintf(stderr, "pmuctl decode --mcap: %s:%llu: %.*s\n", log.c_str(),
                     static_cast<unsigned long long>(lines), static_cast<int>(parsed.error().reason.size()),
                     parsed.error().reason.data());
      continue;
    }
    const auto& l = *parsed;
    if (codec::canopen::is_canopen_id(l.frame.id, l.frame.extended)) {
      ++skipped;  // a battery's or MPPT's frame carries one value; the samples are the service's assembly
      continue;
    }
    const std::uint16_t address = codec::address_of_id(l.frame.id);
    const auto known = learned.find(address);
    const auto m = codec::decode(l.frame, known != learned.end() ? std::optional(known->second) : firmware);
    if (!m) {
      if (errors++ < 10)
        std::fprintf(stderr, "pmuctl decode --mcap: %s:%llu: %s\n", log.c_str(), static_cast<unsigned long long>(lines),
                     m.error().describe().c_str());
      continue;
    }
    if (const auto* info = std::get_if<codec::FirmwareInfo>(&m->payload)) learned[m->address] = info->version();
    service::DeviceKey key;
    key.bus = std::string(l.interface);
    key.address = m->address;
    if (!service::telemetry_cdr("", key, *m, sample)) {
      ++skipped;  // not a telemetry sample (a request, a parameter, a command)
      continue;
    }
    if (!l.has_time) {
      ++untimed;
      continue;
    }
    const std::uint64_t t = static_cast<std::uint64_t>(l.seconds) * 1000000000ull + l.microseconds * 1000ull;
    if (!rec.write(index_of(topics, sample.topic), t, sample.bytes.data(), sample.bytes.size())) {
      std::free(line);
      return give_up(rec.error());
    }
    ++written;
  }
  std::free(line);
  if (std::ferror(in.get())) return give_up("error reading " + log);
  if (errors > 10)
    std::fprintf(stderr, "pmuctl decode --mcap: ... %llu lines not decoded in all\n",
                 static_cast<unsigned long long>(errors));
  if (const auto why = rec.close(); !why.empty()) return give_up(why);
  if (const auto why = rec.commit(); !why.empty()) return give_up(why);
  std::fprintf(stderr,
               "pmuctl decode --mcap: %llu lines, %llu telemetry samples written to %s (%llu bytes), %llu frames not "
               "telemetry, %llu without a timestamp (screen format: take logs with candump -L), %llu errors\n",
               static_cast<unsigned long long>(lines), static_cast<unsigned long long>(written), rec.name().c_str(),
               static_cast<unsigned long long>(rec.bytes()), static_cast<unsigned long long>(skipped),
               static_cast<unsigned long long>(untimed), static_cast<unsigned long long>(errors));
  return 0;
}

}  // namespace pmu::tools
