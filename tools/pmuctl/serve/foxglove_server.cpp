#include "pmuctl/serve/foxglove_server.hpp"

#include <csignal>
#include <cstdio>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <deque>
#include <map>
#include <mutex>
#include <thread>

#include <websocketpp/config/asio_no_tls.hpp>
#include <websocketpp/server.hpp>

#include "pmuctl/record/mcap_recording.hpp"  // human_bytes
#include "pmuctl/serve/client_backlog.hpp"

namespace pmu::tools {
namespace {

using Server = websocketpp::server<websocketpp::config::asio>;
using Hdl = websocketpp::connection_hdl;
using foxglove::StatusLevel;

// Samples waiting for the server thread. Reached only if that thread is starved of CPU:
// past it samples are dropped for everyone rather than held without bound.
constexpr std::size_t kMaxPendingBytes = 8 * 1024 * 1024;
// The kernel's send buffer per client (it doubles it): what a client that does not read
// holds beyond the queue limit, so the limit is what bounds its memory and delay.
constexpr int kSocketSendBuffer = 64 * 1024;
// Largest client message: subscribe requests are small.
constexpr std::size_t kMaxClientMessage = 1024 * 1024;

}  // namespace

// Named, not anonymous: FoxgloveServer::Impl, which has external linkage, holds them.
namespace foxglove_server_parts {

using Instance = std::array<std::uint8_t, 16>;

struct Pending {
  std::uint32_t channel;
  std::uint64_t time_ns;
  Instance instance;
  std::vector<std::uint8_t> payload;
};

struct Client {
  std::string label;  // "127.0.0.1:54321"
  foxglove::ClientSubscriptions subscriptions;
  ClientBacklog backlog;
};

}  // namespace foxglove_server_parts

namespace {
using foxglove_server_parts::Client;
using foxglove_server_parts::Instance;
using foxglove_server_parts::Pending;
}  // namespace

struct FoxgloveServer::Impl {
  Impl(std::vector<foxglove::Channel> c, std::vector<bool> l, ServeOptions o, std::string n)
      : channels(std::move(c)), latched(std::move(l)), options(std::move(o)), name(std::move(n)),
        server_info(foxglove::server_info_json(name)), advertise(foxglove::advertise_json(channels)) {}

  std::vector<foxglove::Channel> channels;
  std::vector<bool> latched;  // by channel id
  ServeOptions options;
  std::string name;
  std::string server_info;
  std::string advertise;

  Server server;
  std::thread thread;
  std::map<Hdl, Client, std::owner_less<Hdl>> clients;  // the server thread's only
  // The last message of each instance of the latched channels (one per device: bounded by the
  // devices the domain has). The server thread's only.
  std::map<std::pair<std::uint32_t, Instance>, Pending> last_state;

  std::mutex pending_mutex;  // publish() and the drain
  std::deque<Pending> pending;
  std::vector<std::pair<foxglove::Channel, bool>> added;  // add_channel(), before the samples pending
  std::size_t pending_bytes = 0;
  bool drain_posted = false;

  std::atomic<std::size_t> client_count{0};
  std::atomic<std::uint64_t> forwarded{0};
  std::atomic<std::uint64_t> dropped{0};

  Server::connection_ptr connection(Hdl h) {
    std::error_code ec;
    auto con = server.get_con_from_hdl(std::move(h), ec);
    return ec ? nullptr : con;
  }

  bool validate(Hdl h) {
    const auto con = connection(h);
    if (!con) return false;
    const auto& offered = con->get_requested_subprotocols();
    if (std::find(offered.begin(), offered.end(), foxglove::kSubprotocol) != offered.end()) {
      std::error_code ec;
      con->select_subprotocol(std::string(foxglove::kSubprotocol), ec);
      return !ec;
    }
    std::fprintf(stderr, "pmuctl serve: refused %s: it does not offer the WebSocket subprotocol %s\n",
                 con->get_remote_endpoint().c_str(), std::string(foxglove::kSubprotocol).c_str());
    con->set_status(websocketpp::http::status_code::bad_request);
    con->set_body("pmuctl serve speaks the Foxglove WebSocket protocol: offer the subprotocol " +
                  std::string(foxglove::kSubprotocol) + "\n");
    return false;
  }

  // A plain HTTP request (a browser opening the address): say what this is.
  void http(Hdl h) {
    if (const auto con = connection(h)) {
      con->set_status(websocketpp::http::status_code::upgrade_required);
      con->set_body("pmuctl serve: a Foxglove WebSocket server (subprotocol " + std::string(foxglove::kSubprotocol) +
                    "); in Foxglove or Lichtblick open a connection to ws://" + endpoint_label(options) + "\n");
    }
  }

