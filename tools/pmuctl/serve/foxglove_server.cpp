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

#include <openssl/err.h>
#include <openssl/ssl.h>
#include <openssl/x509.h>
#include <websocketpp/config/asio.hpp>  // asio (ws://) and asio_tls (wss://)
#include <websocketpp/server.hpp>

#include "pmuctl/record/mcap_recording.hpp"  // human_bytes
#include "pmuctl/serve/client_backlog.hpp"

namespace pmu::tools {
namespace {

using Hdl = websocketpp::connection_hdl;
using TlsContext = asio::ssl::context;
using foxglove::StatusLevel;

// Samples waiting for the server thread. Reached only if that thread is starved of CPU:
// past it samples are dropped for everyone rather than held without bound.
constexpr std::size_t kMaxPendingBytes = 8 * 1024 * 1024;
// The kernel's send buffer per client (it doubles it): what a client that does not read
// holds beyond the queue limit, so the limit is what bounds its memory and delay.
constexpr int kSocketSendBuffer = 64 * 1024;
// Largest client message: subscribe requests are small.
constexpr std::size_t kMaxClientMessage = 1024 * 1024;
// Longest Origin header quoted on stderr.
constexpr std::size_t kMaxOriginShown = 120;

// A client's Origin header as stderr shows it: printable ASCII only, shortened.
std::string shown_origin(const std::string& origin) {
  std::string s;
  for (const char c : origin.substr(0, kMaxOriginShown)) s.push_back(c >= 0x20 && c < 0x7F ? c : '?');
  return origin.size() > kMaxOriginShown ? s + "..." : s;
}

// The certificate chain and key as one context for every connection; nullptr and `why` (naming
// the file) when they do not parse or do not belong together.
std::shared_ptr<TlsContext> make_tls_context(const TlsPem& pem, std::string& why) {
  auto ctx = std::make_shared<TlsContext>(TlsContext::tls_server);
  ctx->set_options(TlsContext::default_workarounds | TlsContext::no_sslv2 | TlsContext::no_sslv3 |
                   TlsContext::no_tlsv1 | TlsContext::no_tlsv1_1 | TlsContext::single_dh_use);
  // OpenSSL would otherwise ask for a key's passphrase on the terminal.
  ctx->set_password_callback([](std::size_t, TlsContext::password_purpose) { return std::string(); });
  std::error_code ec;
  ctx->use_certificate_chain(asio::buffer(pem.cert), ec);
  if (ec) {
    why = "--tls-cert " + pem.cert_file + ": not a PEM certificate (chain): " + ec.message();
    return nullptr;
  }
  ctx->use_private_key(asio::buffer(pem.key), TlsContext::pem, ec);
  // OpenSSL checks the key against the certificate as it takes it.
  if (ec && ec.category() == asio::error::get_ssl_category() &&
      ERR_GET_REASON(static_cast<unsigned long>(ec.value())) == X509_R_KEY_VALUES_MISMATCH) {
    why = "--tls-key " + pem.key_file + " is not the private key of the certificate in --tls-cert " + pem.cert_file;
    return nullptr;
  }
  if (ec) {
    why = "--tls-key " + pem.key_file + ": not a PEM private key: " + ec.message();
    if (pem.key.find("ENCRYPTED") != std::string::npos)
      why += " (it is encrypted; give the key without a passphrase, e.g. openssl pkey -in KEY -out PLAIN)";
    return nullptr;
  }
  if (::SSL_CTX_check_private_key(ctx->native_handle()) != 1) {
    why = "--tls-key " + pem.key_file + " is not the private key of the certificate in --tls-cert " + pem.cert_file;
    return nullptr;
  }
  return ctx;
}

}  // namespace

std::string check_tls(const TlsPem& pem) {
  std::string why;
  make_tls_context(pem, why);
  return why;
}

// The parts both endpoints below (ws:// and wss://) hold.
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
  std::uint64_t time_sent = 0;  // the last Time message's, 0: none yet
};

}  // namespace foxglove_server_parts

namespace {
using foxglove_server_parts::Client;
using foxglove_server_parts::Instance;
using foxglove_server_parts::Pending;
}  // namespace

