// Which pages may open a `pmuctl serve` connection (origin_policy.hpp): the default list, the
// --allow-origin values as typed, and what each Origin header gets.
#include <gtest/gtest.h>

#include "pmuctl/serve/origin_policy.hpp"

namespace pmu::tools {
namespace {

TEST(OriginPolicy, DefaultAllowsTheViewersLocalPagesAndNativeClients) {
  struct Case {
    const char* origin;
    bool allowed;
  };
  const Case cases[] = {
      {"", true},  // no Origin header: not a browser
      {"https://app.foxglove.dev", true},
      {"https://studio.foxglove.dev", true},
      {"file://", true},  // Electron apps (Foxglove, Lichtblick desktop)
      {"http://localhost", true},
      {"http://localhost:8080", true},
      {"https://localhost:3000", true},
      {"http://127.0.0.1:5173", true},
      {"http://[::1]:8080", true},
      {"HTTPS://APP.FOXGLOVE.DEV", true},
      {"null", false},  // a sandboxed page or a data: URL
      {"https://evil.example", false},
      {"http://app.foxglove.dev", false},  // not the app's scheme
      {"https://app.foxglove.dev.evil.example", false},
      {"https://app.foxglove.dev:8443", false},
      {"http://localhost.evil.example", false},
      {"http://localhost:80x", false},
      {"http://127.0.0.2", false},
      {"http://192.168.1.10:8080", false},
      {"ws://localhost", false},
  };
  const OriginPolicy policy;
  for (const auto& c : cases) EXPECT_EQ(origin_allowed(policy, c.origin), c.allowed) << c.origin;
}

TEST(OriginPolicy, AllowOriginAddsExactlyThatOrigin) {
  struct Case {
    const char* typed;
    const char* allows;
    const char* not_allows;
  };
  const Case cases[] = {
      {"https://viz.example.com:8443", "https://viz.example.com:8443", "https://viz.example.com"},
      {"https://Viz.Example.com", "https://viz.example.com", "https://viz.example.com:8443"},
      {"https://viz.example.com:443", "https://viz.example.com", "https://viz.example.com:8443"},  // default port
      {"http://viz.example.com:80", "http://viz.example.com", "https://viz.example.com"},
      {"http://192.168.1.10:8080", "http://192.168.1.10:8080", "http://192.168.1.10"},
      {"http://[fd00::5]:8080", "http://[fd00::5]:8080", "http://[fd00::5]"},
      {"https://lichtblick.example.org", "https://lichtblick.example.org", "https://example.org"},
  };
  for (const auto& c : cases) {
    OriginPolicy policy;
    EXPECT_EQ(add_allowed_origin(c.typed, policy), "") << c.typed;
    EXPECT_TRUE(origin_allowed(policy, c.allows)) << c.typed;
    EXPECT_FALSE(origin_allowed(policy, c.not_allows)) << c.typed;
    EXPECT_FALSE(origin_allowed(policy, "null")) << c.typed;
    EXPECT_TRUE(origin_allowed(policy, "https://app.foxglove.dev")) << "the defaults stay";
  }
}

TEST(OriginPolicy, StarAllowsEveryOriginNullIncluded) {
  OriginPolicy policy;
  ASSERT_EQ(add_allowed_origin("*", policy), "");
  for (const char* o : {"null", "https://evil.example", "http://10.0.0.1:1234", ""})
    EXPECT_TRUE(origin_allowed(policy, o)) << o;
}

TEST(OriginPolicy, MalformedValuesAreRefusedNamingTheOption) {
  struct Case {
    const char* typed;
    const char* says;
  };
  const Case cases[] = {
      {"viz.example.com", "--allow-origin 'viz.example.com' is not an origin scheme://host[:port]"},
      {"https://viz.example.com/", "no path, not even a final /"},
      {"https://viz.example.com/app", "is not an origin"},
      {"https://", "is not an origin"},
      {"ftp://viz.example.com", "is not an origin"},
      {"ws://localhost:8765", "is not an origin"},
      {"null", "is not an origin"},
      {"https://user@viz.example.com", "is not an origin"},
      {"https://viz..example.com", "is not an origin"},
      {"https://viz.example.com?x=1", "is not an origin"},
      {"http://[fd00::zz]:80", "is not an origin"},
      {"https://viz.example.com:0", "the port must be a number 1..65535"},
      {"https://viz.example.com:65536", "the port must be a number 1..65535"},
      {"https://viz.example.com:", "the port must be a number 1..65535"},
      {"https://viz.example.com:x", "the port must be a number 1..65535"},
      {"**", "is not an origin"},
      {"", "is not an origin"},
  };
  for (const auto& c : cases) {
    OriginPolicy policy;
    const auto why = add_allowed_origin(c.typed, policy);
    EXPECT_NE(why.find(c.says), std::string::npos) << c.typed << ": " << why;
    EXPECT_TRUE(policy.exact.empty()) << c.typed;
    EXPECT_FALSE(policy.any) << c.typed;
  }
}

}  // namespace
}  // namespace pmu::tools
