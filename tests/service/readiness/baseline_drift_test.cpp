// A PMU watched against its baseline file (interface.md 1.7, 4.1), end to end in the service on
// the simulated bus with a fake clock: the bus worker reads the simulated unit, the readiness
// tracker compares, and pmu/readiness (here the recording sink) says config_differs or
// serial_differs until a verified set, a reconnect's re-read or another unit changes it.
#include <gtest/gtest.h>
#include <spdlog/sinks/ostream_sink.h>
#include <spdlog/spdlog.h>

#include <sstream>

#include "support/harness.hpp"
#include "pmu/baseline/config_file.hpp"
#include "pmu/codec/encode.hpp"
#include "pmu/dispatch/command_service.hpp"
#include "pmu/readiness/readiness_tracker.hpp"

namespace pmu::service::test::baseline_drift {
namespace {

// What the service logs while it lives, instead of the console.
class LogText {
 public:
  LogText() : previous_(spdlog::default_logger()) {
    spdlog::set_default_logger(
        std::make_shared<spdlog::logger>("drift-test", std::make_shared<spdlog::sinks::ostream_sink_mt>(out_)));
  }
  ~LogText() { spdlog::set_default_logger(previous_); }
  LogText(const LogText&) = delete;
  LogText& operator=(const LogText&) = delete;
  std::string text() const { return out_.str(); }
  std::size_t count(const std::string& what) const {
    const std::string t = out_.str();
    std::size_t n = 0;
    for (auto at = t.find(what); at != std::string::npos; at = t.find(what, at + 1)) ++n;
    return n;
  }

 private:
  std::ostringstream out_;
  std::shared_ptr<spdlog::logger> previous_;
};

// The simulated PMU 1 (serial 4001, factory values: V_A 12.0 V ...) on sim0, configured with
// the baseline `text`; the readiness tracker between the bus worker and the recording sink,
// and a command service to set values as an operator would.
class Watched {
 public:
  explicit Watched(const std::string& text)
      : bus_(bus_with(text)),
        tracker(bus_.buses, Timeouts{}.stale_periods, sink, tracker_clock),
        h(bus_.buses[0], {pmu(1)}, Timeouts{}, &tracker),
        commands({&h.worker()}, PolicyConfig{}, Timeouts{}, h.clock(),
                 [this](const CommandReplyData& r) { replies.push_back(r); }) {}

  // The reasons of PMU 1, by code.
  std::vector<std::string> codes() const {
    std::vector<std::string> out;
    for (const auto& r : tracker.current().reasons)
      if (r.device == 1 && r.source == alarms::DeviceKind::Pmu) out.push_back(r.code);
    return out;
  }
  const ReadinessReason* reason(const std::string& code) const {
    static thread_local ReadinessReport kept;
    kept = tracker.current();
    for (const auto& r : kept.reasons)
      if (r.code == code) return &r;
    return nullptr;
  }
  // An operator's verified set; runs the bus until its reply.
  CommandReplyData set(const char* parameter, double value) {
    CommandSample s;
    s.request_id = "drift-" + std::to_string(++next_id_);
    s.sender = "test";
    s.bus = "sim0";
    s.address = 1;
    s.kind = static_cast<std::uint32_t>(CommandKind::SetParameter);
    s.parameter = parameter;
    s.value = value;
    const auto before = replies.size();
    commands.submit(s);
    for (int i = 0; i < 500 && replies.size() == before; ++i) h.run_for(10ms);
    return replies.size() > before ? replies.back() : CommandReplyData{};
  }
  void silent(bool off) {
    h.pmus().with_model(1, [off](sim::PmuModel& m) {
      auto f = m.faults();
      f.silent = off;
      m.set_faults(f);
    });
  }

 private:
  struct Buses {
    std::vector<BusConfig> buses;
  };
  static Buses bus_with(const std::string& text) {
    auto file = baseline::read_config_file(text);
    EXPECT_TRUE(file.ok()) << (file.ok() ? "" : file.error().message);
    DeviceConfig d = device(1);
    if (file.ok()) d.baseline = *file;
    d.baseline_file = "pmu1.yaml";
    d.baseline_path = "/etc/pmu-dds/pmu1.yaml";
    return {{sim_bus({d})}};
  }
  Buses bus_;
  int next_id_ = 0;

