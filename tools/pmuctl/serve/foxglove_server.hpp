#pragma once
// The WebSocket side of `pmuctl serve`: websocketpp on standalone asio, one server thread,
// speaking the Foxglove protocol (foxglove_protocol.hpp) with the drop policy of
// client_backlog.hpp. websocketpp stays inside foxglove_server.cpp.
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
// Security: no TLS and no authentication; it listens on 127.0.0.1 unless told otherwise.

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "pmuctl/serve/foxglove_protocol.hpp"
#include "pmuctl/serve/serve_options.hpp"

namespace pmu::tools {

class FoxgloveServer {
 public:
  struct Counters {
    std::size_t clients = 0;       // connected now
    std::uint64_t forwarded = 0;   // MessageData frames handed to clients' queues
    std::uint64_t dropped = 0;     // for clients that did not read, and samples the server thread had no room for
  };

  // `latched[i]`: channel i carries state (TRANSIENT_LOCAL in DDS): the server keeps the last
  // message of each instance and sends those to a client when it subscribes, as DDS gives a
  // late-joining reader the current state. `name`: serverInfo's name.
  FoxgloveServer(std::vector<foxglove::Channel> channels, std::vector<bool> latched, ServeOptions options,
                 std::string name);
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

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace pmu::tools
