// lab_ground: the ground station of the network lab (tests/lab/README.md).
//
// One DDS participant that sends batches of pmu::v5::Command to pmu-service and correlates
// the replies by request id, the way a ground-station bridge would over a lossy radio link:
//   - at most `window` requests in flight (pipelined), each with a unique id `<tag>-<n>`;
//   - a request without a final reply `resend` s after it was last sent is written again
//     with the SAME id and content (interface.md 2.4: answered again, never executed twice);
//   - a request without a final reply `timeout` s after its first send is given up: a
//     TIMEOUT at the client;
//   - the batch stops at `deadline` s; what is still open then is listed as unanswered.
// Each batch prints one JSON summary line: sent, final replies per result, duplicates,
// resends, round trip p50/p99/max (first send to final reply), the ids without a final
// reply. Replies that come after their request was given up are printed as "late_reply"
// events, replies to an id already answered as "duplicate_reply" events, and every change
// of the command writer's or reply reader's matches as a "matched" event: the lab measures
// discovery with them. Every event carries `t`, CLOCK_BOOTTIME in seconds, the clock of
// /proc/uptime, so the lab's shell can put it next to its own times.
//
//   lab_ground [--domain N] [--bus NAME] [--address N] [--qos-file F] [--transport udp|default]
//              [batch options]            one batch, then exit
//   lab_ground --stdin [...]              one batch per line read: `batch key=value ...`
//                                         (keys as the options without --), `quit` or EOF ends
// Batch options: --tag T --count N --window W --resend R --timeout T --deadline D
//   --expires-in E (0: expires_at 0, the service's default lifetime) --wait-match S
//   --rate R (new requests per second at most, default 15: under the service's 20/s per PMU)
//   --at T (start the batch at CLOCK_BOOTTIME T; on a line: at=T)
//   --parameter P --values a,b,... (alternated; every request sets P to one of them, and its
//   COMPLETED reply must carry that value read back).
// Exit status 0 when every batch ran (its results are for the caller to judge), 2 for a
// usage error or when DDS cannot be set up.

#include <time.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <fastdds/dds/core/status/PublicationMatchedStatus.hpp>
#include <fastdds/dds/core/status/SubscriptionMatchedStatus.hpp>
#include <fastdds/dds/publisher/DataWriterListener.hpp>
#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <iostream>
#include <map>
#include <mutex>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "pmu/command/command.hpp"
#include "pmu/dds/dds_context.hpp"
#include "pmu/idl/command.h"
#include "pmu/idl/commandPubSubTypes.h"
#include "pmu/idl/guarded_type.hpp"
#include "pmu/idl/topics.hpp"

