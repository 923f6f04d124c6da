// cyclone_client: a mission computer and ground station in one, on Eclipse Cyclone DDS's C
// API (not Fast DDS), written against interface.md alone: the contract's topic names, type
// names and QoS. Started after pmu-service is up (a late joiner), it checks that
//   - every topic delivers a sample of the device (telemetry within --telemetry-ms),
//   - pmu/config, pmu/info, pmu/health and pmu/readiness arrive within --state-ms of matching their writer,
//   - each command sent right after matching gets exactly one final reply (request id);
//     one unanswered after --resend-ms is sent again with the same id (see below).
// Prints one line per check ("ok ..." or "MISS ..."), then a "summary" line of key=value
// figures (tests/cyclone/measure_repair.sh reads them). Exit status: 0 nothing missed,
// 1 something missed, 2 bad usage or no DDS.
//
// With --canopen-bus NAME it checks the batteries and MPPTs instead (interface.md 1.4):
// pmu/battery, pmu/battery_cells and pmu/mppt deliver the values tests/cyclone/canopen_feeder.py
// puts on that bus (NaN and the `received` bits for what it never sends), and pmu/health
// has the battery and the MPPT as instances of their own kind.
#include <dds/dds.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <cmath>

#include "alarms.h"
#include "canopen.h"
#include "command.h"
#include "state.h"
#include "telemetry.h"

namespace {

using Clock = std::chrono::steady_clock;
using std::chrono::milliseconds;

// interface.md: sized like pmuctl for a fleet of 64 services x 256 PMUs (deploy/qos.xml).
constexpr int32_t kFleetInstances = 64 * 256;
// The command profile's depth: a burst of several hundred commands does not overflow it.
constexpr int32_t kCommandDepth = 4096;

struct Options {
  uint32_t domain = 0;
  std::string bus = "sim0";
  uint16_t address = 1;
  long state_ms = 1000;
  long telemetry_ms = 5000;
  long reply_ms = 5000;
  long command_delay_ms = -1;  // after the client's start; -1: right after matching
  long resend_ms = 1000;       // resend a request (same id) unanswered this long; 0: never
  std::string canopen_bus;     // non-empty: check batteries and MPPTs on this bus instead
};

[[noreturn]] void usage(const char* why) {
  std::fprintf(stderr,
               "cyclone_client: %s\nusage: cyclone_client [--domain N] [--bus NAME] [--address N] [--state-ms MS] "
               "[--telemetry-ms MS] [--reply-ms MS] [--command-delay-ms MS] [--resend-ms MS] [--canopen-bus NAME]\n",
               why);
  std::exit(2);
}

long number(const char* option, const char* text, long lo, long hi) {
  char* end = nullptr;
  const long v = std::strtol(text, &end, 10);
  if (end == text || *end != '\0' || v < lo || v > hi)
    usage((std::string(option) + " " + text + ": expected an integer " + std::to_string(lo) + ".." + std::to_string(hi))
              .c_str());
  return v;
}

Options parse(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; i += 2) {
    if (i + 1 >= argc) usage((std::string(argv[i]) + " needs a value").c_str());
    const std::string k = argv[i];
    const char* v = argv[i + 1];
    if (k == "--domain")
      o.domain = static_cast<uint32_t>(number("--domain", v, 0, 232));
    else if (k == "--bus")
      o.bus = v;
    else if (k == "--address")
      o.address = static_cast<uint16_t>(number("--address", v, 0, 65534));
    else if (k == "--state-ms")
      o.state_ms = number("--state-ms", v, 1, 600000);
    else if (k == "--telemetry-ms")
      o.telemetry_ms = number("--telemetry-ms", v, 1, 600000);
    else if (k == "--reply-ms")
      o.reply_ms = number("--reply-ms", v, 1, 600000);
    else if (k == "--command-delay-ms")
      o.command_delay_ms = number("--command-delay-ms", v, 0, 600000);
    else if (k == "--resend-ms")
      o.resend_ms = number("--resend-ms", v, 0, 600000);
    else if (k == "--canopen-bus")
      o.canopen_bus = v;
    else
      usage(("unknown option " + k).c_str());
  }
  if (o.bus.empty() || o.bus.size() > 15) usage("--bus must be 1..15 characters");
  return o;
}