// What FoxgloveServer forwards to: one Endpoint for ws://, another for wss://.
struct FoxgloveServer::Impl {
  virtual ~Impl() = default;
  virtual std::string start() = 0;
  virtual void publish(std::uint32_t channel, std::uint64_t time_ns, const Instance& instance,
                       std::vector<std::uint8_t>&& payload) = 0;
  virtual void add_channel(foxglove::Channel channel, bool latched) = 0;
  virtual Counters counters() const = 0;
  virtual void stop() = 0;
};

namespace {

// The server on websocketpp's asio config (ws://) or asio_tls config (wss://).
template <class Config>
struct Endpoint final : FoxgloveServer::Impl {
  using Server = websocketpp::server<Config>;
  using Counters = FoxgloveServer::Counters;

  Endpoint(std::vector<foxglove::Channel> c, std::vector<bool> l, ServeOptions o, std::string n, TlsPem t)
      : channels(std::move(c)),
        latched(std::move(l)),
        options(std::move(o)),
        name(std::move(n)),
        tls(std::move(t)),
        server_info(foxglove::server_info_json(name)),
        advertise(foxglove::advertise_json(channels)) {}
  ~Endpoint() override { stop(); }

  std::vector<foxglove::Channel> channels;
  std::vector<bool> latched;  // by channel id
  ServeOptions options;
  std::string name;
  TlsPem tls;  // wss:// only
  std::shared_ptr<TlsContext> tls_context;
  std::string server_info;
  std::string advertise;

  Server server;
  std::thread thread;
  std::map<Hdl, Client, std::owner_less<Hdl>> clients;  // the server thread's only
  // The last message of each instance of the latched channels (one per device: bounded by the
  // devices the domain has). The server thread's only.
  std::map<std::pair<std::uint32_t, Instance>, Pending> last_state;
  // The server's clock (capability time): the newest source time forwarded; it never goes
  // back. 0 until the first sample. The server thread's only.
  std::uint64_t clock = 0;

  std::mutex pending_mutex;  // publish() and the drain
  std::deque<Pending> pending;
  std::vector<std::pair<foxglove::Channel, bool>> added;  // add_channel(), before the samples pending
  std::size_t pending_bytes = 0;
  bool drain_posted = false;

  std::atomic<std::size_t> client_count{0};
  std::atomic<std::uint64_t> forwarded{0};
  std::atomic<std::uint64_t> dropped{0};

  typename Server::connection_ptr connection(Hdl h) {
    std::error_code ec;
    auto con = server.get_con_from_hdl(std::move(h), ec);
    return ec ? nullptr : con;
  }

  bool validate(Hdl h) {
    const auto con = connection(h);
    if (!con) return false;
    // First the page: a site the operator did not allow learns nothing, not even the protocol.
    const std::string origin = con->get_request_header("Origin");
    if (!origin_allowed(options.origins, origin)) {
      const std::string shown = shown_origin(origin);
      OriginPolicy probe;
      const std::string how = add_allowed_origin(origin, probe).empty()
                                  ? "pmuctl serve --allow-origin " + shown + " allows it"
                                  : "it is no scheme://host[:port] origin; only --allow-origin '*' allows it";
      std::fprintf(stderr, "pmuctl serve: refused %s: origin %s is not allowed (%s)\n",
                   con->get_remote_endpoint().c_str(), shown.c_str(), how.c_str());
      con->set_status(websocketpp::http::status_code::forbidden);
      con->set_body("pmuctl serve: pages of origin " + shown + " may not connect (" + how + ")\n");
      return false;
    }
    const std::string_view chosen = foxglove::choose_subprotocol(con->get_requested_subprotocols());
    if (!chosen.empty()) {
      std::error_code ec;
      con->select_subprotocol(std::string(chosen), ec);
      return !ec;
    }
    std::fprintf(stderr, "pmuctl serve: refused %s: it does not offer the WebSocket subprotocol %s\n",
                 con->get_remote_endpoint().c_str(), std::string(foxglove::kSubprotocols).c_str());
    con->set_status(websocketpp::http::status_code::bad_request);
    con->set_body("pmuctl serve speaks the Foxglove WebSocket protocol: offer the subprotocol " +
                  std::string(foxglove::kSubprotocols) + "\n");
    return false;
  }


