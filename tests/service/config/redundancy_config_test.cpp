// The `redundancy:` section (interface.md 4.7): absent, nothing changes; its values read into
// the role machine's settings; every bad value refused at its line.
#include <unistd.h>

#include <gtest/gtest.h>

#include <string>

#include "pmu/config/config.hpp"

namespace pmu::service {
namespace {

using namespace std::chrono_literals;

const char* const kBusesAfter = "buses:\n  - name: can0\n    interface: can0\n    discover: true\n";

TEST(RedundancyConfig, WithoutTheSectionAServiceIsAlone) {
  const auto c = parse_config(kBusesAfter, "c.yaml");
  EXPECT_FALSE(c.redundancy.has_value());
}

TEST(RedundancyConfig, ItsValuesAndTheDefaults) {
  const auto c = parse_config(std::string("redundancy:\n  priority: 2\n  peer: mc-b\n") + kBusesAfter, "c.yaml");
  ASSERT_TRUE(c.redundancy.has_value());
  EXPECT_EQ(c.redundancy->priority, 2);
  EXPECT_EQ(c.redundancy->peer, "mc-b");
  EXPECT_EQ(c.redundancy->heartbeat_period, 100ms);
  EXPECT_EQ(c.redundancy->lease, 300ms);
  EXPECT_EQ(c.redundancy->can_silence, 150ms);
  EXPECT_EQ(c.redundancy_line, "c.yaml:1");

  const auto all = parse_config(std::string("log_level: info\nredundancy:\n  priority: 255\n  peer: mc-a.local\n"
                                            "  heartbeat_period: 0.05\n  lease: 0.2\n  can_silence: 0.09\n") +
                                    kBusesAfter,
                                "c.yaml");
  ASSERT_TRUE(all.redundancy.has_value());
  EXPECT_EQ(all.redundancy->priority, 255);
  EXPECT_EQ(all.redundancy->peer, "mc-a.local");
  EXPECT_EQ(all.redundancy->heartbeat_period, 50ms);
  EXPECT_EQ(all.redundancy->lease, 200ms);
  EXPECT_EQ(all.redundancy->can_silence, 90ms);
  EXPECT_EQ(all.redundancy_line, "c.yaml:2");
}

TEST(RedundancyConfig, TheInstanceNameIsWrittenOrTheHosts) {
  const auto named =
      parse_config(std::string("redundancy:\n  priority: 2\n  peer: mc-b\n  name: mc-a\n") + kBusesAfter, "c.yaml");
  EXPECT_EQ(named.redundancy->name, "mc-a");
  char host[256] = {};
  ASSERT_EQ(::gethostname(host, sizeof host - 1), 0);
  std::string expected(host);
  expected = expected.substr(0, expected.find('.'));
  const auto unnamed = parse_config(std::string("redundancy:\n  priority: 2\n  peer: mc-b\n") + kBusesAfter, "c.yaml");
  EXPECT_EQ(unnamed.redundancy->name, expected);
  try {
    (void)parse_config(std::string("redundancy:\n  priority: 2\n  peer: mc-b\n  name: 'mc a'\n") + kBusesAfter,
                       "bad.yaml");
    ADD_FAILURE() << "a name with a space was taken";
  } catch (const ConfigError& e) {
    EXPECT_STREQ(e.what(),
                 "bad.yaml:4: redundancy name 'mc a' is not an instance name (1..63 letters, digits, '-', '_' or '.', "
                 "as a host name)");
  }
}

TEST(RedundancyConfig, EveryBadValueIsRefusedWithItsLine) {
  struct Case {
    const char* section;
    const char* message;
  };
  const Case cases[] = {
      {"redundancy: yes\n", "bad.yaml:1: redundancy must be a map: {priority: 2, peer: mc-b}"},
      {"redundancy:\n  priority: 2\n  peer: b\n  leese: 1\n",
       "bad.yaml:4: unknown key 'leese' in redundancy (known: priority, peer, name, heartbeat_period, lease, can_silence)"},
      {"redundancy:\n  peer: b\n",
       "bad.yaml:2: redundancy needs priority (1..255; the higher wins when neither instance owns the bus)"},
      {"redundancy:\n  priority: 2\n", "bad.yaml:2: redundancy needs peer (the other instance's name)"},
      {"redundancy:\n  priority: 0\n  peer: b\n", "bad.yaml:2: redundancy priority 0 out of range 1..255"},
      {"redundancy:\n  priority: 256\n  peer: b\n", "bad.yaml:2: redundancy priority 256 out of range 1..255"},
      {"redundancy:\n  priority: 02\n  peer: b\n",
       "bad.yaml:2: redundancy priority must be a decimal integer (digits, optionally after '-'; no leading 0, '+', "
       "0x, 0o, exponent or fraction), not '02'"},
      {"redundancy:\n  priority: 2\n  peer:\n",
       "bad.yaml:3: redundancy peer '' is not an instance name (1..63 letters, digits, '-', '_' or '.', as a host "
       "name)"},
      {"redundancy:\n  priority: 2\n  peer: mc b\n",
       "bad.yaml:3: redundancy peer 'mc b' is not an instance name (1..63 letters, digits, '-', '_' or '.', as a "
       "host name)"},
      {"redundancy:\n  priority: 2\n  peer: [a, b]\n", "bad.yaml:3: redundancy peer must be a name"},
      {"redundancy:\n  priority: 2\n  peer: b\n  heartbeat_period: 0.005\n",
       "bad.yaml:4: redundancy heartbeat_period 0.005 out of range 0.01..1"},
      {"redundancy:\n  priority: 2\n  peer: b\n  heartbeat_period: fast\n",
       "bad.yaml:4: redundancy heartbeat_period must be a number, not 'fast'"},
      {"redundancy:\n  priority: 2\n  peer: b\n  heartbeat_period: 0.0505\n",
       "bad.yaml:4: redundancy heartbeat_period 0.0505 is not whole milliseconds"},
      {"redundancy:\n  priority: 2\n  peer: b\n  lease: 11\n",
       "bad.yaml:4: redundancy lease 11 out of range 0.001..10"},
      {"redundancy:\n  priority: 2\n  peer: b\n  lease: 0.15\n",
       "bad.yaml:4: redundancy lease 150 ms is under 2 x heartbeat_period (200 ms)"},
      {"redundancy:\n  priority: 2\n  peer: b\n  heartbeat_period: 0.2\n",
       "bad.yaml:4: redundancy lease 300 ms is under 2 x heartbeat_period (400 ms)"},
      {"redundancy:\n  priority: 2\n  peer: b\n  can_silence: 0.02\n",
       "bad.yaml:4: redundancy can_silence 0.02 out of range 0.03..10"},
  };
  for (const auto& c : cases) {
    try {
      parse_config(std::string(c.section) + kBusesAfter, "bad.yaml");
      ADD_FAILURE() << "accepted: " << c.section;
    } catch (const ConfigError& e) {
      EXPECT_EQ(std::string(e.what()), c.message) << c.section;
    }
  }
}

}  // namespace
}  // namespace pmu::service