// Fast DDS 2.9 offers and accepts XCDR (version 1) only. Cyclone 0.10 picks its writers'
// representation from the type, and says so in discovery; pinning XCDR1 on every endpoint
// keeps a future idlc default (XCDR2 for appendable types) from failing the match silently.
void xcdr1(dds_qos_t* q) {
  const dds_data_representation_id_t r[] = {DDS_DATA_REPRESENTATION_XCDR1};
  dds_qset_data_representation(q, 1, r);
}

// Profile `telemetry` (reader side).
dds_qos_t* telemetry_qos() {
  dds_qos_t* q = dds_create_qos();
  dds_qset_reliability(q, DDS_RELIABILITY_BEST_EFFORT, 0);
  dds_qset_durability(q, DDS_DURABILITY_VOLATILE);
  dds_qset_history(q, DDS_HISTORY_KEEP_LAST, 1);
  dds_qset_resource_limits(q, kFleetInstances, kFleetInstances, 1);
  xcdr1(q);
  return q;
}

// Profile `state` (reader side).
dds_qos_t* state_qos() {
  dds_qos_t* q = dds_create_qos();
  dds_qset_reliability(q, DDS_RELIABILITY_RELIABLE, DDS_MSECS(100));
  dds_qset_durability(q, DDS_DURABILITY_TRANSIENT_LOCAL);
  dds_qset_history(q, DDS_HISTORY_KEEP_LAST, 1);
  dds_qset_resource_limits(q, kFleetInstances, kFleetInstances, 1);
  xcdr1(q);
  return q;
}

// Profile `command`, both sides; LIFESPAN on requests so an old one is never executed.
dds_qos_t* command_qos(bool writer) {
  dds_qos_t* q = dds_create_qos();
  dds_qset_reliability(q, DDS_RELIABILITY_RELIABLE, DDS_MSECS(100));
  dds_qset_durability(q, DDS_DURABILITY_VOLATILE);
  dds_qset_history(q, DDS_HISTORY_KEEP_LAST, kCommandDepth);
  dds_qset_resource_limits(q, kCommandDepth, 1, kCommandDepth);
  if (writer) dds_qset_lifespan(q, DDS_SECS(10));
  xcdr1(q);
  return q;
}

class Participant {
 public:
  explicit Participant(uint32_t domain) : pp_(dds_create_participant(domain, nullptr, nullptr)) {}
  ~Participant() {
    if (pp_ > 0) dds_delete(pp_);
  }
  Participant(const Participant&) = delete;
  Participant& operator=(const Participant&) = delete;
  dds_entity_t get() const { return pp_; }

 private:
  dds_entity_t pp_;
};

dds_entity_t entity(dds_entity_t e, const char* what) {
  if (e < 0) {
    std::fprintf(stderr, "cyclone_client: cannot create %s: %s\n", what, dds_strretcode(e));
    std::exit(2);
  }
  return e;
}

dds_entity_t reader(dds_entity_t pp, const dds_topic_descriptor_t* type, const char* name, dds_qos_t* qos) {
  const dds_entity_t topic = entity(dds_create_topic(pp, type, name, nullptr, nullptr), name);
  const dds_entity_t r = entity(dds_create_reader(pp, topic, qos, nullptr), name);
  dds_delete_qos(qos);
  return r;
}

bool reader_matched(dds_entity_t r) {
  dds_subscription_matched_status_t st{};
  return dds_get_subscription_matched_status(r, &st) == DDS_RETCODE_OK && st.current_count > 0;
}

bool writer_matched(dds_entity_t w) {
  dds_publication_matched_status_t st{};
  return dds_get_publication_matched_status(w, &st) == DDS_RETCODE_OK && st.current_count > 0;
}

// Takes every sample and calls fn(sample) for the valid ones.
template <class T, class Fn>
void take_all(dds_entity_t r, Fn fn) {
  void* samples[64] = {nullptr};
  dds_sample_info_t infos[64];
  for (;;) {
    const dds_return_t n = dds_take(r, samples, infos, 64, 64);
    if (n <= 0) return;
    for (dds_return_t i = 0; i < n; ++i)
      if (infos[i].valid_data) fn(*static_cast<const T*>(samples[i]));
    dds_return_loan(r, samples, n);
  }
}