  void open(Hdl h) {
    const auto con = connection(h);
    if (!con) return;
    const std::string label = con->get_remote_endpoint();
    clients.emplace(h, Client{label, foxglove::ClientSubscriptions(channels.size()),
                              ClientBacklog(options.client_queue)});
    client_count = clients.size();
    // The spec's first messages; not subject to the queue limit (the queue is empty).
    con->send(server_info, websocketpp::frame::opcode::text);
    con->send(advertise, websocketpp::frame::opcode::text);
    std::fprintf(stderr, "pmuctl serve: client %s connected\n", label.c_str());
  }

  void close(Hdl h) {
    const auto it = clients.find(h);
    if (it == clients.end()) return;  // a refused handshake never became a client
    const auto& c = it->second;
    if (c.backlog.dropping())
      std::fprintf(stderr, "pmuctl serve: client %s disconnected; %llu messages were dropped for it (it did not read)\n",
                   c.label.c_str(), static_cast<unsigned long long>(c.backlog.episode_dropped()));
    else
      std::fprintf(stderr, "pmuctl serve: client %s disconnected\n", c.label.c_str());
    clients.erase(it);
    client_count = clients.size();
  }

  void message(Hdl h, Server::message_ptr msg) {
    const auto it = clients.find(h);
    const auto con = connection(h);
    if (it == clients.end() || !con) return;
    auto& client = it->second;
    const std::string& payload = msg->get_payload();
    std::vector<bool> had(channels.size());
    for (std::uint32_t c = 0; c < channels.size(); ++c) had[c] = client.subscriptions.subscription(c).has_value();
    const auto replies =
        msg->get_opcode() == websocketpp::frame::opcode::text
            ? client.subscriptions.on_text(payload)
            : client.subscriptions.on_binary(reinterpret_cast<const std::uint8_t*>(payload.data()), payload.size());
    for (const auto& r : replies) con->send(r, websocketpp::frame::opcode::text);
    // A new subscription to a state channel gets the current state at once.
    for (const auto& [key, sample] : last_state)
      if (!had[key.first]) send_to(client, con, sample);
  }

  void drain() {
    std::deque<Pending> batch;
    std::vector<std::pair<foxglove::Channel, bool>> new_channels;
    {
      std::lock_guard<std::mutex> lock(pending_mutex);
      batch.swap(pending);
      new_channels.swap(added);
      pending_bytes = 0;
      drain_posted = false;
    }
    for (auto& [channel, state] : new_channels) {
      const std::string one = foxglove::advertise_json({channel});
      channels.push_back(std::move(channel));
      latched.push_back(state);
      for (auto& [h, client] : clients) {
        client.subscriptions.add_channel();
        if (const auto con = connection(h); con && con->get_state() == websocketpp::session::state::open)
          con->send(one, websocketpp::frame::opcode::text);
      }
    }
    if (!new_channels.empty()) advertise = foxglove::advertise_json(channels);
    for (auto& p : batch) {
      for (auto& [h, client] : clients)
        if (const auto con = connection(h)) send_to(client, con, p);
      if (p.channel < latched.size() && latched[p.channel])
        last_state[{p.channel, p.instance}] = std::move(p);
    }
  }

