#pragma once
// The WebSocket side of `pmuctl serve`: websocketpp on standalone asio (ws://, or wss://
// through OpenSSL), one server thread, speaking the Foxglove protocol (foxglove_protocol.hpp)
// with the drop policy of client_backlog.hpp and the origins of origin_policy.hpp. websocketpp
// stays inside foxglove_server.cpp.
//
// Threads: publish() is called by Fast DDS's listener threads. It only appends the sample to
// a bounded hand-over queue and, when that queue was empty, posts one drain to the server
// thread; it never touches a client, so a client can never hold up DDS. The server thread
// owns every connection: it answers requests and frames each sample for each subscriber,
// or drops it for a client whose queue is full.
//
// Error handling: start() returns what went wrong ("cannot listen on 127.0.0.1:8765:
// Address already in use"); after it nothing throws. Client mistakes are answered with
// status messages; a client that fails or vanishes is just removed.
// Time (capability `time`): the server's clock is the newest source time it has forwarded,
// told to each client in a Time message before the first message that advances it; a state
// sample sent to a new subscriber is stamped max(its source time, that clock).
// Security: pages of origins the options do not allow are refused (HTTP 403); TLS when
// given a certificate; no authentication; it listens on 127.0.0.1 unless told otherwise.

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "pmuctl/serve/foxglove_protocol.hpp"
#include "pmuctl/serve/serve_options.hpp"

namespace pmu::tools {

// --tls-cert's and --tls-key's files as read, PEM; the names are for messages.
struct TlsPem {
  std::string cert_file, cert;
  std::string key_file, key;
};

// Whether the certificate chain and key parse and belong together: "" or what is wrong,
// naming the option and file ("--tls-key k.pem is not the private key of the certificate in
// --tls-cert c.pem").
std::string check_tls(const TlsPem& pem);

class FoxgloveServer {
 public:
  struct Counters {
    std::size_t clients = 0;      // connected now
    std::uint64_t forwarded = 0;  // MessageData frames handed to clients' queues
    std::uint64_t dropped = 0;    // for clients that did not read, and samples the server thread had no room for
  };

  // `latched[i]`: channel i carries state (TRANSIENT_LOCAL in DDS): the server keeps the last
  // message of each instance and sends those to a client when it subscribes, as DDS gives a
  // late-joining reader the current state. `name`: serverInfo's name. `tls`: used when
  // options.tls(), checked by check_tls() beforehand.
  FoxgloveServer(std::vector<foxglove::Channel> channels, std::vector<bool> latched, ServeOptions options,
                 std::string name, TlsPem tls = {});
  ~FoxgloveServer();  // stop()
  FoxgloveServer(const FoxgloveServer&) = delete;
  FoxgloveServer& operator=(const FoxgloveServer&) = delete;

  // Listens and starts the server thread. "" or what failed, naming the address and port.
  std::string start();
  // Any thread. `channel`: an advertised channel id; `time_ns`: the message's timestamp;
  // `instance`: the DDS instance (for latched channels).
  void publish(std::uint32_t channel, std::uint64_t time_ns, const std::array<std::uint8_t, 16>& instance,
               std::vector<std::uint8_t>&& payload);
  // Any thread. One more channel (a ROS 2 topic discovery found), its id the number of
  // channels before it: advertised to the clients connected and to those that connect later.
  // Samples published for it after this call reach the server thread after the channel.
  void add_channel(foxglove::Channel channel, bool latched);
  Counters counters() const;
  // Closes every connection (going away), waits for them briefly, ends the server thread.
  void stop();

  struct Impl;  // opaque: foxglove_server.cpp's ws:// and wss:// endpoints implement it

 private:
  std::unique_ptr<Impl> impl_;
};

}  // namespace pmu::tools