struct Topic {
  explicit Topic(const char* n) : name(n) {}
  const char* name;
  dds_entity_t reader = 0;
  std::optional<Clock::time_point> matched;
  std::optional<Clock::time_point> received;
};

struct Request {
  Request(std::string i, const char* w, pmu_v5_CommandKind k, const char* p, double v)
      : id(std::move(i)), what(w), kind(k), parameter(p), value(v) {}
  std::string id;
  const char* what;
  pmu_v5_CommandKind kind;
  const char* parameter;
  double value;
  Clock::time_point sent{};  // first sent
  Clock::time_point last_sent{};
  int sends = 0;
  int finals = 0;
  std::optional<Clock::time_point> first_final;
  std::string result;
};

const char* result_name(pmu_v5_CommandResult r) {
  static const char* const names[] = {"COMPLETED", "REJECTED", "DENIED",     "UNSUPPORTED",
                                      "TIMEOUT",   "FAILED",   "IN_PROGRESS"};
  const auto i = static_cast<std::size_t>(r);
  return i < sizeof names / sizeof names[0] ? names[i] : "UNKNOWN";
}

template <std::size_t N>
void copy(char (&dst)[N], const std::string& s) {
  std::snprintf(dst, N, "%s", s.c_str());
}

long ms(Clock::duration d) { return static_cast<long>(std::chrono::duration_cast<milliseconds>(d).count()); }

// What canopen_feeder.py sends, read back as the contract says it arrives.
struct CanOpenCheck {
  const char* what;
  bool done = false;
  std::string detail = "no sample";
};

bool near(float a, double b) { return std::fabs(static_cast<double>(a) - b) < 1e-3; }