namespace {

using namespace eprosima::fastdds::dds;
using Json = nlohmann::json;
using Clock = std::chrono::steady_clock;

// CLOCK_BOOTTIME: what /proc/uptime shows, so event times line up with the lab's shell.
double boottime() {
  timespec ts{};
  ::clock_gettime(CLOCK_BOOTTIME, &ts);
  return static_cast<double>(ts.tv_sec) + static_cast<double>(ts.tv_nsec) / 1e9;
}

double seconds_between(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double>(b - a).count();
}

// The service's names for its results; pmu::v5::CommandResult has the same order (static_assert
// in service/endpoints/src/dds_commands.cpp). The names are literals, so data() ends in NUL.
const char* result_name(pmu::v5::CommandResult r) {
  return pmu::service::to_string(static_cast<pmu::service::CommandResult>(r)).data();
}

// One line per event or summary; the listener threads and the main thread both print.
std::mutex g_out;
void emit(Json j) {
  std::lock_guard<std::mutex> lock(g_out);
  std::printf("%s\n", j.dump().c_str());
  std::fflush(stdout);
}

struct BatchSpec {
  std::string tag = "cmd";
  long count = 1;
  int window = 8;
  double resend = 0;       // s; 0: never
  double timeout = 0;      // s; 0: none but the deadline
  double deadline = 60;    // s
  double expires_in = 0;   // s; 0: expires_at 0
  double wait_match = 30;  // s to wait for the service before the first send; 0: send at once
  double at = 0;           // CLOCK_BOOTTIME s at which the batch starts (0: at once): the lab
                           // schedules sends into a cut to the tenth of a second this way,
                           // which its shell, on an emulated VM, could not
  double rate = 15;        // new requests per second at most; 0: no cap. The service refuses
                           // more than 20/s per PMU (policy rate_limit, burst 40); resends are
                           // not counted there, so only new requests are paced.
  std::string parameter = "payload_voltage";
  std::vector<double> values{12.5, 13.5};
};

// What the client knows of one request id.
struct Request {
  std::string tag;  // its batch
  pmu::v5::Command command;
  Clock::time_point first_send;
  Clock::time_point last_send;
  int sends = 0;
  enum class State { Open, Answered, GivenUp } state = State::Open;
  bool client_timeout = false;  // given up after the batch's timeout (not at its deadline)
  std::optional<pmu::v5::CommandReply> reply;
  double rtt = 0;  // s, first send to final reply
};

class Ground : public DataWriterListener, public DataReaderListener {
 public:
  Ground(int domain, const std::string& qos_file, pmu::dds::Transport transport, std::string bus, std::uint16_t address)
      : dds_(domain, qos_file, "lab_ground", {}, transport), bus_(std::move(bus)), address_(address) {
    // The reader first: a reply can then never come before the reader exists.
    replies_ = &dds_.reader(
        dds_.topic(pmu::topics::kCommandReply, TypeSupport(new pmu::idl::Guarded<pmu::v5::CommandReplyPubSubType>())),
        pmu::qos_profiles::kCommand, this);
    writer_ = &dds_.writer(dds_.topic(pmu::topics::kCommand, TypeSupport(new pmu::v5::CommandPubSubType())),
                           pmu::qos_profiles::kCommand, this);
  }
  ~Ground() override {
    // The entities die with dds_; no callback may reach a half-destroyed listener.
    replies_->set_listener(nullptr);
    writer_->set_listener(nullptr);
  }
  Ground(const Ground&) = delete;
  Ground& operator=(const Ground&) = delete;

  Json run(const BatchSpec& spec);

  void on_publication_matched(DataWriter*, const PublicationMatchedStatus& s) override {
    writer_matched_ = s.current_count;
    emit({{"event", "matched"},
          {"endpoint", "commands"},
          {"current", s.current_count},
          {"change", s.current_count_change},
          {"t", boottime()}});
    wake_.notify_all();
  }
  void on_subscription_matched(DataReader*, const SubscriptionMatchedStatus& s) override {
    reader_matched_ = s.current_count;
    emit({{"event", "matched"},
          {"endpoint", "replies"},
          {"current", s.current_count},
          {"change", s.current_count_change},
          {"t", boottime()}});
    wake_.notify_all();
  }
  void on_data_available(DataReader* reader) override {
    pmu::v5::CommandReply r;
    SampleInfo info;
    while (reader->take_next_sample(&r, &info) == ReturnCode_t::RETCODE_OK) {
      if (info.valid_data) on_reply(r);
    }
  }

 private:
  bool matched() const { return writer_matched_ > 0 && reader_matched_ > 0; }
  void on_reply(const pmu::v5::CommandReply& r);
  pmu::v5::Command make(const BatchSpec& spec, long n) const;
  void send(Request& q, Clock::time_point now);

  pmu::dds::DdsContext dds_;
  std::string bus_;
  std::uint16_t address_;
  DataWriter* writer_ = nullptr;
  DataReader* replies_ = nullptr;
  std::atomic<int> writer_matched_{0};
  std::atomic<int> reader_matched_{0};

