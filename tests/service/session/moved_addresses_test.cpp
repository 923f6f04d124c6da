// The record of moved CAN addresses (moved_addresses.hpp): its lines, every bad line with
// FILE:LINE, where it lives, and what --check-config says of a config it makes stale.
#include "pmu/session/moved_addresses.hpp"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstdio>
#include <fstream>

namespace pmu::service {
namespace {

TEST(MovedAddresses, PathIsTheFirstStateDirectoryElseVarLib) {
  const struct {
    const char* env;
    const char* path;
  } cases[] = {
      {nullptr, "/var/lib/pmu-dds/moved-addresses"},
      {"", "/var/lib/pmu-dds/moved-addresses"},
      {"/var/lib/pmu-dds", "/var/lib/pmu-dds/moved-addresses"},
      {"/var/lib/private/pmu-dds/", "/var/lib/private/pmu-dds/moved-addresses"},
      {"/a:/b", "/a/moved-addresses"},
  };
  for (const auto& c : cases) EXPECT_EQ(moved_addresses_path(c.env), c.path) << (c.env ? c.env : "unset");
}

TEST(MovedAddresses, FormatAndParseAreInverse) {
  const std::vector<MovedAddress> moves = {{"can0", 1, 7, 1001, ""}, {"can1", 65534, 0, std::nullopt, ""}};
  const auto back = parse_moved_addresses(format_moved_addresses(moves), "f");
  EXPECT_TRUE(back.errors.empty());
  ASSERT_EQ(back.moves.size(), 2u);
  EXPECT_EQ(back.moves[0].bus, "can0");
  EXPECT_EQ(back.moves[0].configured, 1);
  EXPECT_EQ(back.moves[0].now, 7);
  EXPECT_EQ(back.moves[0].serial, std::optional<std::uint16_t>(1001));
  EXPECT_EQ(back.moves[0].where, "f:3");  // after the two comment lines
  EXPECT_EQ(back.moves[1].configured, 65534);
  EXPECT_EQ(back.moves[1].serial, std::nullopt);
}

TEST(MovedAddresses, EveryBadLineIsAnErrorAtItsLineAndTheRestIsKept) {
  const struct {
    const char* line;
    const char* error;  // a part of it
  } cases[] = {
      {"can0 1 7", "f:2: expected `BUS CONFIGURED-ADDRESS ADDRESS-NOW SERIAL`, got 3 field(s)"},
      {"can0 1 7 1001 x", "got 5 field(s)"},
      {"can0 one 7 1001", "f:2: address 'one' is not 0..65534"},
      {"can0 1 65535 1001", "address '65535' is not 0..65534"},
      {"can0 1 -7 1001", "address '-7'"},
      {"can0 1 7 70000", "f:2: serial '70000' is not 0..65535 or -"},
      {"can0 2 3 1", "f:2: bus can0 address 2 appears twice"},
  };
  for (const auto& c : cases) {
    const auto r = parse_moved_addresses("can0 2 8 5  # kept\n" + std::string(c.line) + "\n\n", "f");
    ASSERT_EQ(r.errors.size(), 1u) << c.line;
    EXPECT_NE(r.errors[0].find(c.error), std::string::npos) << r.errors[0];
    ASSERT_EQ(r.moves.size(), 1u) << c.line;
    EXPECT_EQ(r.moves[0].now, 8);
  }
}

TEST(MovedAddresses, MissingFileIsNoMoves) {
  const auto r = read_moved_addresses("/nonexistent-dir/moved-addresses");
  EXPECT_TRUE(r.moves.empty());
  EXPECT_TRUE(r.errors.empty());
}

// A state file that is no regular file is reported and taken as no moves, never read or
// waited on (docs/safety.md H12): the start goes on.
TEST(MovedAddresses, ADeviceOrAFifoIsAnErrorNotARead) {
  char dir[] = "/tmp/pmu-moved-XXXXXX";
  ASSERT_NE(::mkdtemp(dir), nullptr);
  const std::string fifo = std::string(dir) + "/moved-addresses";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const std::pair<std::string, std::string> cases[] = {
      {"/dev/zero", "/dev/zero: cannot read: it is a character device, not a regular file"},
      {fifo, fifo + ": cannot read: it is a FIFO, not a regular file"},
  };
  for (const auto& [path, error] : cases) {
    SCOPED_TRACE(path);
    const auto r = read_moved_addresses(path);
    EXPECT_TRUE(r.moves.empty());
    EXPECT_EQ(r.errors, std::vector<std::string>{error});
  }
  ::unlink(fifo.c_str());
  ::rmdir(dir);
}

const char* kConfig =
    "buses:\n"
    "  - interface: can0\n"
    "    devices:\n"
    "      - address: 1\n"
    "      - address: 2\n";

TEST(MovedAddresses, StaleAddressNamesTheConfigLineAndTheValueToWrite) {
  const Config cfg = parse_config(kConfig, "/etc/pmu-dds/pmu-service.yaml");
  const std::vector<MovedAddress> moves = {{"can0", 2, 9, 1002, "/var/lib/pmu-dds/moved-addresses:3"},
                                           {"can1", 1, 5, 1001, "x:4"},   // another bus
                                           {"can0", 3, 6, 1003, "x:5"}};  // not in the config
  const auto stale = stale_addresses(cfg, moves);
  ASSERT_EQ(stale.size(), 1u);
  EXPECT_EQ(stale[0],
            "/etc/pmu-dds/pmu-service.yaml:5: bus can0, address 2: the PMU (serial 1002) answers at address 9 "
            "(/var/lib/pmu-dds/moved-addresses:3): change `address: 2` to `address: 9`");
}

TEST(MovedAddresses, StoreRecordsMovesDropsThemWhenBackAndForgetsFixedConfigs) {
  char dir[] = "/tmp/pmu-moved-XXXXXX";
  ASSERT_NE(::mkdtemp(dir), nullptr);
  const std::string path = std::string(dir) + "/moved-addresses";
  const Config cfg = parse_config(kConfig, "c.yaml");
  {
    MovedAddressStore store(path, cfg);
    store.record("can0", 1, 7, 1001);
    store.record("can0", 1, 8, 1001);  // moved again: one line, the newest address
    store.record("can0", 2, 9, 1002);
    store.record("can0", 2, 2, 1002);  // back where the config has it
    const auto r = read_moved_addresses(path);
    ASSERT_EQ(r.moves.size(), 1u);
    EXPECT_EQ(r.moves[0].configured, 1);
    EXPECT_EQ(r.moves[0].now, 8);
    EXPECT_EQ(stale_addresses(cfg, r.moves).size(), 1u);
  }
  {
    // The operator fixed the config (address 8 now): the record of address 1 goes at start.
    const Config fixed =
        parse_config("buses:\n  - interface: can0\n    devices:\n      - address: 8\n      - address: 2\n", "c.yaml");
    MovedAddressStore store(path, fixed);
    EXPECT_TRUE(store.moves().empty());
    EXPECT_TRUE(read_moved_addresses(path).moves.empty());
  }
  std::remove(path.c_str());
  ::rmdir(dir);
}

}  // namespace
}  // namespace pmu::service