int run_canopen(const Options& o, dds_entity_t pp) {
  const dds_entity_t battery = reader(pp, &pmu_v5_Battery_desc, "pmu/battery", telemetry_qos());
  const dds_entity_t cells = reader(pp, &pmu_v5_BatteryCells_desc, "pmu/battery_cells", telemetry_qos());
  const dds_entity_t mppt = reader(pp, &pmu_v5_Mppt_desc, "pmu/mppt", telemetry_qos());
  const dds_entity_t health = reader(pp, &pmu_v5_Health_desc, "pmu/health", state_qos());
  CanOpenCheck checks[] = {
      {"pmu/battery"}, {"pmu/battery_cells"}, {"pmu/mppt"}, {"pmu/health battery"}, {"pmu/health mppt"}};
  const auto until = Clock::now() + milliseconds(o.telemetry_ms);
  auto all = [&] {
    for (const auto& c : checks)
      if (!c.done) return false;
    return true;
  };
  while (!all() && Clock::now() < until) {
    take_all<pmu_v5_Battery>(battery, [&](const pmu_v5_Battery& s) {
      if (o.canopen_bus != s.bus || s.node != 2) return;
      // voltage (bit 0), state_of_charge (4), bms_state (10), power_level (15); current never sent.
      const uint32_t want = (1u << 0) | (1u << 4) | (1u << 10) | (1u << 15);
      if (s.received != want) {
        checks[0].detail = "received " + std::to_string(s.received) + ", want " + std::to_string(want);
        return;
      }
      const bool ok = near(s.voltage, 48.123) && near(s.state_of_charge, 87) && s.bms_state == double{0x12345678u} &&
                      near(s.power_level, 77) && std::isnan(s.current);
      checks[0].done = ok;
      checks[0].detail =
          ok ? "voltage 48.123, state_of_charge 87, bms_state 0x12345678, power_level 77, current NaN" : "wrong values";
    });
    take_all<pmu_v5_BatteryCells>(cells, [&](const pmu_v5_BatteryCells& s) {
      if (o.canopen_bus != s.bus || s.node != 2 || s.cells._length != 1) return;
      const bool ok = s.cells._buffer[0].cell == 5 && near(s.cells._buffer[0].cell_voltage, 3.301);
      checks[1].done = ok;
      checks[1].detail = ok ? "cell 5 at 3.301 V" : "wrong cell";
    });
    take_all<pmu_v5_Mppt>(mppt, [&](const pmu_v5_Mppt& s) {
      if (o.canopen_bus != s.bus || s.device != 4) return;
      const uint32_t want = (1u << 0) | (1u << 4) | (1u << 13);
      if (s.received != want) return;
      const bool ok = near(s.voltage_output_raw, -100) && s.safety_enabled == 1.0f && near(s.duty_cycle_panel_2, 45) &&
                      std::isnan(s.current_output_raw) && std::isnan(s.pwm_enabled);
      checks[2].done = ok;
      checks[2].detail =
          ok ? "voltage_output_raw -100, safety_enabled 1, duty_cycle_panel_2 45, pwm_enabled NaN" : "wrong values";
    });
    take_all<pmu_v5_Health>(health, [&](const pmu_v5_Health& s) {
      if (o.canopen_bus != s.bus || s.state != pmu_v5_ONLINE) return;
      if (s.kind == pmu_v5_KIND_BATTERY && s.address == 2) checks[3] = {"pmu/health battery", true, "node 2 ONLINE"};
      if (s.kind == pmu_v5_KIND_MPPT && s.address == 4) checks[4] = {"pmu/health mppt", true, "device 4 ONLINE"};
    });
    std::this_thread::sleep_for(milliseconds(5));
  }
  int misses = 0;
  for (const auto& c : checks) {
    misses += c.done ? 0 : 1;
    std::printf("%s %s: %s\n", c.done ? "ok" : "MISS", c.what, c.detail.c_str());
  }
  std::printf("summary misses=%d\n", misses);
  return misses == 0 ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  const Options o = parse(argc, argv);
  const auto t0 = Clock::now();
  Participant pp(o.domain);
  if (pp.get() < 0) {
    std::fprintf(stderr, "cyclone_client: cannot create a participant on domain %u: %s\n", o.domain,
                 dds_strretcode(pp.get()));
    return 2;
  }
  if (!o.canopen_bus.empty()) return run_canopen(o, pp.get());
  std::vector<Topic> telemetry = {Topic("pmu/voltages"), Topic("pmu/currents"), Topic("pmu/battery_energy"),
                                  Topic("pmu/temperatures"), Topic("pmu/status")};
  std::vector<Topic> state = {Topic("pmu/config"), Topic("pmu/info"), Topic("pmu/health"), Topic("pmu/readiness")};
  const dds_topic_descriptor_t* telemetry_types[] = {&pmu_v5_Voltages_desc, &pmu_v5_Currents_desc,
                                                     &pmu_v5_BatteryEnergy_desc, &pmu_v5_Temperatures_desc,
                                                     &pmu_v5_Status_desc};
  const dds_topic_descriptor_t* state_types[] = {&pmu_v5_Config_desc, &pmu_v5_DeviceInfo_desc, &pmu_v5_Health_desc,
                                                 &pmu_v5_Readiness_desc};
  for (std::size_t i = 0; i < state.size(); ++i)
    state[i].reader = reader(pp.get(), state_types[i], state[i].name, state_qos());
  for (std::size_t i = 0; i < telemetry.size(); ++i)
    telemetry[i].reader = reader(pp.get(), telemetry_types[i], telemetry[i].name, telemetry_qos());
  const dds_entity_t replies = reader(pp.get(), &pmu_v5_CommandReply_desc, "pmu/command_reply", command_qos(false));
  const dds_entity_t command_topic =
      entity(dds_create_topic(pp.get(), &pmu_v5_Command_desc, "pmu/command", nullptr, nullptr), "pmu/command");
  dds_qos_t* wq = command_qos(true);
  const dds_entity_t commands = entity(dds_create_writer(pp.get(), command_topic, wq, nullptr), "the command writer");
  dds_delete_qos(wq);

  const std::string id_prefix = "cyclone-" + std::to_string(::getpid()) + "-";
  std::vector<Request> requests = {
      Request(id_prefix + "1", "GET avionics_voltage", pmu_v5_GET, "avionics_voltage", 0.0),
      Request(id_prefix + "2", "SET_PARAMETER avionics_voltage 24.0", pmu_v5_SET_PARAMETER, "avionics_voltage", 24.0),
      Request(id_prefix + "3", "GET_FIRMWARE", pmu_v5_GET_FIRMWARE, "", 0.0),
  };
  std::optional<Clock::time_point> command_match, sent_at;

  auto is_ours = [&](const char* bus, uint16_t address) { return o.bus == bus && o.address == address; };
  auto mark = [&](Topic& t, const char* bus, uint16_t address) {
    if (!t.received && is_ours(bus, address)) t.received = Clock::now();
  };
  auto all_done = [&] {
    for (const auto& t : state)
      if (!t.received) return false;
    for (const auto& t : telemetry)
      if (!t.received) return false;
    for (const auto& r : requests)
      if (r.finals == 0) return false;
    return true;
  };

  auto send = [&](Request& r) {
    pmu_v5_Command c{};
    copy(c.request_id, r.id);
    copy(c.bus, o.bus);
    c.address = o.address;
    c.kind = r.kind;
    copy(c.parameter, r.parameter);
    c.value = r.value;
    r.last_sent = Clock::now();
    if (r.sends++ == 0) r.sent = r.last_sent;
    const dds_return_t rc = dds_write(commands, &c);
    if (rc != DDS_RETCODE_OK) std::printf("MISS write %s: %s\n", r.what, dds_strretcode(rc));
  };
  // Stop waiting for what is past its limit: a miss is a miss, however late it would come.
  constexpr milliseconds kMatchLimit{10000};
  auto settled = [&](Clock::time_point now) {
    for (auto* group : {&state, &telemetry})
      for (const auto& t : *group) {
        const long limit = group == &state ? o.state_ms : o.telemetry_ms;
        const auto from = group == &state && t.matched ? *t.matched : t0;
        if (!t.received && now - from <= milliseconds(limit) + (t.matched ? milliseconds(0) : kMatchLimit))
          return false;
      }
    if (!sent_at) return now - t0 > kMatchLimit + milliseconds(std::max(o.command_delay_ms, 0L));
    for (const auto& r : requests)
      if (r.finals == 0 && now - r.sent <= milliseconds(o.reply_ms)) return false;
    return true;
  };
  std::optional<Clock::time_point> done_at;
  for (;;) {
    const auto now = Clock::now();
    for (auto* group : {&state, &telemetry})
      for (auto& t : *group)
        if (!t.matched && reader_matched(t.reader)) t.matched = now;
    if (!command_match && writer_matched(commands) && reader_matched(replies)) command_match = now;
    const bool send_now = o.command_delay_ms < 0 ? command_match.has_value()
                                                 : command_match && now - t0 >= milliseconds(o.command_delay_ms);
    if (send_now && !sent_at) {
      sent_at = now;
      for (auto& r : requests) send(r);
    }
    // A volatile Cyclone reader skips for good a reply that its first accepted heartbeat
    // from the reply writer lists (deploy/README.md, "QoS: capacity and repair times"): a request still
    // unanswered is sent again with the same id, which the service answers again and never
    // executes twice (interface.md).
    for (auto& r : requests)
      if (sent_at && o.resend_ms > 0 && r.finals == 0 && now - r.last_sent >= milliseconds(o.resend_ms) &&
          now - r.sent < milliseconds(o.reply_ms))
        send(r);
    take_all<pmu_v5_Config>(state[0].reader, [&](const pmu_v5_Config& s) { mark(state[0], s.bus, s.address); });
    take_all<pmu_v5_DeviceInfo>(state[1].reader, [&](const pmu_v5_DeviceInfo& s) { mark(state[1], s.bus, s.address); });
    take_all<pmu_v5_Health>(state[2].reader, [&](const pmu_v5_Health& s) { mark(state[2], s.bus, s.address); });
    // One instance per vehicle: any sample with its reasons decoded counts (a sequence of
    // structs with bounded strings, the contract's deepest type).
    take_all<pmu_v5_Readiness>(state[3].reader, [&](const pmu_v5_Readiness& s) {
      if (!state[3].received && s.reasons._length <= 64 && s.reasons_total >= s.reasons._length)
        state[3].received = Clock::now();
    });
    take_all<pmu_v5_Voltages>(telemetry[0].reader,
                              [&](const pmu_v5_Voltages& s) { mark(telemetry[0], s.bus, s.address); });
    take_all<pmu_v5_Currents>(telemetry[1].reader,
                              [&](const pmu_v5_Currents& s) { mark(telemetry[1], s.bus, s.address); });
    take_all<pmu_v5_BatteryEnergy>(telemetry[2].reader,
                                   [&](const pmu_v5_BatteryEnergy& s) { mark(telemetry[2], s.bus, s.address); });
    take_all<pmu_v5_Temperatures>(telemetry[3].reader,
                                  [&](const pmu_v5_Temperatures& s) { mark(telemetry[3], s.bus, s.address); });
    take_all<pmu_v5_Status>(telemetry[4].reader, [&](const pmu_v5_Status& s) { mark(telemetry[4], s.bus, s.address); });
    take_all<pmu_v5_CommandReply>(replies, [&](const pmu_v5_CommandReply& s) {
      if (s.result == pmu_v5_IN_PROGRESS) return;
      for (auto& r : requests) {
        if (r.id != s.request_id) continue;  // another client's reply: every reply reader sees them
        if (++r.finals == 1) {
          r.first_final = Clock::now();
          r.result = result_name(s.result);
        }
      }
    });
    // Once everything is in, listen a little longer: a second final reply would be a bug.
    if (!done_at && (all_done() || settled(Clock::now()))) done_at = Clock::now();
    if (done_at && Clock::now() - *done_at > milliseconds(300)) break;
    std::this_thread::sleep_for(milliseconds(5));
  }

  int misses = 0;
  long state_worst = -1;
  for (const auto& t : state) {
    if (!t.matched) {
      std::printf("MISS %s: no writer matched\n", t.name);
      ++misses;
      continue;
    }
    if (!t.received) {
      std::printf("MISS %s: no sample of %s/%u\n", t.name, o.bus.c_str(), o.address);
      ++misses;
      continue;
    }
    const long after = ms(*t.received - *t.matched);
    state_worst = std::max(state_worst, after);
    const bool late = after > o.state_ms;
    misses += late ? 1 : 0;
    std::printf("%s %s: %ld ms after matching (%ld ms after start)%s\n", late ? "MISS" : "ok", t.name, after,
                ms(*t.received - t0), late ? " (late joiner limit exceeded)" : "");
  }
  for (const auto& t : telemetry) {
    const bool got = t.received && ms(*t.received - t0) <= o.telemetry_ms;
    misses += got ? 0 : 1;
    if (got)
      std::printf("ok %s: first sample %ld ms after start\n", t.name, ms(*t.received - t0));
    else
      std::printf("MISS %s: no sample of %s/%u within %ld ms\n", t.name, o.bus.c_str(), o.address, o.telemetry_ms);
  }
  int lost = 0, resent = 0;
  long reply_worst = -1;
  if (!sent_at) {
    std::printf("MISS commands: the service's command reader and reply writer never matched\n");
    ++misses;
    lost = static_cast<int>(requests.size());
  }
  for (const auto& r : requests) {
    if (!sent_at) break;
    if (r.finals == 0) {
      std::printf("MISS %s (%s): no final reply\n", r.what, r.id.c_str());
      ++misses;
      ++lost;
      continue;
    }
    const long after = ms(*r.first_final - r.sent);
    reply_worst = std::max(reply_worst, after);
    resent += r.sends > 1 ? 1 : 0;
    const bool bad = r.finals != 1 || after > o.reply_ms || r.result != "COMPLETED";
    misses += bad ? 1 : 0;
    std::printf("%s %s (%s): %s after %ld ms, %d final repl%s, sent %d time(s)\n", bad ? "MISS" : "ok", r.what,
                r.id.c_str(), r.result.c_str(), after, r.finals, r.finals == 1 ? "y" : "ies", r.sends);
  }
  std::printf("summary misses=%d match_ms=%ld state_after_match_ms=%ld replies_lost=%d resent=%d reply_worst_ms=%ld\n",
              misses, command_match ? ms(*command_match - t0) : -1L, state_worst, lost, resent, reply_worst);
  return misses == 0 ? 0 : 1;
}