  // A plain HTTP request (a browser opening the address): say what this is.
  void http(Hdl h) {
    if (const auto con = connection(h)) {
      con->set_status(websocketpp::http::status_code::upgrade_required);
      con->set_body("pmuctl serve: a Foxglove WebSocket server (subprotocol " + std::string(foxglove::kSubprotocol) +
                    "); in Foxglove or Lichtblick open a connection to " + (options.tls() ? "wss://" : "ws://") +
                    endpoint_label(options) + "\n");
    }
  }

  void open(Hdl h) {
    const auto con = connection(h);
    if (!con) return;
    const std::string label = con->get_remote_endpoint();
    clients.emplace(h,
                    Client{label, foxglove::ClientSubscriptions(channels.size()), ClientBacklog(options.client_queue)});
    client_count = clients.size();
    // The spec's first messages; not subject to the queue limit (the queue is empty).
    con->send(server_info, websocketpp::frame::opcode::text);
    con->send(advertise, websocketpp::frame::opcode::text);
    if (clock != 0) send_time(clients.at(h), con);
    std::fprintf(stderr, "pmuctl serve: client %s connected (%s)\n", label.c_str(), con->get_subprotocol().c_str());
  }

  void close(Hdl h) {
    const auto it = clients.find(h);
    if (it == clients.end()) return;  // a refused handshake never became a client
    const auto& c = it->second;
    if (c.backlog.dropping())
      std::fprintf(stderr,
                   "pmuctl serve: client %s disconnected; %llu messages were dropped for it (it did not read)\n",
                   c.label.c_str(), static_cast<unsigned long long>(c.backlog.episode_dropped()));
    else
      std::fprintf(stderr, "pmuctl serve: client %s disconnected\n", c.label.c_str());
    clients.erase(it);
    client_count = clients.size();
  }

  void message(Hdl h, typename Server::message_ptr msg) {
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
    // A new subscription to a state channel gets the current state at once, stamped with the
    // server's clock where the sample is older (state published hours ago would otherwise
    // stretch a player's timeline back to then). It is the current state; whether a device is
    // live is pmu/health's state, not this time (docs/safety.md H7).
    for (const auto& [key, sample] : last_state)
      if (!had[key.first]) send_to(client, con, sample, std::max(sample.time_ns, clock));
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
    // The batch's newest source time is the clock; each client hears it (send_time) before
    // the batch's first message it gets.
    for (const auto& p : batch) clock = std::max(clock, p.time_ns);
    for (auto& p : batch) {
      for (auto& [h, client] : clients)
        if (const auto con = connection(h)) send_to(client, con, p, p.time_ns);
      if (p.channel < latched.size() && latched[p.channel]) last_state[{p.channel, p.instance}] = std::move(p);
    }
  }

  // The server's clock to a client that has not heard it yet. 9 bytes: not subject to the
  // queue limit, but sent only with a message that is.
  void send_time(Client& client, const typename Server::connection_ptr& con) {
    if (client.time_sent == clock) return;
    con->send(foxglove::time_message(clock), websocketpp::frame::opcode::binary);
    client.time_sent = clock;
  }

  // One message for one client, stamped `time_ns`, if it subscribed to the channel and its
  // queue has room.
  void send_to(Client& client, const typename Server::connection_ptr& con, const Pending& p, std::uint64_t time_ns) {
    const auto sub = client.subscriptions.subscription(p.channel);
    if (!sub || con->get_state() != websocketpp::session::state::open) return;
    const std::string frame = foxglove::message_data(*sub, time_ns, p.payload.data(), p.payload.size());
    const auto v = client.backlog.offer(con->get_buffered_amount(), frame.size());
    if (v.change == ClientBacklog::Change::Began)
      std::fprintf(stderr,
                   "pmuctl serve: client %s is not reading (%s queued): dropping its messages until it "
                   "catches up\n",
                   client.label.c_str(), human_bytes(con->get_buffered_amount()).c_str());
    if (!v.send) {
      ++dropped;
      return;
    }
    if (v.change == ClientBacklog::Change::Ended) {
      std::fprintf(stderr, "pmuctl serve: client %s reads again; %llu messages were dropped for it\n",
                   client.label.c_str(), static_cast<unsigned long long>(v.dropped));
      con->send(foxglove::status_json(StatusLevel::Warning, std::to_string(v.dropped) +
                                                                " messages were dropped for this client: it did "
                                                                "not read them in time (pmuctl serve holds " +
                                                                human_bytes(options.client_queue) + " per client)"),
                websocketpp::frame::opcode::text);
    }
    send_time(client, con);
    if (!con->send(frame, websocketpp::frame::opcode::binary)) ++forwarded;
  }

