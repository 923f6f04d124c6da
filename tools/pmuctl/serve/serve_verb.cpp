#include "pmuctl/serve/serve_verb.hpp"

#include <unistd.h>

#include <CLI/CLI.hpp>
#include <cstdio>
#include <string_view>
#include <tuple>

#include "pmu/dds/dds_context.hpp"
#include "pmu/files/bounded_file.hpp"
#include "pmu/idl/topics.hpp"
#include "pmuctl/record/raw_topic_readers.hpp"
#include "pmuctl/serve/foxglove_server.hpp"
#include "pmu/transport/stop_signals.hpp"

namespace pmu::tools {
namespace {

std::string progress(const FoxgloveServer::Counters& c) {
  return std::to_string(c.clients) + (c.clients == 1 ? " client, " : " clients, ") + std::to_string(c.forwarded) +
         " messages forwarded, " + std::to_string(c.dropped) + " dropped";
}

// A certificate chain or key is a few kB; the bound keeps a wrong path (a log, a device) out.
constexpr std::size_t kMaxPemBytes = 1024 * 1024;

// --tls-cert's and --tls-key's files read and checked; "" or what is wrong and which file.
std::string load_tls(const ServeOptions& serve, TlsPem& pem) {
  for (const auto& [option, path, text] :
       {std::tuple{"--tls-cert", &serve.tls_cert, &pem.cert}, std::tuple{"--tls-key", &serve.tls_key, &pem.key}}) {
    auto file = pmu::files::read_bounded_file(*path, kMaxPemBytes);
    if (!file.ok()) return std::string(option) + " " + *path + " cannot be read: " + file.error;
    *text = std::move(file.text);
  }
  pem.cert_file = serve.tls_cert;
  pem.key_file = serve.tls_key;
  return check_tls(pem);
}

}  // namespace

int run_serve(const GlobalOptions& o, const ServeOptions& serve, const std::vector<std::string>& names) {
  std::vector<const RecordedTopic*> topics;
  Ros2Selection ros2;
  if (!forwarded_topics(o, names, "serve", topics, ros2)) return 2;
  // Channel id = index into `topics`, which is also the readers' topic index.
  std::vector<foxglove::Channel> channels;
  std::vector<bool> latched;
  for (std::uint32_t i = 0; i < topics.size(); ++i) {
    channels.push_back(foxglove::Channel{i, topics[i]->channel_name(), topics[i]->schema(), topics[i]->idl,
                                         topics[i]->schema_encoding()});
    const std::string_view profile = topics[i]->qos_profile;
    latched.push_back(profile == pmu::qos_profiles::kState || profile == pmu::qos_profiles::kAlarms);
  }

  TlsPem pem;
  if (serve.tls()) {
    if (const auto why = load_tls(serve, pem); !why.empty()) {
      std::fprintf(stderr, "pmuctl serve: %s\n", why.c_str());
      return 2;
    }
  } else if (!listens_on_loopback(serve)) {
    std::fprintf(stderr,
                 "pmuctl serve: warning: ws://%s is plain WebSocket: a page served over https (the Foxglove web "
                 "app) may not connect to it (mixed content), only the desktop apps and pages of http:// can; "
                 "give --tls-cert and --tls-key to serve wss://, or put a TLS proxy in front\n",
                 endpoint_label(serve).c_str());
  }

  pmu::transport::StopSignals stop;  // before the server's and Fast DDS's threads
  FoxgloveServer server(std::move(channels), std::move(latched), serve, "pmuctl serve (pmu-dds)", std::move(pem));
  if (const auto why = server.start(); !why.empty()) {
    std::fprintf(stderr, "pmuctl serve: %s\n", why.c_str());
    return 1;
  }
  // Declared after the server, so destroyed before it: no listener calls publish() on a
  // server that is gone.
  RawTopicReaders readers([&server](const RawSampleInfo& info, RawSample& sample) {
    server.publish(static_cast<std::uint32_t>(info.topic), info.time_ns, info.instance, std::move(sample.bytes));
  });
  {
    pmu::dds::DdsContext dds(o.domain, o.qos_file, "pmuctl-serve", o.security, pmu::dds::Transport::Default, o.network,
                             partitions_for(o));
    readers.open(dds, topics);
    // A ROS 2 topic, found in discovery, becomes a channel advertised to every client. Its
    // writer keeps its last message (TRANSIENT_LOCAL, keyless): latched, as the state topics,
    // with the sample's source timestamp, so an old message does not look new (docs/safety.md H7).
    Ros2Readers ros2_readers(std::move(ros2), o.vehicle, "serve");
    auto next_id = static_cast<std::uint32_t>(topics.size());
    const auto add_channel = [&server, &next_id](const RecordedTopic& t) {
      const std::uint32_t id = next_id++;
      server.add_channel(foxglove::Channel{id, t.channel_name(), t.schema(), t.idl, t.schema_encoding()}, true);
      return std::size_t{id};
    };
    ros2_readers.update(dds, readers, add_channel);
    std::fprintf(stderr,
                 "pmuctl serve: serving %zu topics of domain %d on %s://%s (Foxglove WebSocket, subprotocol %s); "
                 "Ctrl-C stops\n",
                 topics.size(), o.domain, serve.tls() ? "wss" : "ws", endpoint_label(serve).c_str(),
                 std::string(foxglove::kSubprotocols).c_str());
    const bool tty = ::isatty(STDERR_FILENO) == 1;
    for (int ticks = 1; stop.wait_for(std::chrono::seconds(1)) == 0; ++ticks) {
      ros2_readers.update(dds, readers, add_channel);
      if (tty)
        std::fprintf(stderr, "\r\033[Kpmuctl serve: %s", progress(server.counters()).c_str());
      else if (ticks % 10 == 0)
        std::fprintf(stderr, "pmuctl serve: %s\n", progress(server.counters()).c_str());
    }
    if (tty) std::fprintf(stderr, "\n");
  }  // the participant and its readers end here: nothing publishes after
  server.stop();
  std::fprintf(stderr, "pmuctl serve: stopped; %s\n", progress(server.counters()).c_str());
  return 0;
}

namespace {

class ServeVerb : public Verb {
 public:
  explicit ServeVerb(CLI::App& app) {
    serve_ = app.add_subcommand(
        "serve",
        "Serve the topics live to Foxglove or Lichtblick (Foxglove WebSocket protocol) until Ctrl-C or SIGTERM");
    serve_
        ->add_option("--listen", listen_,
                     "IP address to listen on (0.0.0.0: every interface; there is no authentication; a web page "
                     "served over https needs --tls-cert for a remote address)")
        ->type_name("ADDR")
        ->capture_default_str();
    serve_->add_option("--port", port_, "TCP port (Foxglove's default)")->type_name("N")->capture_default_str();
    serve_
        ->add_option("--client-queue", queue_,
                     "kB held for a client that does not read; beyond, its messages are dropped")
        ->type_name("KB")
        ->capture_default_str();
    serve_->add_option("--topic", topics_, "Only this topic, as for record; repeat for more (default: record's)")
        ->type_name("NAME")
        ->allow_extra_args(false);
    serve_
        ->add_option("--allow-origin", origins_,
                     "Also let pages of this origin connect (scheme://host[:port], exactly; '*': every page); "
                     "repeat for more (default: the Foxglove app, the Foxglove and Lichtblick desktop apps, pages "
                     "on localhost, and clients that send no Origin)")
        ->type_name("ORIGIN")
        ->allow_extra_args(false);
    serve_->add_option("--tls-cert", cert_, "Serve wss:// with this certificate (chain), PEM; with --tls-key")
        ->type_name("FILE");
    serve_->add_option("--tls-key", key_, "The certificate's private key, PEM, without a passphrase")->type_name("FILE");
  }
  bool chosen() const override { return serve_->parsed(); }
  std::optional<int> check(const GlobalOptions&) override {
    auto why = parse_serve_options(listen_, port_, queue_, options_);
    if (why.empty()) why = parse_serve_access(origins_, cert_, key_, options_);
    if (why.empty()) return std::nullopt;
    std::fprintf(stderr, "pmuctl serve: %s\n", why.c_str());
    return 2;
  }
  bool ends_by_itself() const override { return false; }
  int run(GlobalOptions& g) override { return run_serve(g, options_, topics_); }

 private:
  CLI::App* serve_;
  std::string listen_ = "127.0.0.1", port_ = "8765", queue_ = "1024";
  std::vector<std::string> topics_, origins_;
  std::string cert_, key_;
  ServeOptions options_;
};

}  // namespace

std::unique_ptr<Verb> add_serve_verb(CLI::App& app) { return std::make_unique<ServeVerb>(app); }

}  // namespace pmu::tools
