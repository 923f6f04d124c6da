#include "telemetry/relay_status.hpp"

#include <gtest/gtest.h>

namespace pmu::mavlink_bridge {
namespace relay_status_test {  // named: the unity build joins this file with others of its target
namespace {

struct Outputs {
  bool avionics_servo;
  bool payload;
  bool charger_a;
  bool charger_b;
  bool generation;
};

PmuView pmu_with(bool online, const Outputs* outputs) {
  PmuView v;
  v.online = online;
  if (outputs) {
    v.status.emplace();
    v.status->avionics_servo_on(outputs->avionics_servo);
    v.status->payload_on(outputs->payload);
    v.status->charger_a_on(outputs->charger_a);
    v.status->charger_b_on(outputs->charger_b);
    v.status->generation_enabled(outputs->generation);
  }
  return v;
}

constexpr Outputs kAllOff{false, false, false, false, false};
constexpr Outputs kAllOn{true, true, true, true, true};

// One PMU: every known and unknown case. Present is all five bits or none; `on` only where
// present (a state not known is never reported as off or on: docs/safety.md H7).
TEST(RelayStatus, OnePmuKnownAndUnknown) {
  const Outputs avionics{true, false, false, false, false};
  const Outputs payload{false, true, false, false, false};
  const Outputs charger_a{false, false, true, false, false};
  const Outputs charger_b{false, false, false, true, false};
  const Outputs generation{false, false, false, false, true};
  const Outputs mixed{true, false, true, false, true};
  const struct {
    const char* name;
    bool online;
    const Outputs* outputs;  // null: no pmu/status read
    std::uint16_t on;
    std::uint16_t present;
  } cases[] = {
      {"not online, no status", false, nullptr, 0x00, 0x00},
      {"not online, status all on (old)", false, &kAllOn, 0x00, 0x00},
      {"not online, status all off (old)", false, &kAllOff, 0x00, 0x00},
      {"online, no status read", true, nullptr, 0x00, 0x00},
      {"online, all off", true, &kAllOff, 0x00, 0x1F},
      {"online, avionics_servo: instance 0", true, &avionics, 0x01, 0x1F},
      {"online, payload: instance 1", true, &payload, 0x02, 0x1F},
      {"online, charger_a: instance 2", true, &charger_a, 0x04, 0x1F},
      {"online, charger_b: instance 3", true, &charger_b, 0x08, 0x1F},
      {"online, generation: instance 4", true, &generation, 0x10, 0x1F},
      {"online, mixed", true, &mixed, 0x15, 0x1F},
      {"online, all on", true, &kAllOn, 0x1F, 0x1F},
  };
  for (const auto& c : cases) {
    const PmuView v = pmu_with(c.online, c.outputs);
    const PmuRelays r = pmu_relays(v);
    EXPECT_EQ(r.on, c.on) << c.name;
    EXPECT_EQ(r.present, c.present) << c.name;
    const auto m = relay_status({{0, &v}}, 1234);
    EXPECT_EQ(m.on, c.on) << c.name;
    EXPECT_EQ(m.present, c.present) << c.name;
    EXPECT_EQ(m.time_boot_ms, 1234U) << c.name;
  }
}

// Several PMUs: PMU n at bits 5n..5n+4, PMUs 0..2 only; each PMU's unknown outputs stay out.
TEST(RelayStatus, PmusByNumber) {
  const Outputs payload{false, true, false, false, false};
  const PmuView on0 = pmu_with(true, &kAllOn);
  const PmuView payload_only = pmu_with(true, &payload);
  const PmuView offline = pmu_with(false, &kAllOn);
  const PmuView unread = pmu_with(true, nullptr);
  const struct {
    const char* name;
    std::vector<std::pair<unsigned, const PmuView*>> pmus;
    std::uint16_t on;
    std::uint16_t present;
  } cases[] = {
      {"no PMU: nothing present", {}, 0x0000, 0x0000},
      {"PMU 1 at bits 5..9", {{1, &payload_only}}, 0x0040, 0x03E0},
      {"PMU 2 at bits 10..14", {{2, &on0}}, 0x7C00, 0x7C00},
      {"PMU 3 does not fit", {{3, &on0}}, 0x0000, 0x0000},
      {"PMU 0 known, PMU 1 not online", {{0, &on0}, {1, &offline}}, 0x001F, 0x001F},
      {"PMU 0 status unread, PMU 2 known", {{0, &unread}, {2, &payload_only}}, 0x0800, 0x7C00},
      {"three PMUs", {{0, &on0}, {1, &payload_only}, {2, &on0}}, 0x7C5F, 0x7FFF},
      {"the number decides, not the order", {{2, &payload_only}, {0, &on0}}, 0x081F, 0x7C1F},
  };
  for (const auto& c : cases) {
    const auto m = relay_status(c.pmus, 0);
    EXPECT_EQ(m.on, c.on) << c.name;
    EXPECT_EQ(m.present, c.present) << c.name;
    EXPECT_EQ(m.present & 0x8000, 0) << c.name << ": bit 15 is no PMU's";
  }
}

}  // namespace
}  // namespace relay_status_test
}  // namespace pmu::mavlink_bridge
