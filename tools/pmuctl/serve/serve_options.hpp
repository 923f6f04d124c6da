#pragma once
// `pmuctl serve`'s own options turned into typed values once, before anything starts
// (docs/interface.md, "Live: Foxglove WebSocket"). Pure.
//
//   --listen 127.0.0.1 --port 8765     -> {"127.0.0.1", 8765}, label "127.0.0.1:8765"
//   --listen ::1                       -> label "[::1]:8765"
//   --listen localhost                 -> error: an IP address, not a host name
//   --port 70000, --port 0, --port x   -> error: a port 1..65535
//   --client-queue 8                   -> error: 64..1048576 kB
//   --allow-origin https://x.example   -> origins: the defaults and that one (origin_policy.hpp)
//   --tls-cert c.pem --tls-key k.pem   -> wss:// with that certificate chain and key
//   --tls-cert c.pem alone             -> error: both or neither

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "pmuctl/serve/origin_policy.hpp"

namespace pmu::tools {

struct ServeOptions {
  std::string address = "127.0.0.1";       // an IPv4 or IPv6 address literal
  std::uint16_t port = 8765;               // Foxglove's default
  std::size_t client_queue = 1024 * 1024;  // bytes held for a client that does not read
  OriginPolicy origins;                    // pages that may connect
  std::string tls_cert;                    // PEM files; both empty: plain ws://
  std::string tls_key;

  bool tls() const { return !tls_cert.empty(); }
};

inline constexpr long kMinClientQueueKb = 64;
inline constexpr long kMaxClientQueueKb = 1024 * 1024;

// The option texts into `out`; "" or what is wrong, naming the option
// ("--port '70000' is not a port number 1..65535").
std::string parse_serve_options(const std::string& listen, const std::string& port, const std::string& client_queue_kb,
                                ServeOptions& out);

// --allow-origin (each), --tls-cert and --tls-key into `out`; "" or what is wrong, naming the
// option. The files are read later (serve_verb), where their errors name them.
std::string parse_serve_access(const std::vector<std::string>& allow_origins, const std::string& tls_cert,
                               const std::string& tls_key, ServeOptions& out);

// Whether only this host can reach the address (127.0.0.0/8, ::1).
bool listens_on_loopback(const ServeOptions& o);

// "127.0.0.1:8765", "[::1]:8765": for messages and the ws:// URL.
std::string endpoint_label(const ServeOptions& o);

}  // namespace pmu::tools
