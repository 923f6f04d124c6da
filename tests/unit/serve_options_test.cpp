// `pmuctl serve`'s --listen, --port and --client-queue (serve_options.hpp): every text gives
// a value or a message naming the option.
#include <gtest/gtest.h>

#include "pmuctl/serve/serve_options.hpp"

namespace pmu::tools {
namespace {

TEST(ServeOptions, Accepted) {
  struct Case { const char *listen, *port, *queue, *label; std::size_t queue_bytes; };
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
  struct Case { const char *listen, *port, *queue, *says; };
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

}  // namespace
}  // namespace pmu::tools
