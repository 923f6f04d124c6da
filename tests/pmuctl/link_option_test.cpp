// pmuctl's --link and PMU_LINK (interface.md section 7.3): the option wins over the variable,
// an unknown profile is refused naming where it came from, and the profile reaches the
// participant's settings (ResolvedNetwork::link) and pmuctl's summary, which a call compares
// with its agent's.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <optional>
#include <string>

#include "pmuctl/call/network_options.hpp"

namespace {

pmu::dds::NetworkLookup no_lookup() {
  return {[] { return std::vector<pmu::dds::LocalAddress>{}; },
          [](const std::string&) { return std::vector<std::string>{}; }};
}

// PMU_LINK set (or unset) for one case, and the other network variables unset.
class Environment {
 public:
  explicit Environment(const char* link) {
    for (const char* name : {"PMU_DDS_PEERS", "PMU_DISCOVERY_SERVER", "PMU_DDS_INTERFACES", "PMU_LINK"})
      ::unsetenv(name);
    if (link) ::setenv("PMU_LINK", link, 1);
  }
  ~Environment() { ::unsetenv("PMU_LINK"); }
};

struct Case {
  const char* option;    // --link, "" when absent
  const char* variable;  // PMU_LINK, nullptr when unset
  bool ok;
  pmu::dds::LinkProfile profile;
  const char* where;    // where the profile came from
  const char* message;  // stderr when refused
};

const Case kCases[] = {
    {"", nullptr, true, pmu::dds::LinkProfile::None, "", ""},
    {"radio", nullptr, true, pmu::dds::LinkProfile::Radio, "--link", ""},
    {"", "radio", true, pmu::dds::LinkProfile::Radio, "PMU_LINK", ""},
    {"none", "radio", true, pmu::dds::LinkProfile::None, "--link", ""},
    {"radio", "satellite", true, pmu::dds::LinkProfile::Radio, "--link", ""},
    {"satellite", "radio", false, pmu::dds::LinkProfile::None, "",
     "pmuctl: --link 'satellite': not a link profile (one of: radio, none)\n"},
    {"", "RADIO", false, pmu::dds::LinkProfile::None, "",
     "pmuctl: PMU_LINK 'RADIO': not a link profile (one of: radio, none)\n"},
};

TEST(PmuctlLinkOption, TheOptionWinsOverTheVariableAndAnUnknownProfileIsRefused) {
  for (const auto& c : kCases) {
    SCOPED_TRACE(std::string("--link '") + c.option + "' PMU_LINK=" + (c.variable ? c.variable : "(unset)"));
    const Environment env(c.variable);
    pmu::tools::NetworkOptions options;
    options.link = c.option;
    pmu::dds::ResolvedNetwork out;
    testing::internal::CaptureStderr();
    const bool ok = pmu::tools::resolve_network_options(options, no_lookup(), false, out);
    const std::string err = testing::internal::GetCapturedStderr();
    EXPECT_EQ(ok, c.ok);
    EXPECT_EQ(err, c.message);
    if (!c.ok) continue;
    EXPECT_EQ(out.link.profile, c.profile);
    EXPECT_EQ(out.link.low_rate_watch, c.profile == pmu::dds::LinkProfile::Radio);
    if (c.profile == pmu::dds::LinkProfile::Radio) {
      EXPECT_EQ(out.link.round_trip.value, pmu::dds::kRadioRoundTrip);
      EXPECT_EQ(out.link.round_trip.from, std::string("profile radio, ") + c.where);
      EXPECT_EQ(out.link.announcement_period.value, pmu::dds::kRadioAnnouncementPeriod);
      EXPECT_EQ(out.link.lease.value, pmu::dds::kRadioLease);
      EXPECT_EQ(out.link.agent_workers, 1);
      EXPECT_NE(out.summary.find("link profile radio"), std::string::npos) << out.summary;
    } else {
      EXPECT_FALSE(out.link.round_trip.set());
      EXPECT_EQ(out.summary.find("link"), std::string::npos) << out.summary;
    }
  }
}

}  // namespace
