// The command boundary against the real pmu-service process, as a hostile or careless DDS
// peer would meet it: every kind of malformed or adversarial pmu::v5::Command gets exactly one
// reply with a reason (or, when it is not a pmu::v5::Command at all, is counted and dropped),
// nothing kills or stalls the service, nothing forges its log, duplicates are told apart per
// sender, bursts are answered in full and the memory for remembered ids stays bounded.
#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstring>
#include <fastdds/dds/core/status/PublicationMatchedStatus.hpp>
#include <fastdds/dds/core/status/SubscriptionMatchedStatus.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastrtps/rtps/common/SerializedPayload.h>
#include <fstream>
#include <limits>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <thread>

#include "pmu/dds/dds_context.hpp"
#include "pmu/endpoints/command_cdr.hpp"
#include "pmu/idl/command.h"
#include "pmu/idl/commandPubSubTypes.h"
#include "pmu/idl/guarded_type.hpp"
#include "pmu/idl/topics.hpp"
#include "support/answered.hpp"
#include "support/domain.hpp"
#include "support/process.hpp"
#include "support/wait.hpp"

namespace pmu::service {
namespace {

using namespace eprosima::fastdds::dds;
using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

std::uint32_t wire(CommandKind k) { return static_cast<std::uint32_t>(k); }

std::uint64_t now_ns() {
  return static_cast<std::uint64_t>(
      std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::system_clock::now().time_since_epoch()).count());
}

// pmu-service on two simulated PMUs, its log in a file. No rate limit: the bursts below are
// about delivery, not policy.
class Service {
 public:
  explicit Service(int domain) : log_path_("/tmp/pmu-boundary-" + std::to_string(::getpid()) + ".log") {
    config_path_ = "/tmp/pmu-boundary-" + std::to_string(::getpid()) + ".yaml";
    std::ofstream(config_path_) << "domain: " << domain
                                << "\nbuses:\n  - interface: sim\n    name: sim0\n    devices:\n"
                                   "      - address: 1\n      - address: 2\npolicy:\n  rate_limit: 0\n";
    pmu::test::ChildOptions o;
    o.stderr_path = log_path_;
    process_ = pmu::test::Child({PMU_SERVICE_PATH, "--config", config_path_}, o);
  }
  ~Service() {
    (void)process_.stop(10s);
    ::unlink(config_path_.c_str());
    ::unlink(log_path_.c_str());
  }
  bool alive() const { return process_.running(); }
  std::string log() const {
    std::ifstream in(log_path_);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
  }
  long rss_kib() const {
    std::ifstream in("/proc/" + std::to_string(process_.pid()) + "/status");
    std::string line;
    while (std::getline(in, line))
      if (line.rfind("VmRSS:", 0) == 0) return std::stol(line.substr(6));
    return -1;
  }

 private:
  mutable pmu::test::Child process_;  // running() reaps it once it has exited
  std::string config_path_, log_path_;
};

CommandSample command(const std::string& id, CommandKind kind, std::uint16_t address = 1) {
  CommandSample s;
  s.request_id = id;
  s.bus = "sim0";
  s.address = address;
  s.kind = wire(kind);
  return s;
}

// A peer that writes CommandSamples as they are, booleans and all, and reads every reply.
class Peer {
 public:
  Peer(int domain, const std::string& name)
      : dds_(domain, "", name),
        writer_(
            dds_.writer(dds_.topic(topics::kCommand, TypeSupport(new CommandSampleType())), qos_profiles::kCommand)),
        replies_(dds_.reader(dds_.topic(topics::kCommandReply, TypeSupport(new pmu::v5::CommandReplyPubSubType())),
                             qos_profiles::kCommand)) {}