  std::mutex mutex_;  // guards what follows; the listener thread and run() share it
  std::condition_variable wake_;
  std::map<std::string, Request> requests_;  // every id of every batch, so a late reply is known
  std::map<std::string, int> duplicates_;    // per batch tag
};

pmu::v5::Command Ground::make(const BatchSpec& spec, long n) const {
  pmu::v5::Command c;
  c.request_id(spec.tag + "-" + std::to_string(n));
  c.bus(bus_);
  c.address(address_);
  c.kind(pmu::v5::SET_PARAMETER);
  c.parameter(spec.parameter);
  c.value(spec.values[static_cast<std::size_t>(n - 1) % spec.values.size()]);
  c.confirm(false);
  if (spec.expires_in > 0) {
    const auto at = std::chrono::system_clock::now() + std::chrono::duration_cast<std::chrono::system_clock::duration>(
                                                           std::chrono::duration<double>(spec.expires_in));
    c.expires_at(static_cast<std::uint64_t>(
        std::chrono::duration_cast<std::chrono::nanoseconds>(at.time_since_epoch()).count()));
  } else {
    c.expires_at(0);
  }
  return c;
}

// Caller holds mutex_. A resend writes the very same sample (same id, same expires_at).
void Ground::send(Request& q, Clock::time_point now) {
  if (q.sends == 0) q.first_send = now;
  q.last_send = now;
  ++q.sends;
  if (!writer_->write(&q.command))
    emit({{"event", "write_failed"}, {"id", q.command.request_id().to_string()}, {"t", boottime()}});
}

void Ground::on_reply(const pmu::v5::CommandReply& r) {
  if (r.result() == pmu::v5::IN_PROGRESS) return;  // not final (engine start); never sent here
  const std::string id = r.request_id().to_string();
  std::lock_guard<std::mutex> lock(mutex_);
  auto it = requests_.find(id);
  if (it == requests_.end()) return;  // another client's reply: every reply reader sees them all
  Request& q = it->second;
  const auto now = Clock::now();
  switch (q.state) {
    case Request::State::Open:
      q.state = Request::State::Answered;
      q.reply = r;
      q.rtt = seconds_between(q.first_send, now);
      wake_.notify_all();
      return;
    case Request::State::Answered:
      // The service answers every resend again (interface.md 2.4): expected, and counted.
      ++duplicates_[q.tag];
      emit({{"event", "duplicate_reply"}, {"id", id}, {"result", result_name(r.result())}, {"t", boottime()}});
      return;
    case Request::State::GivenUp:
      // The client timed out on it: whatever comes now comes late, and the lab checks it.
      emit({{"event", "late_reply"},
            {"id", id},
            {"result", result_name(r.result())},
            {"reason", r.reason().to_string()},
            {"after_first_send_s", seconds_between(q.first_send, now)},
            {"t", boottime()}});
      return;
  }
}

// Nearest-rank percentile of sorted values.
double percentile(const std::vector<double>& sorted, double p) {
  if (sorted.empty()) return 0;
  auto rank = static_cast<std::size_t>(std::ceil(p / 100.0 * static_cast<double>(sorted.size())));
  rank = std::clamp<std::size_t>(rank, 1, sorted.size());
  return sorted[rank - 1];
}

Json Ground::run(const BatchSpec& spec) {
  if (const double wait = spec.at - boottime(); wait > 0)
    std::this_thread::sleep_for(std::chrono::duration<double>(wait));
  const auto start = Clock::now();
  const auto deadline =
      start + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(spec.deadline));
  const double t_start = boottime();
  std::unique_lock<std::mutex> lock(mutex_);
  bool waited_for_match = true;
  if (spec.wait_match > 0) {
    const auto until =
        start + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(spec.wait_match));
    waited_for_match = wake_.wait_until(lock, until, [this] { return matched(); });
  }
  const double t_matched = boottime();
  std::vector<std::string> ids;
  ids.reserve(static_cast<std::size_t>(spec.count));
  std::set<std::string> open;  // ids in flight
  long next = 1;
  long resends = 0;
  duplicates_[spec.tag] = 0;
  const auto resend_after = std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(spec.resend));
  const auto give_up_after = std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(spec.timeout));

  for (;;) {
    auto now = Clock::now();
    // Answers that came in: out of flight.
    for (auto it = open.begin(); it != open.end();) {
      if (requests_.at(*it).state != Request::State::Open)
        it = open.erase(it);
      else
        ++it;
    }
    if (now >= deadline) break;
    // Request n (from 1) may go at start + (n - 1) / rate: the rate cap, as a schedule.
    const auto slot = [&](long n) {
      return spec.rate > 0 ? start + std::chrono::duration_cast<Clock::duration>(
                                         std::chrono::duration<double>(static_cast<double>(n - 1) / spec.rate))
                           : start;
    };
    while (static_cast<int>(open.size()) < spec.window && next <= spec.count && now >= slot(next)) {
      pmu::v5::Command c = make(spec, next++);
      const std::string id = c.request_id().to_string();
      auto [it, fresh] = requests_.try_emplace(id);
      if (!fresh) {  // a tag used twice would make a resend out of a new command: refuse it
        emit({{"event", "error"}, {"what", "request id " + id + " already used; use another tag"}});
        return Json{{"batch", spec.tag}, {"error", "request id reused"}};
      }
      it->second.tag = spec.tag;
      it->second.command = c;
      send(it->second, now);
      ids.push_back(id);
      open.insert(id);
    }
    if (next > spec.count && open.empty()) break;
    // Give up or resend; find the next moment something is due.
    auto due = deadline;
    if (static_cast<int>(open.size()) < spec.window && next <= spec.count) due = std::min(due, slot(next));
    for (auto it = open.begin(); it != open.end();) {
      Request& q = requests_.at(*it);
      if (spec.timeout > 0 && now - q.first_send >= give_up_after) {
        q.state = Request::State::GivenUp;
        q.client_timeout = true;
        it = open.erase(it);
        continue;
      }
      if (spec.resend > 0 && now - q.last_send >= resend_after) {
        send(q, now);
        ++resends;
      }
      if (spec.timeout > 0) due = std::min(due, q.first_send + give_up_after);
      if (spec.resend > 0) due = std::min(due, q.last_send + resend_after);
      ++it;
    }
    if (next > spec.count && open.empty()) break;
    wake_.wait_until(lock, due);
  }
  const double t_end = boottime();

  std::map<std::string, long> results;
  std::vector<double> rtts;
  std::vector<std::string> no_reply, client_timeouts, value_mismatch;
  long finals = 0;
  for (const auto& id : ids) {
    Request& q = requests_.at(id);
    if (q.state == Request::State::Open) q.state = Request::State::GivenUp;  // the deadline: a later reply is late
    if (!q.reply) {
      no_reply.push_back(id);
      if (q.client_timeout) client_timeouts.push_back(id);
      continue;
    }
    ++finals;
    ++results[result_name(q.reply->result())];
    rtts.push_back(q.rtt * 1000.0);
    if (q.reply->result() == pmu::v5::COMPLETED &&
        (!q.reply->has_value() || std::fabs(q.reply->value() - q.command.value()) > 1e-3))
      value_mismatch.push_back(id);
  }
  std::sort(rtts.begin(), rtts.end());
  auto ms = [](double v) { return std::round(v * 10.0) / 10.0; };
  Json j{{"batch", spec.tag},
         {"matched_before_first_send", waited_for_match},
         {"sent", static_cast<long>(ids.size())},
         {"writes", static_cast<long>(ids.size()) + resends},
         {"resends", resends},
         {"final_replies", finals},
         {"results", results},
         {"duplicates", duplicates_[spec.tag]},
         {"rtt_ms",
          {{"min", ms(rtts.empty() ? 0.0 : rtts.front())},
           {"p50", ms(percentile(rtts, 50))},
           {"p90", ms(percentile(rtts, 90))},
           {"p99", ms(percentile(rtts, 99))},
           {"max", ms(rtts.empty() ? 0.0 : rtts.back())}}},
         {"no_reply", no_reply},
         {"client_timeouts", client_timeouts},
         {"value_mismatch", value_mismatch},
         {"t_start", t_start},
         {"t_first_send", t_matched},
         {"t_end", t_end}};
  return j;
}

