// A verified engine start as an operator runs it (docs/interface.md 2.7): pmuctl against a
// pmu-service whose simulated engine is stopped and fires after 2 s, or never fires. pmuctl
// prints each IN_PROGRESS on stderr, the final result last, and exits 0 only on COMPLETED.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdlib>
#include <string>

#include "support/configured_service.hpp"
#include "support/domain.hpp"
#include "support/process.hpp"

namespace {

struct StartCase {
  const char* what;
  const char* sim;  // the PMU's sim: mapping
  int status;
  const char* final_line;  // the final line's start
  double at_least;         // the seconds it names next are at least these (measured: a loaded host adds)
};

const StartCase kStarts[] = {
    {"the engine fires after 2 s", "{engine: stopped, engine_starts_after: 2}", 0,
     "COMPLETED: engine running: 6000 rpm for ", 1.0},
    {"a flooded engine never fires", "{engine: stopped, engine_starts_after: never}", 1,
     "FAILED: no start: rpm 0 after ", 7.0},
    {"the engine already runs", "{engine: running}", 1, "DENIED: engine already running: 6000 rpm", 0.0},
};

std::size_t count_of(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (auto at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

TEST(EngineStartOverDds, PmuctlShowsProgressAndExitsZeroOnlyWhenTheEngineRuns) {
  for (const auto& c : kStarts) {
    SCOPED_TRACE(c.what);
    const std::string domain = std::to_string(pmu::test::exclusive_dds_domain());
    pmu::test::ConfiguredService service(
        PMU_SERVICE_PATH, "domain: " + domain +
                              "\nqos_file: " PMU_QOS_FILE
                              "\nbuses:\n  - interface: sim\n    devices:\n      - address: 1\n        period: 0.5\n"
                              "        sim: " +
                              std::string(c.sim) + "\n");
    const std::string p = std::string(PMUCTL_PATH) + " --domain " + domain + " ";
    // Ready once the PMU's configuration has been read (a start needs its firmware).
    const auto ready = pmu::test::run_capture(p + "--timeout 30 --address 1 config get cranking_time");
    ASSERT_EQ(ready.status, 0) << ready.out << service.describe();
    // --timeout 5 is shorter than a start that never fires (7 s): the progress keeps it waiting.
    const auto r = pmu::test::run_capture(p + "--timeout 5 --address 1 --confirm engine start 2>&1");
    EXPECT_EQ(r.status, c.status) << r.out << service.describe();
    const auto at = r.out.find(c.final_line);
    ASSERT_NE(at, std::string::npos) << r.out;
    if (c.at_least > 0) {
      const auto seconds = std::strtod(r.out.c_str() + at + std::string(c.final_line).size(), nullptr);
      EXPECT_GE(seconds, c.at_least) << r.out;
      EXPECT_LT(seconds, c.at_least + 2.0) << r.out;
    }
    if (c.status == 1 && c.at_least > 0) {
      EXPECT_NE(r.out.find("s (cranking time 5.0 s)", at), std::string::npos) << r.out;
    }
    if (c.status == 0 || std::string(c.final_line).rfind("FAILED", 0) == 0) {
      EXPECT_GE(count_of(r.out, "IN_PROGRESS: cranking"), 2u) << r.out;
      EXPECT_LT(r.out.find("IN_PROGRESS"), r.out.find(c.final_line)) << "progress before the result";
    } else {
      EXPECT_EQ(count_of(r.out, "IN_PROGRESS"), 0u) << r.out;
    }
  }
}

}  // namespace