  bool wait_matched(std::chrono::seconds within = 20s) {
    return pmu::test::wait_until(
        [&] {
          PublicationMatchedStatus p;
          SubscriptionMatchedStatus s;
          writer_.get_publication_matched_status(p);
          replies_.get_subscription_matched_status(s);
          return p.current_count > 0 && s.current_count > 0;
        },
        within);
  }
  void send(const CommandSample& s) {
    CommandSampleType::Received r{s};
    ASSERT_TRUE(writer_.write(&r));
  }
  void settle() { writer_.wait_for_acknowledgments(eprosima::fastrtps::Duration_t(10, 0)); }
  // Matched on both sides: until the service has answered a probe (support/answered.hpp),
  // whatever its result.
  bool wait_answered(const std::string& probe_id) {
    return wait_matched() && pmu::test::until_answered([&] { send(command(probe_id, CommandKind::GetSerial)); },
                                                       [&] { return !replies(probe_id, 1, 0s).empty(); }, 30s);
  }
  // Replies received so far (a mark for replies()).
  std::size_t received() {
    (void)replies("", 0, 0s);
    return all_.size();
  }
  // Every reply (from the `since`-th received on) whose id starts with `prefix`, until `count`
  // of them arrived or `within` passed.
  std::vector<pmu::v5::CommandReply> replies(const std::string& prefix, std::size_t count,
                                             std::chrono::seconds within = 20s, std::size_t since = 0) {
    // Not wait_until: under a burst the reader must be drained again at once whenever the last
    // take found samples (its history is the command profile's depth), and sleep only when
    // it found none.
    const auto end = Clock::now() + within;
    do {
      pmu::v5::CommandReply r;
      SampleInfo info;
      bool any = false;
      while (replies_.take_next_sample(&r, &info) == ReturnCode_t::RETCODE_OK) {
        any = true;
        if (info.valid_data) all_.push_back(r);
      }
      mine_.clear();
      for (std::size_t i = since; i < all_.size(); ++i)
        if (all_[i].request_id().to_string().rfind(prefix, 0) == 0) mine_.push_back(all_[i]);
      if (mine_.size() >= count) break;
      if (!any) std::this_thread::sleep_for(2ms);
    } while (Clock::now() < end);
    return mine_;
  }
  dds::DdsContext& dds() { return dds_; }

 private:
  dds::DdsContext dds_;
  DataWriter& writer_;
  DataReader& replies_;
  std::vector<pmu::v5::CommandReply> all_, mine_;
};

CommandSample set(const std::string& id, const char* parameter, double value) {
  auto s = command(id, CommandKind::SetParameter);
  s.parameter = parameter;
  s.value = value;
  return s;
}

class Boundary : public ::testing::Test {
 protected:
  Boundary() : domain_(test::exclusive_dds_domain()), service_(domain_), peer_(domain_, "hostile-peer") {}
  void SetUp() override {
    ASSERT_TRUE(peer_.wait_matched()) << service_.log();
    // The devices' start-up reading: wait until a GET is answered (each try waits up to 2 s
    // for its reply, then the next is sent).
    int tries = 0;
    const bool ready = pmu::test::wait_until(
        [&] {
          const std::string id = "ready-" + std::to_string(tries++);
          peer_.send(command(id, CommandKind::GetSerial));
          const auto r = peer_.replies(id, 1, 2s);
          return !r.empty() && r[0].result() == pmu::v5::COMPLETED;
        },
        200s, 100ms);
    if (!ready) FAIL() << "the service never became ready\n" << service_.log();
  }
  // Sends `s` and returns its one reply (fails the test unless exactly one arrives).
  pmu::v5::CommandReply one_reply(const CommandSample& s) {
    const auto since = peer_.received();
    peer_.send(s);
    auto r = peer_.replies(s.request_id, 1, 20s, since);
    // Meant to let time pass: a second reply must NOT come, so there is no condition to wait
    // for; 100 ms gives one already sent the time to arrive.
    std::this_thread::sleep_for(100ms);
    r = peer_.replies(s.request_id, 2, 0s, since);
    EXPECT_EQ(r.size(), 1u) << "replies to " << s.request_id;
    return r.empty() ? pmu::v5::CommandReply{} : r.front();
  }