  std::string start() override;
  void publish(std::uint32_t channel, std::uint64_t time_ns, const Instance& instance,
               std::vector<std::uint8_t>&& payload) override;
  void add_channel(foxglove::Channel channel, bool state) override;
  Counters counters() const override { return Counters{client_count.load(), forwarded.load(), dropped.load()}; }
  void stop() override;
  // wss:// only: the context every connection shares.
  void set_tls_handler();
};

template <>
void Endpoint<websocketpp::config::asio>::set_tls_handler() {}

template <>
void Endpoint<websocketpp::config::asio_tls>::set_tls_handler() {
  server.set_tls_init_handler([this](Hdl) { return tls_context; });
}

template <class Config>
std::string Endpoint<Config>::start() {
  Endpoint& m = *this;
  const std::string where = endpoint_label(m.options);
  if (m.options.tls()) {
    std::string why;
    m.tls_context = make_tls_context(m.tls, why);
    if (!m.tls_context) return why;
  }
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
  m.server.set_message_handler(
      [&m](Hdl h, typename Server::message_ptr msg) { m.message(std::move(h), std::move(msg)); });
  m.set_tls_handler();

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
        return;                            // stop()
      } catch (const std::exception& e) {  // not expected: say it and keep serving
        std::fprintf(stderr, "pmuctl serve: server thread: %s\n", e.what());
      }
    }
  });
  return {};
}

template <class Config>
void Endpoint<Config>::publish(std::uint32_t channel, std::uint64_t time_ns, const Instance& instance,
                               std::vector<std::uint8_t>&& payload) {
  Endpoint& m = *this;
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

template <class Config>
void Endpoint<Config>::add_channel(foxglove::Channel channel, bool state) {
  Endpoint& m = *this;
  bool post = false;
  {
    std::lock_guard<std::mutex> lock(m.pending_mutex);
    m.added.emplace_back(std::move(channel), state);
    post = !m.drain_posted;
    m.drain_posted = true;
  }
  if (post) asio::post(m.server.get_io_service(), [&m] { m.drain(); });
}

template <class Config>
void Endpoint<Config>::stop() {
  Endpoint& m = *this;
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

}  // namespace

FoxgloveServer::FoxgloveServer(std::vector<foxglove::Channel> channels, std::vector<bool> latched, ServeOptions options,
                               std::string name, TlsPem tls) {
  if (options.tls())
    impl_ = std::make_unique<Endpoint<websocketpp::config::asio_tls>>(
        std::move(channels), std::move(latched), std::move(options), std::move(name), std::move(tls));
  else
    impl_ = std::make_unique<Endpoint<websocketpp::config::asio>>(std::move(channels), std::move(latched),
                                                                  std::move(options), std::move(name), TlsPem{});
}

FoxgloveServer::~FoxgloveServer() = default;  // the Endpoint stops

std::string FoxgloveServer::start() { return impl_->start(); }

void FoxgloveServer::publish(std::uint32_t channel, std::uint64_t time_ns, const std::array<std::uint8_t, 16>& instance,
                             std::vector<std::uint8_t>&& payload) {
  impl_->publish(channel, time_ns, instance, std::move(payload));
}

void FoxgloveServer::add_channel(foxglove::Channel channel, bool latched) {
  impl_->add_channel(std::move(channel), latched);
}

FoxgloveServer::Counters FoxgloveServer::counters() const { return impl_->counters(); }

void FoxgloveServer::stop() { impl_->stop(); }

}  // namespace pmu::tools
