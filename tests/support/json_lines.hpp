#pragma once
// pmu::test_support: pmuctl's --json output, one JSON document per line, as a vector.
// A line that is not JSON becomes a discarded value (is_discarded()), so a test asserts on
// it instead of dying in an exception:
//
//   for (const auto& j : pmu::test::json_lines(run_capture(PMUCTL_PATH " list --json").out))
//     EXPECT_FALSE(j.is_discarded());
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace pmu::test {

inline std::vector<nlohmann::json> json_lines(const std::string& out) {
  std::vector<nlohmann::json> v;
  std::istringstream in(out);
  for (std::string line; std::getline(in, line);)
    if (!line.empty()) v.push_back(nlohmann::json::parse(line, nullptr, false));
  return v;
}

}  // namespace pmu::test