  int domain_;
  Service service_;
  Peer peer_;
};

struct Hostile {
  const char* what;
  CommandSample sample;
  pmu::v5::CommandResult result;
  const char* reason;  // a part of the reason
};

TEST_F(Boundary, EveryHostileSampleGetsOneReplyWithAReasonAndTheServiceLivesOn) {
  const double inf = std::numeric_limits<double>::infinity();
  auto with = [](CommandSample s, auto&& change) {
    change(s);
    return s;
  };
  const std::uint64_t far = 1ull << 63;
  const Hostile cases[] = {
      {"kind 12", with(command("h-kind12", CommandKind::Get), [](auto& s) { s.kind = 12; }), pmu::v5::REJECTED,
       "unknown command kind 12"},
      {"kind 2^32-1", with(command("h-kindmax", CommandKind::Get), [](auto& s) { s.kind = 0xFFFFFFFF; }),
       pmu::v5::REJECTED, "unknown command kind 4294967295"},
      {"NaN", set("h-nan", "avionics_voltage", std::nan("")), pmu::v5::REJECTED, "is not a number"},
      {"Inf", set("h-inf", "avionics_voltage", inf), pmu::v5::REJECTED, "is not a number"},
      {"-Inf", set("h-ninf", "servo_voltage", -inf), pmu::v5::REJECTED, "is not a number"},
      {"huge", set("h-huge", "battery_voltage", 1e300), pmu::v5::REJECTED, "out of range"},
      {"denormal voltage", set("h-denorm", "payload_voltage", 4e-320), pmu::v5::REJECTED, "out of range"},
      {"undefined output bits",
       with(command("h-outbits", CommandKind::EnableOutputs), [](auto& s) { s.outputs = 0xF2; }), pmu::v5::REJECTED,
       "unknown output bits 0xF0"},
      {"undefined group bits",
       with(command("h-groups", CommandKind::RequestMeasurements), [](auto& s) { s.groups = 0xE1; }), pmu::v5::REJECTED,
       "unknown measurement group bits 0xE0"},
      {"broadcast set", with(set("h-bcast", "avionics_voltage", 20), [](auto& s) { s.address = 0xFFFF; }),
       pmu::v5::REJECTED, "broadcast (65535) is only accepted for engine_stop"},
      {"unknown address", command("h-addr", CommandKind::GetSerial, 9), pmu::v5::REJECTED, "device 9 not seen on sim0"},
      {"unknown bus", with(command("h-bus", CommandKind::GetSerial), [](auto& s) { s.bus = "can7"; }),
       pmu::v5::REJECTED, "bus 'can7' is not served here"},
      {"empty bus", with(command("h-nobus", CommandKind::GetSerial), [](auto& s) { s.bus.clear(); }), pmu::v5::REJECTED,
       "bus '' is not served here"},
      {"over-long bus name",
       with(command("h-longbus", CommandKind::GetSerial), [](auto& s) { s.bus = std::string(200, 'b'); }),
       pmu::v5::REJECTED, "bus is 200 bytes long; at most 15 are allowed"},
      {"over-long parameter", set("h-longparam", std::string(40, 'p').c_str(), 1), pmu::v5::REJECTED,
       "parameter is 40 bytes long"},
      {"confirm byte 2", with(command("h-confirm2", CommandKind::EngineStart), [](auto& s) { s.confirm = 2; }),
       pmu::v5::REJECTED, "confirm is not a boolean (byte 0x02"},
      {"confirm byte 0xFF", with(command("h-confirmff", CommandKind::Reset), [](auto& s) { s.confirm = 0xFF; }),
       pmu::v5::REJECTED, "confirm is not a boolean (byte 0xFF"},
      {"enable byte 2", with(command("h-enable2", CommandKind::SetGeneration), [](auto& s) { s.enable = 2; }),
       pmu::v5::REJECTED, "enable is not a boolean"},
      {"T_U 0.0005 rounds to 0", set("h-tu", "upper_temperature_limit", 0.0005), pmu::v5::DENIED,
       "rule thermal_shutdown"},
      {"T_U -0.0009 rounds to 0", set("h-tu2", "upper_temperature_limit", -0.0009), pmu::v5::DENIED,
       "rule thermal_shutdown"},
      {"S0 -0.0004 rounds to 0", set("h-s0", "power_up_state", -0.0004), pmu::v5::DENIED, "rule power_up_avionics_off"},
      {"newline and escapes in the parameter", set("h-esc", "volts\n\x1b[2Jaudit: x", 1), pmu::v5::REJECTED,
       "unknown parameter 'volts\\x0A\\x1B[2Jaudit: x'"},
      {"expires_at 1", with(command("h-exp1", CommandKind::GetSerial), [](auto& s) { s.expires_at = 1; }),
       pmu::v5::REJECTED, "expired"},
      {"expired a second ago",
       with(command("h-exp-1s", CommandKind::GetSerial), [](auto& s) { s.expires_at = now_ns() - 1000000000ull; }),
       pmu::v5::REJECTED, "expired"},
      {"expires_at 2^63", with(command("h-exp63", CommandKind::GetSerial), [&](auto& s) { s.expires_at = far; }),
       pmu::v5::COMPLETED, ""},
      {"expires_at 2^64-2",
       with(command("h-exp64-2", CommandKind::GetSerial), [](auto& s) { s.expires_at = ~0ull - 1; }),
       pmu::v5::COMPLETED, ""},
      {"expires_at 2^64-1", with(command("h-exp64-1", CommandKind::GetSerial), [](auto& s) { s.expires_at = ~0ull; }),
       pmu::v5::COMPLETED, ""},
      {"expires in 5 s",
       with(command("h-exp5", CommandKind::GetSerial), [](auto& s) { s.expires_at = now_ns() + 5000000000ull; }),
       pmu::v5::COMPLETED, ""},
      {"broadcast engine stop", command("h-stopall", CommandKind::EngineStop, 0xFFFF), pmu::v5::COMPLETED,
       "stop sent to every PMU"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.what);
    const auto r = one_reply(c.sample);
    EXPECT_EQ(r.result(), c.result) << r.request_id().to_string() << " " << r.reason().to_string() << " "
                                    << r.value_text().to_string();
    EXPECT_NE(r.reason().to_string().find(c.reason), std::string::npos) << r.reason().to_string();
    ASSERT_TRUE(service_.alive()) << service_.log();
  }
  // An over-long request id: answered (cut to the reply's 63 bytes), not executed.
  auto long_id = command("h-longid-" + std::string(60, 'i'), CommandKind::GetSerial);
  peer_.send(long_id);
  const auto r = peer_.replies("h-longid-", 1);
  ASSERT_EQ(r.size(), 1u);
  EXPECT_EQ(r[0].result(), pmu::v5::REJECTED);
  EXPECT_NE(r[0].reason().to_string().find("request_id is 69 bytes long"), std::string::npos);
  // An empty id: one reply, REJECTED.
  peer_.send(command("", CommandKind::GetSerial));
  std::size_t empties = 0;
  const auto count_empties = [&] {
    empties = 0;
    for (const auto& x : peer_.replies("", 1000, 0s)) empties += x.request_id().to_string().empty() ? 1u : 0u;
    return empties;
  };
  pmu::test::wait_until([&] { return count_empties() >= 1; }, 20s);
  // Meant to let time pass: a second reply to it must NOT come; give one the time to arrive.
  std::this_thread::sleep_for(100ms);
  count_empties();
  EXPECT_EQ(empties, 1u);
  // Still serving.
  EXPECT_EQ(one_reply(set("h-after", "avionics_voltage", 20.0)).result(), pmu::v5::COMPLETED);
}

TEST_F(Boundary, NetworkTextCannotForgeTheServiceLog) {
  auto s = command("x\n\x1b[2Jaudit: FORGED command from nobody", CommandKind::GetSerial);
  s.bus = "s\naudit: FORGED";
  peer_.send(s);
  peer_.replies("x\n", 1);
  EXPECT_EQ(one_reply(command("log-after", CommandKind::GetSerial)).result(), pmu::v5::COMPLETED);
  const std::string log = service_.log();
  EXPECT_NE(log.find("x\\x0A\\x1B[2Jaudit: FORGED command from nobody"), std::string::npos) << log;
  std::istringstream lines(log);
  std::string line;
  const std::regex logger_began(R"(^\d{4}-\d\d-\d\d \d\d:\d\d:\d\d)");  // the console pattern's time
  while (std::getline(lines, line)) {
    EXPECT_TRUE(std::regex_search(line, logger_began)) << "a line the logger did not begin: " << line;
    EXPECT_EQ(line.find('\x1b'), std::string::npos) << line;
  }
}

TEST_F(Boundary, DuplicatesAreKnownPerSenderAndAReusedIdIsRejected) {
  // The same command twice: answered twice, executed once (the audit trail says so).
  const auto first = set("dup-1", "avionics_voltage", 20.0);
  peer_.send(first);
  peer_.send(first);
  const auto both = peer_.replies("dup-1", 2);
  ASSERT_EQ(both.size(), 2u);
  EXPECT_EQ(both[0].result(), pmu::v5::COMPLETED);
  EXPECT_EQ(both[1].result(), pmu::v5::COMPLETED);
  // The same id with other content from the same sender: rejected, not the old reply.
  const auto reused = one_reply(set("dup-1", "avionics_voltage", 16.5));
  EXPECT_EQ(reused.result(), pmu::v5::REJECTED);
  EXPECT_NE(reused.reason().to_string().find("was already used by this sender for another command"), std::string::npos)
      << reused.reason().to_string();
  // The same id from another sender: its own command, executed.
  Peer other(domain_, "other-ground-station");
  ASSERT_TRUE(other.wait_answered("probe-other"));
  other.send(set("dup-1", "avionics_voltage", 16.5));
  const auto theirs = other.replies("dup-1", 1);
  ASSERT_EQ(theirs.size(), 1u);
  EXPECT_EQ(theirs[0].result(), pmu::v5::COMPLETED) << theirs[0].reason().to_string();
  EXPECT_DOUBLE_EQ(theirs[0].value(), 16.5);

  // The audit lines reach the log file after the replies: wait until both executions and the
  // duplicate are there (or 10 s pass, and the assertions below say what is missing).
  std::string log;
  std::size_t executed = 0;
  pmu::test::wait_until(
      [&] {
        log = service_.log();
        executed = 0;
        for (std::size_t pos = 0; (pos = log.find("audit: command dup-1 from", pos)) != std::string::npos; ++pos)
          executed += log.find("-> COMPLETED", pos) < log.find('\n', pos) ? 1u : 0u;
        return executed >= 2 && log.find("audit: duplicate command dup-1") != std::string::npos;
      },
      10s, 20ms);
  EXPECT_EQ(executed, 2u) << log;  // once for each sender
  EXPECT_NE(log.find("audit: duplicate command dup-1"), std::string::npos) << log;
}

// A payload that is not a pmu::v5::Command (a look-alike type of the same name with another
// layout, a truncated one, another encapsulation) cannot be answered: dropped and counted.
class RawCommandType final : public TopicDataType {
 public:
  RawCommandType() {
    setName("pmu::v5::Command");
    m_typeSize = 4096;
    m_isGetKeyDefined = false;
  }
  bool serialize(void* data, eprosima::fastrtps::rtps::SerializedPayload_t* payload) override {
    const auto& bytes = *static_cast<std::vector<std::uint8_t>*>(data);
    std::memcpy(payload->data, bytes.data(), bytes.size());
    payload->length = static_cast<std::uint32_t>(bytes.size());
    return true;
  }
  bool deserialize(eprosima::fastrtps::rtps::SerializedPayload_t*, void*) override { return false; }
  std::function<uint32_t()> getSerializedSizeProvider(void* data) override {
    return [data] { return static_cast<uint32_t>(static_cast<std::vector<std::uint8_t>*>(data)->size()); };
  }
  void* createData() override { return new std::vector<std::uint8_t>(); }
  void deleteData(void* data) override { delete static_cast<std::vector<std::uint8_t>*>(data); }
  bool getKey(void*, eprosima::fastrtps::rtps::InstanceHandle_t*, bool) override { return false; }
};

TEST_F(Boundary, ALookAlikeTypeOrGarbageIsDroppedNeverFatal) {
  dds::DdsContext raw(domain_, "", "look-alike");
  DataWriter& w = raw.writer(raw.topic(topics::kCommand, TypeSupport(new RawCommandType())), qos_profiles::kCommand);
  pmu::test::wait_until(
      [&] {
        PublicationMatchedStatus p;
        w.get_publication_matched_status(p);
        return p.current_count > 0;
      },
      5s);
  // The fields of pmu::v5::Command in another order: kind and address first, then the strings.
  std::vector<std::uint8_t> reordered = {0,
                                         1,
                                         0,
                                         0,
                                         /*kind*/ 7,
                                         0,
                                         0,
                                         0,
                                         /*address*/ 1,
                                         0,
                                         0,
                                         0,
                                         /*string length 1000*/ 0xE8,
                                         0x03,
                                         0,
                                         0,
                                         'x',
                                         0};
  const auto valid = write_command_cdr(command("raw-valid", CommandKind::GetSerial));
  std::vector<std::uint8_t> truncated(valid.begin(), valid.begin() + 20);
  std::vector<std::uint8_t> xcdr2 = valid;
  xcdr2[1] = 0x07;  // CDR2 little-endian: not what pmu::v5::Command's readers speak
  std::vector<std::uint8_t> bool_two = write_command_cdr(command("raw-bool", CommandKind::EngineStart));
  bool_two.back() = 2;  // confirm = 2, which aborted the service before
  for (auto* bytes : {&reordered, &truncated, &xcdr2, &bool_two}) ASSERT_TRUE(w.write(bytes));
  w.wait_for_acknowledgments(eprosima::fastrtps::Duration_t(5, 0));

  const auto r = peer_.replies("raw-bool", 1);
  ASSERT_EQ(r.size(), 1u);
  EXPECT_EQ(r[0].result(), pmu::v5::REJECTED);
  EXPECT_EQ(one_reply(command("raw-after", CommandKind::GetSerial)).result(), pmu::v5::COMPLETED);
  ASSERT_TRUE(service_.alive());
  const std::string log = service_.log();
  EXPECT_NE(log.find("pmu/command: dropped"), std::string::npos) << log;
}

// Every peer sends `per_peer` commands as fast as it can, reading replies as it goes (as a
// client does: a reader's history holds the command profile's depth, not the whole burst).
// Half-way through, peer 0 sends ENGINE_STOP: it goes ahead of the device's queue, so its
// reply comes before the burst's last one. KEEP_LAST is no promise under load (a reply a slow
// reader has not acknowledged when 4,096 newer ones are written is gone), so a client does
// what the contract allows (interface.md 2.4): it resends, with the same id, a request that
// got no reply, and the service answers it again without executing it twice. Every id must
// be answered, and the audit trail must show each executed exactly once.
void burst(Service& service, std::vector<Peer*> peers, int per_peer) {
  std::vector<std::map<std::string, std::set<int>>> results(peers.size());  // id -> results seen
  std::vector<std::map<std::string, std::string>> refusals(peers.size());   // id -> reason of one not COMPLETED
  std::vector<std::thread> clients;
  for (std::size_t p = 0; p < peers.size(); ++p)
    clients.emplace_back([&, p] {
      Peer& peer = *peers[p];
      const std::string prefix = "b" + std::to_string(p) + "-";
      std::map<std::string, CommandSample> sent;
      for (int i = 0; i < per_peer; ++i) {
        auto c = command(prefix + std::to_string(i), i % 3 ? CommandKind::GetSerial : CommandKind::GetFirmware,
                         static_cast<std::uint16_t>(1 + i % 2));
        peer.send(c);
        sent.emplace(c.request_id, c);
        if (p == 0 && i == per_peer / 2) {
          const auto stop = command("stop-in-burst", CommandKind::EngineStop);
          peer.send(stop);
          sent.emplace(stop.request_id, stop);
        }
        if (i % 50 == 49) (void)peer.received();
      }
      for (const auto end = Clock::now() + 120s; Clock::now() < end;) {
        (void)peer.replies(prefix, static_cast<std::size_t>(per_peer), 2s);  // waits for the burst's
        for (const auto& r : peer.replies("", 0, 0s)) {                      // then takes them all
          const auto id = r.request_id().to_string();
          if (!sent.count(id)) continue;
          results[p][id].insert(static_cast<int>(r.result()));
          if (r.result() != pmu::v5::COMPLETED) refusals[p][id] = r.reason().to_string();
        }
        if (results[p].size() == sent.size()) break;
        for (const auto& [id, c] : sent)
          if (!results[p].count(id)) peer.send(c);
      }
    });
  for (auto& t : clients) t.join();
  const std::string log = service.log();
  // Every peer resends what it has not seen answered, as a client must: its reader sees every
  // client's replies, and on a loaded machine a peer that reads late can lose some from its
  // history (KEEP_LAST 4096); the service answers a resend again and never executes it twice.
  for (std::size_t p = 0; p < peers.size(); ++p) {
    const std::size_t ids = static_cast<std::size_t>(per_peer) + (p == 0 ? 1 : 0);  // + the stop
    EXPECT_EQ(results[p].size(), ids) << "peer " << p << ": ids answered";
    for (const auto& [id, seen] : results[p])
      EXPECT_EQ(seen, std::set<int>{pmu::v5::COMPLETED}) << id << ": " << refusals[p][id];
    std::size_t executed = 0;
    const std::string audit = "audit: command b" + std::to_string(p) + "-";
    for (auto at = log.find(audit); at != std::string::npos; at = log.find(audit, at + 1)) ++executed;
    EXPECT_EQ(executed, static_cast<std::size_t>(per_peer)) << "peer " << p << ": commands executed";
  }
  // ENGINE_STOP jumps the queue: the service executed it, once, before the last command of
  // the burst it was sent in the middle of (the audit trail is in execution order).
  const auto stop_at = log.find("audit: command stop-in-burst");
  ASSERT_NE(stop_at, std::string::npos) << "ENGINE_STOP was never executed";
  EXPECT_EQ(log.find("audit: command stop-in-burst", stop_at + 1), std::string::npos) << "ENGINE_STOP ran twice";
  EXPECT_LT(stop_at, log.rfind("audit: command b0-")) << "ENGINE_STOP was executed only after the burst";
  EXPECT_TRUE(service.alive());
}

TEST_F(Boundary, ABurstOf2000FromOneWriterIsAnsweredInFull) { burst(service_, {&peer_}, 2000); }

TEST_F(Boundary, BurstsOf2000FromFourWritersAtOnceAreAnsweredInFull) {
  Peer b(domain_, "ground-b"), c(domain_, "ground-c"), d(domain_, "ground-d");
  for (auto* p : {&b, &c, &d}) ASSERT_TRUE(p->wait_answered("probe"));
  burst(service_, {&peer_, &b, &c, &d}, 2000);
}

TEST_F(Boundary, FiftyThousandDistinctIdsAreAllAnsweredWithBoundedMemory) {
  const long before = service_.rss_kib();
  constexpr int kIds = 50000;
  for (int i = 0; i < kIds; ++i) {
    auto s = command("m-" + std::to_string(i), CommandKind::GetSerial);
    s.bus = "nowhere";  // answered at once: what is measured is what the service remembers
    peer_.send(s);
    if (i % 1000 == 999) {
      peer_.settle();
      (void)peer_.received();  // read as a client does: the reader holds 4096 replies
    }
  }
  const auto got = peer_.replies("m-", kIds, 120s);
  EXPECT_EQ(got.size(), static_cast<std::size_t>(kIds));
  const long after = service_.rss_kib();
  // At most 16,384 ids are remembered (CommandService); each costs well under 1 KiB.
  std::printf("service RSS before %ld KiB, after 50,000 ids %ld KiB\n", before, after);
  EXPECT_LT(after - before, 32 * 1024) << "remembered ids are not bounded";
}

// The readers of pmuctl (and any reader built on Guarded) survive what killed the service: a
// CommandReply whose has_value byte is 2 makes the generated deserialize throw.
TEST(GuardedType, AMalformedBooleanIsCountedNotThrown) {
  pmu::v5::CommandReply reply;
  reply.request_id("r");
  reply.bus("b");
  reply.has_value(true);
  pmu::v5::CommandReplyPubSubType plain;
  eprosima::fastrtps::rtps::SerializedPayload_t payload(1024);
  ASSERT_TRUE(plain.serialize(&reply, &payload));
  // Body offsets (after the 4-byte encapsulation): "r" 0..5, vehicle "" 8..12, "b" 16..21,
  // address 22, kind 24, result 28, reason "" 32..36, has_value 37.
  ASSERT_EQ(payload.data[4 + 37], 1);
  payload.data[4 + 37] = 2;
  pmu::v5::CommandReply out;
  EXPECT_ANY_THROW(plain.deserialize(&payload, &out));  // what the service and pmuctl met

  pmu::idl::Guarded<pmu::v5::CommandReplyPubSubType> guarded;
  bool ok = true;
  EXPECT_NO_THROW(ok = guarded.deserialize(&payload, &out));
  EXPECT_FALSE(ok);
  EXPECT_EQ(guarded.malformed(), 1u);
  EXPECT_TRUE(out.request_id().to_string().empty());  // reset, not half-filled

  payload.data[4 + 37] = 1;
  EXPECT_TRUE(guarded.deserialize(&payload, &out));
  EXPECT_EQ(out.request_id().to_string(), "r");
  EXPECT_EQ(guarded.malformed(), 1u);
}

}  // namespace
}  // namespace pmu::service
