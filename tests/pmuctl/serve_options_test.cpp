// `pmuctl serve`'s --listen, --port, --client-queue, --allow-origin, --tls-cert and --tls-key
// (serve_options.hpp): every text gives a value or a message naming the option.
#include <gtest/gtest.h>

#include "pmuctl/serve/serve_options.hpp"

namespace pmu::tools {
namespace {

TEST(ServeOptions, Accepted) {
  struct Case {
    const char *listen, *port, *queue, *label;
    std::size_t queue_bytes;
  };
  const Case cases[] = {
      {"127.0.0.1", "8765", "1024", "127.0.0.1:8765", 1024 * 1024},
      {"0.0.0.0", "1", "64", "0.0.0.0:1", 64 * 1024},
      {"::1", "65535", "1048576", "[::1]:65535", std::size_t{1024} * 1024 * 1024},
      {"::", "80", "100", "[::]:80", 100 * 1024},
  };
  for (const auto& c : cases) {
    ServeOptions o;
    EXPECT_EQ(parse_serve_options(c.listen, c.port, c.queue, o), "") << c.listen << " " << c.port;
    EXPECT_EQ(endpoint_label(o), c.label);
    EXPECT_EQ(o.client_queue, c.queue_bytes);
  }
}

TEST(ServeOptions, RefusedWithTheOptionNamed) {
  struct Case {
    const char *listen, *port, *queue, *says;
  };
  const Case cases[] = {
      {"localhost", "8765", "1024", "--listen 'localhost' is not an IP address"},
      {"", "8765", "1024", "--listen '' is not an IP address"},
      {"127.0.0.256", "8765", "1024", "--listen '127.0.0.256'"},
      {"127.0.0.1:80", "8765", "1024", "--listen '127.0.0.1:80'"},
      {"127.0.0.1", "0", "1024", "--port '0' is not a port number 1..65535"},
      {"127.0.0.1", "65536", "1024", "--port '65536'"},
      {"127.0.0.1", "-1", "1024", "--port '-1'"},
      {"127.0.0.1", "80x", "1024", "--port '80x'"},
      {"127.0.0.1", "", "1024", "--port ''"},
      {"127.0.0.1", " 80", "1024", "--port ' 80'"},
      {"127.0.0.1", "99999999999", "1024", "--port '99999999999'"},
      {"127.0.0.1", "8765", "8", "--client-queue '8' is not a size in kB 64..1048576"},
      {"127.0.0.1", "8765", "1048577", "--client-queue '1048577'"},
      {"127.0.0.1", "8765", "1M", "--client-queue '1M'"},
  };
  for (const auto& c : cases) {
    ServeOptions o;
    const auto why = parse_serve_options(c.listen, c.port, c.queue, o);
    EXPECT_NE(why.find(c.says), std::string::npos) << why;
    EXPECT_EQ(o.port, 8765) << "left as it was";
  }
}

TEST(ServeOptions, AccessOptions) {
  struct Case {
    std::vector<std::string> origins;
    const char *cert, *key, *says;
  };
  const Case cases[] = {
      {{}, "", "", ""},
      {{"https://viz.example.com", "*"}, "c.pem", "k.pem", ""},
      {{"viz.example.com"}, "", "", "--allow-origin 'viz.example.com' is not an origin"},
      {{},
       "c.pem",
       "",
       "--tls-cert and --tls-key go together (the certificate chain and its private key, PEM): "
       "--tls-key is missing"},
      {{}, "", "k.pem", "--tls-cert is missing"},
  };
  for (const auto& c : cases) {
    ServeOptions o;
    const auto why = parse_serve_access(c.origins, c.cert, c.key, o);
    if (*c.says == '\0') {
      EXPECT_EQ(why, "");
      EXPECT_EQ(o.tls(), *c.cert != '\0');
      EXPECT_EQ(o.origins.exact.size() + (o.origins.any ? 1u : 0u), c.origins.size());
    } else {
      EXPECT_NE(why.find(c.says), std::string::npos) << why;
      EXPECT_FALSE(o.tls()) << "left as it was";
    }
  }
}

TEST(ServeOptions, LoopbackAddresses) {
  struct Case {
    const char* listen;
    bool loopback;
  };
  for (const Case c : {Case{"127.0.0.1", true}, Case{"127.1.2.3", true}, Case{"::1", true}, Case{"0.0.0.0", false},
                       Case{"::", false}, Case{"192.168.1.5", false}, Case{"::ffff:127.0.0.1", false}}) {
    ServeOptions o;
    ASSERT_EQ(parse_serve_options(c.listen, "8765", "1024", o), "");
    EXPECT_EQ(listens_on_loopback(o), c.loopback) << c.listen;
  }
}

}  // namespace
}  // namespace pmu::tools