 public:
  transport::ManualClock tracker_clock;
  RecordingSink sink;
  ReadinessTracker tracker;
  Harness h;
  std::vector<CommandReplyData> replies;
  CommandService commands;
};

// Read, and its first streamed packets heard (one period, 1 s): until then its alarms see
// nothing and input_missing is a reason of its own.
constexpr auto kFirstPackets = 1500ms;

TEST(BaselineDrift, FoundAtStartAndGoneAfterASetThatMakesItMatch) {
  LogText log;
  Watched w("parameters:\n  avionics_voltage: 22.0\n  upper_temperature_limit: 80\n");
  w.h.run_for(kFirstPackets);
  ASSERT_TRUE(w.h.worker().session(1)->ready());
  EXPECT_EQ(w.codes(), std::vector<std::string>{"config_differs"});
  EXPECT_FALSE(w.tracker.current().ready);
  const auto* r = w.reason("config_differs");
  ASSERT_NE(r, nullptr);
  EXPECT_EQ(r->message, "config differs: avionics_voltage");
  EXPECT_EQ(r->bus, "sim0");
  EXPECT_EQ(r->description, "avionics_voltage 12.0 V->22.0 V. pmuctl config diff / apply pmu1.yaml");
  EXPECT_EQ(log.count("sim0/1: configuration differs from baseline /etc/pmu-dds/pmu1.yaml: avionics_voltage device "
                      "12.0 V, baseline 22.0 V"),
            1u)
      << log.text();

  // Telemetry and health every period: the verdict is not logged again while it holds.
  w.h.run_for(5000ms);
  EXPECT_EQ(log.count("configuration differs"), 1u) << log.text();

  const auto reply = w.set("avionics_voltage", 22.0);
  EXPECT_EQ(reply.result, CommandResult::Completed) << reply.reason;
  EXPECT_TRUE(w.codes().empty()) << "the verified set made it match";
  EXPECT_TRUE(w.tracker.current().ready);
  EXPECT_EQ(log.count("sim0/1: configuration matches baseline /etc/pmu-dds/pmu1.yaml again"), 1u) << log.text();

  // A set that leaves the file's values is drift again, logged once.
  EXPECT_EQ(w.set("upper_temperature_limit", 85).result, CommandResult::Completed);
  ASSERT_NE(w.reason("config_differs"), nullptr);
  EXPECT_EQ(w.reason("config_differs")->message, "config differs: upper_temperature_limit");
  EXPECT_EQ(log.count("configuration differs"), 2u) << log.text();
}

// Whoever changed the unit while the service did not hear it: the re-read after OFFLINE is
// compared again.
TEST(BaselineDrift, ComparedAgainAfterAReconnect) {
  LogText log;
  Watched w("parameters:\n  avionics_voltage: 12.0\n");
  w.h.run_for(kFirstPackets);
  EXPECT_TRUE(w.codes().empty());
  EXPECT_EQ(log.count("sim0/1: configuration matches baseline /etc/pmu-dds/pmu1.yaml"), 1u) << log.text();

  w.silent(true);
  w.h.run_for(12000ms);  // OFFLINE after 10 periods of 1 s
  EXPECT_NE(w.reason("device_not_online"), nullptr);
  EXPECT_EQ(w.reason("config_differs"), nullptr) << "what was read still matches";
  // Back, with another tool's set of V_A taken while the service did not listen.
  w.h.pmus().with_model(1, [&](sim::PmuModel& m) {
    auto f = m.faults();
    f.silent = false;
    m.set_faults(f);
    m.on_frame(*codec::encode_parameter_reply(codec::Parameter::AvionicsVoltage, 240, 1), w.h.clock().steady_now());
  });
  w.h.run_for(3000ms);
  ASSERT_NE(w.sink.last_health(1), nullptr);
  EXPECT_EQ(w.sink.last_health(1)->reconnects, 1u);
  EXPECT_EQ(w.reason("device_not_online"), nullptr);
  ASSERT_NE(w.reason("config_differs"), nullptr);
  EXPECT_EQ(w.reason("config_differs")->description,
            "avionics_voltage 24.0 V->12.0 V. pmuctl config diff / apply pmu1.yaml");
  EXPECT_EQ(log.count("configuration differs from baseline /etc/pmu-dds/pmu1.yaml: avionics_voltage device 24.0 V, "
                      "baseline 12.0 V"),
            1u)
      << log.text();
}

TEST(BaselineDrift, AnotherUnitsSerialIsSerialDiffers) {
  LogText log;
  Watched w("device:\n  serial: 1001\nparameters:\n  avionics_voltage: 12.0\n");
  w.h.run_for(kFirstPackets);
  EXPECT_EQ(w.codes(), std::vector<std::string>{"serial_differs"});
  ASSERT_NE(w.reason("serial_differs"), nullptr);
  EXPECT_EQ(w.reason("serial_differs")->message, "PMU 1 serial 4001, baseline 1001");
  EXPECT_EQ(log.count("sim0/1: PMU serial 4001 is not the serial 1001 of baseline /etc/pmu-dds/pmu1.yaml"), 1u)
      << log.text();
  w.h.run_for(3000ms);
  EXPECT_EQ(log.count("PMU serial 4001 is not"), 1u) << "once per change, not every second";
}

TEST(BaselineDrift, TheBaselinesFirmwarePinCountsAsMinFirmware) {
  Watched w("device:\n  min_firmware: \"1.18\"\nparameters:\n  avionics_voltage: 12.0\n");
  w.h.run_for(kFirstPackets);
  EXPECT_EQ(w.codes(), std::vector<std::string>{"firmware_below_minimum"});
  ASSERT_NE(w.reason("firmware_below_minimum"), nullptr);
  EXPECT_EQ(w.reason("firmware_below_minimum")->message, "PMU 1 firmware 1.17 < 1.18");
}

}  // namespace
}  // namespace pmu::service::test::baseline_drift