  // One message for one client, if it subscribed to the channel and its queue has room.
  void send_to(Client& client, const Server::connection_ptr& con, const Pending& p) {
    const auto sub = client.subscriptions.subscription(p.channel);
    if (!sub || con->get_state() != websocketpp::session::state::open) return;
    const std::string frame = foxglove::message_data(*sub, p.time_ns, p.payload.data(), p.payload.size());
    const auto v = client.backlog.offer(con->get_buffered_amount(), frame.size());
    if (v.change == ClientBacklog::Change::Began)
      std::fprintf(stderr, "pmuctl serve: client %s is not reading (%s queued): dropping its messages until it "
                           "catches up\n", client.label.c_str(), human_bytes(con->get_buffered_amount()).c_str());
    if (!v.send) {
      ++dropped;
      return;
    }
    if (v.change == ClientBacklog::Change::Ended) {
      std::fprintf(stderr, "pmuctl serve: client %s reads again; %llu messages were dropped for it\n",
                   client.label.c_str(), static_cast<unsigned long long>(v.dropped));
      con->send(foxglove::status_json(StatusLevel::Warning,
                                      std::to_string(v.dropped) + " messages were dropped for this client: it did "
                                      "not read them in time (pmuctl serve holds " +
                                          human_bytes(options.client_queue) + " per client)"),
                websocketpp::frame::opcode::text);
    }
    if (!con->send(frame, websocketpp::frame::opcode::binary)) ++forwarded;
  }
};

FoxgloveServer::FoxgloveServer(std::vector<foxglove::Channel> channels, std::vector<bool> latched,
                               ServeOptions options, std::string name)
    : impl_(std::make_unique<Impl>(std::move(channels), std::move(latched), std::move(options), std::move(name))) {}

FoxgloveServer::~FoxgloveServer() { stop(); }

std::string FoxgloveServer::start() {
  Impl& m = *impl_;
  const std::string where = endpoint_label(m.options);
  // A peer that vanishes mid-write must not kill the process (asio also sends with MSG_NOSIGNAL).
  std::signal(SIGPIPE, SIG_IGN);
  std::error_code ec;
  m.server.clear_access_channels(websocketpp::log::alevel::all);  // it would print to stdout
  m.server.clear_error_channels(websocketpp::log::elevel::all);
  m.server.init_asio(ec);
  if (ec) return "cannot start the WebSocket server: " + ec.message();
  m.server.set_reuse_addr(true);  // a restart need not wait for TIME_WAIT; a listener still holds the port
  m.server.set_max_message_size(kMaxClientMessage);
  // After accept (the socket init handler runs before it, on a socket not yet open).
  m.server.set_tcp_pre_init_handler([&m](Hdl h) {
    if (const auto con = m.connection(std::move(h))) {
      std::error_code ignored;
      auto& s = con->get_raw_socket();
      s.set_option(asio::socket_base::send_buffer_size(kSocketSendBuffer), ignored);
      s.set_option(asio::ip::tcp::no_delay(true), ignored);  // small messages, live: no Nagle delay
    }
  });
  m.server.set_validate_handler([&m](Hdl h) { return m.validate(std::move(h)); });
  m.server.set_http_handler([&m](Hdl h) { m.http(std::move(h)); });
  m.server.set_open_handler([&m](Hdl h) { m.open(std::move(h)); });
  m.server.set_close_handler([&m](Hdl h) { m.close(std::move(h)); });
  m.server.set_fail_handler([&m](Hdl h) { m.close(std::move(h)); });
  m.server.set_message_handler([&m](Hdl h, Server::message_ptr msg) { m.message(std::move(h), std::move(msg)); });

  const auto address = asio::ip::make_address(m.options.address, ec);
  if (ec) return "cannot listen on " + where + ": " + ec.message();
  m.server.listen(asio::ip::tcp::endpoint(address, m.options.port), ec);
  if (ec) return "cannot listen on " + where + ": " + ec.message();
  m.server.start_accept(ec);
  if (ec) return "cannot accept on " + where + ": " + ec.message();
  m.thread = std::thread([&m] {
    for (;;) {
      try {
        m.server.run();
        return;  // stop()
      } catch (const std::exception& e) {  // not expected: say it and keep serving
        std::fprintf(stderr, "pmuctl serve: server thread: %s\n", e.what());
      }
    }
  });
  return {};
}

void FoxgloveServer::publish(std::uint32_t channel, std::uint64_t time_ns, const std::array<std::uint8_t, 16>& instance,
                             std::vector<std::uint8_t>&& payload) {
  Impl& m = *impl_;
  bool post = false;
  {
    std::lock_guard<std::mutex> lock(m.pending_mutex);
    if (m.pending_bytes + payload.size() > kMaxPendingBytes) {
      ++m.dropped;
      return;
    }
    m.pending_bytes += payload.size();
    m.pending.push_back(Pending{channel, time_ns, instance, std::move(payload)});
    post = !m.drain_posted;
    m.drain_posted = true;
  }
  if (post) asio::post(m.server.get_io_service(), [&m] { m.drain(); });
}

void FoxgloveServer::add_channel(foxglove::Channel channel, bool latched) {
  Impl& m = *impl_;
  bool post = false;
  {
    std::lock_guard<std::mutex> lock(m.pending_mutex);
    m.added.emplace_back(std::move(channel), latched);
    post = !m.drain_posted;
    m.drain_posted = true;
  }
  if (post) asio::post(m.server.get_io_service(), [&m] { m.drain(); });
}

FoxgloveServer::Counters FoxgloveServer::counters() const {
  return Counters{impl_->client_count.load(), impl_->forwarded.load(), impl_->dropped.load()};
}

void FoxgloveServer::stop() {
  Impl& m = *impl_;
  if (!m.thread.joinable()) return;
  asio::post(m.server.get_io_service(), [&m] {
    std::error_code ignored;
    m.server.stop_listening(ignored);
    for (auto& entry : m.clients)
      m.server.close(entry.first, websocketpp::close::status::going_away, "pmuctl serve is stopping", ignored);
  });
  // Clients that read answer the close at once; one that does not is not waited for long.
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(2);
  while (m.client_count.load() > 0 && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  m.server.stop();
  m.thread.join();
}

}  // namespace pmu::tools