std::vector<double> parse_values(const std::string& text) {
  std::vector<double> out;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ',')) {
    if (item.empty()) continue;
    std::size_t used = 0;
    const double v = std::stod(item, &used);  // throws on junk: a usage error, caught in main
    if (used != item.size()) throw std::invalid_argument("'" + item + "' is not a number");
    out.push_back(v);
  }
  if (out.empty()) throw std::invalid_argument("no values");
  return out;
}

// `batch tag=x count=5 ...`: keys as the command-line options, over the defaults given there.
BatchSpec parse_batch_line(const std::string& line, BatchSpec spec) {
  std::stringstream ss(line);
  std::string word;
  ss >> word;  // "batch"
  while (ss >> word) {
    const auto eq = word.find('=');
    if (eq == std::string::npos) throw std::invalid_argument("'" + word + "' is not key=value");
    const std::string key = word.substr(0, eq), value = word.substr(eq + 1);
    if (key == "tag")
      spec.tag = value;
    else if (key == "count")
      spec.count = std::stol(value);
    else if (key == "window")
      spec.window = std::stoi(value);
    else if (key == "resend")
      spec.resend = std::stod(value);
    else if (key == "timeout")
      spec.timeout = std::stod(value);
    else if (key == "deadline")
      spec.deadline = std::stod(value);
    else if (key == "expires-in")
      spec.expires_in = std::stod(value);
    else if (key == "wait-match")
      spec.wait_match = std::stod(value);
    else if (key == "rate")
      spec.rate = std::stod(value);
    else if (key == "at")
      spec.at = std::stod(value);
    else if (key == "parameter")
      spec.parameter = value;
    else if (key == "values")
      spec.values = parse_values(value);
    else
      throw std::invalid_argument("unknown key '" + key + "'");
  }
  if (spec.count < 1 || spec.window < 1 || spec.deadline <= 0)
    throw std::invalid_argument("count, window and deadline must be positive");
  if (spec.tag.empty() || spec.tag.size() > 40) throw std::invalid_argument("tag must be 1..40 characters");
  return spec;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"lab_ground: the network lab's ground station (tests/lab/README.md)"};
  int domain = 0;
  std::string qos_file, bus = "sim0", transport = "udp", values = "12.5,13.5";
  int address = 1;
  bool from_stdin = false;
  BatchSpec spec;
  app.add_option("--domain", domain)->check(CLI::Range(0, 232));
  app.add_option("--qos-file", qos_file, "QoS profiles (default: $PMU_QOS_FILE)");
  app.add_option("--bus", bus)->capture_default_str();
  app.add_option("--address", address)->check(CLI::Range(0, 65535))->capture_default_str();
  // udp: the ground station is another host; only what crosses the ground link may count.
  app.add_option("--transport", transport)->check(CLI::IsMember({"udp", "default"}))->capture_default_str();
  app.add_flag("--stdin", from_stdin, "Read batch lines from standard input");
  app.add_option("--tag", spec.tag)->capture_default_str();
  app.add_option("--count", spec.count)->capture_default_str();
  app.add_option("--window", spec.window)->capture_default_str();
  app.add_option("--resend", spec.resend, "Seconds without a final reply before a resend (0: never)")
      ->capture_default_str();
  app.add_option("--timeout", spec.timeout, "Seconds after the first send before the client gives up (0: none)")
      ->capture_default_str();
  app.add_option("--deadline", spec.deadline, "Seconds the batch may take")->capture_default_str();
  app.add_option("--expires-in", spec.expires_in, "expires_at this many seconds ahead (0: expires_at 0)")
      ->capture_default_str();
  app.add_option("--wait-match", spec.wait_match, "Seconds to wait for the service before sending (0: do not)")
      ->capture_default_str();
  app.add_option("--at", spec.at, "Start the batch at this CLOCK_BOOTTIME second (0: at once)")->capture_default_str();
  app.add_option("--rate", spec.rate, "New requests per second at most (0: no cap)")->capture_default_str();
  app.add_option("--parameter", spec.parameter)->capture_default_str();
  app.add_option("--values", values)->capture_default_str();
  CLI11_PARSE(app, argc, argv);

  try {
    spec.values = parse_values(values);
    spec = parse_batch_line("batch", spec);  // the same checks as a line
    Ground ground(domain, qos_file, transport == "udp" ? pmu::dds::Transport::UdpOnly : pmu::dds::Transport::Default,
                  bus, static_cast<std::uint16_t>(address));
    emit({{"event", "ready"}, {"t", boottime()}});
    if (!from_stdin) {
      emit(ground.run(spec));
      return 0;
    }
    std::string line;
    while (std::getline(std::cin, line)) {
      if (line.empty()) continue;
      if (line == "quit") break;
      if (line.rfind("batch", 0) != 0) {
        emit({{"event", "error"}, {"what", "unknown line: " + line}});
        continue;
      }
      BatchSpec b;
      try {
        b = parse_batch_line(line, spec);
      } catch (const std::exception& e) {
        emit({{"event", "error"}, {"what", std::string("bad batch line: ") + e.what()}});
        continue;
      }
      emit(ground.run(b));
    }
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "lab_ground: %s\n", e.what());
    return 2;
  }
}
