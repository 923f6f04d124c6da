// pmu-service: owns the CAN buses, speaks the PMU protocol, publishes on DDS
// (interface.md section 3.1). Start-up errors (config, bus, DDS) end the process with a
// message and a non-zero status before anything is sent on a bus; after start-up nothing
// throws, and SIGTERM stops it cleanly within a second.

#include <signal.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <future>
#include <cstdlib>
#include <memory>
#include <optional>
#include <spdlog/spdlog.h>
#include <string>
#include <thread>
#include <vector>

#include "pmu/energy_sink/energy_tracker.hpp"
#include "pmu/readiness/readiness_tracker.hpp"
#include "pmu/app/logging.hpp"
#include "pmu/app/state_fanout.hpp"
#include "pmu/app/simulated_bus.hpp"
#include "pmu/app/systemd.hpp"
#include "pmu/config/config.hpp"
#include "pmu/dds_settings/statistics_settings.hpp"
#include "pmu/dds_settings/vehicle.hpp"
#include "pmu/dds/dds_context.hpp"
#include "pmu/dispatch/command_service.hpp"
#include "pmu/endpoints/dds_alarm_acks.hpp"
#include "pmu/endpoints/dds_commands.hpp"
#include "pmu/endpoints/dds_publisher.hpp"
#include "pmu/endpoints/dds_role.hpp"
#include "pmu/endpoints/ros2_publisher.hpp"
#include "pmu/endpoints/startup_check.hpp"
#include "pmu/session/bus_worker.hpp"
#include "pmu/session/moved_addresses.hpp"
#include "pmu/session/receive_filters.hpp"
#include "pmu/standby/fenced_bus.hpp"
#include "pmu/standby/ownership.hpp"
#include "pmu/standby/role_gate.hpp"
#include "pmu/standby/role_holder.hpp"
#include "pmu/sysconf_dir.hpp"
#include "pmu/transport/socketcan_bus.hpp"
#include "pmu/transport/stop_signals.hpp"
#include "pmu/version.hpp"

namespace {

using namespace pmu;
using std::chrono::milliseconds;

constexpr const char* kDefaultConfig = PMU_SYSCONFDIR "/pmu-service.yaml";

// Everything one bus needs, torn down in reverse order.
struct BusRuntime {
  std::unique_ptr<transport::SimulatedNetwork> network;  // --bus sim only
  std::unique_ptr<sim::BusRunner> simulator;             // --bus sim only
  std::unique_ptr<service::BusWorker> worker;
  std::thread thread;
};

std::unique_ptr<transport::CanBus> open_bus(const service::BusConfig& bus, const transport::Clock& clock,
                                            BusRuntime& rt, bool standby_pair) {
  if (bus.interface != "sim") {
    transport::SocketCanOptions options;
    options.filters = service::receive_filters(bus);
    // The peer's CAN heartbeats (docs/design.md, "The CAN heartbeat frame").
    if (standby_pair) options.filters.push_back({redundancy::kCanBeatIdBase, 0x1FFFFF00u, true});
    auto b = bus.interface.rfind("fd:", 0) == 0
                 ? transport::SocketCanBus::adopt(transport::UniqueFd(std::stoi(bus.interface.substr(3))), bus.name,
                                                  options, clock)
                 : transport::SocketCanBus::open(bus.interface, options, clock);
    if (!b->has_socket()) {
      spdlog::warn(
          "{}: interface {} does not exist yet: waiting for it (pmu/health bus_state DOWN), bound when it "
          "appears",
          bus.name, bus.interface);
      return b;
    }
    const auto& r = b->report();
    spdlog::info("{}: SocketCAN open, receive buffer {} bytes{}, kernel filters {}, timestamps {}", bus.name,
                 r.receive_buffer_bytes, r.receive_buffer_forced ? " (forced)" : "", r.kernel_filters ? "on" : "off",
                 r.kernel_timestamps ? "kernel" : "user");
    return b;
  }
  auto simulated = service::make_simulated_bus(bus, clock);
  rt.network = std::move(simulated.network);
  rt.simulator = std::move(simulated.simulator);
  return std::move(simulated.service_end);
}

// Called on the main thread while the workers run: only their thread-safe counters.
std::string summary(const std::vector<BusRuntime>& buses) {
  std::size_t devices = 0;
  for (const auto& b : buses) devices += b.worker->device_count();
  return "serving " + std::to_string(devices) + " PMU(s) on " + std::to_string(buses.size()) + " bus(es)";
}

int run(const service::Config& cfg, const pmu::dds::ResolvedNetwork& network) {
  // Before any thread starts, so that every thread inherits the blocked mask.
  transport::StopSignals stop({SIGHUP});

  transport::SystemClock clock;
  service::SystemdNotifier systemd;

  milliseconds longest{0};
  for (const auto& b : cfg.buses)
    for (const auto& d : b.devices) longest = std::max(longest, d.period);
  if (longest == milliseconds{0}) longest = milliseconds(1000);
  // Batteries and MPPTs send each value once per their period; a heard one is taken as 1 s.
  milliseconds canopen_longest{1000};
  bool canopen = false;
  for (const auto& b : cfg.buses) {
    canopen |= b.wants_canopen();
    for (const auto& d : b.batteries) canopen_longest = std::max(canopen_longest, d.period);
    for (const auto& d : b.mppts) canopen_longest = std::max(canopen_longest, d.period);
    canopen_longest = std::max(canopen_longest, b.canopen_publish_period);
  }

  spdlog::info("DDS: {}", network.summary);
  const auto partitions = pmu::dds::vehicle_partitions(cfg.vehicle);
  pmu::dds::DdsContext participant(cfg.domain, cfg.qos_file, pmu::dds::kServiceParticipantName, cfg.security.files,
                                   cfg.dds_transport, network, {partitions, partitions}, cfg.dds_statistics,
                                   cfg.dds_type_objects);
  // The link's values (link_profile.hpp): the participant took them from `network`.
  if (network.link.profile != pmu::dds::LinkProfile::None || network.link.round_trip.set())
    for (const auto& line : network.link.explain()) spdlog::info("DDS: {}", line);
  if (cfg.dds_type_objects) spdlog::info("DDS: type objects announced (dds_type_objects)");
  if (!cfg.dds_statistics.empty())
    spdlog::info("DDS: Fast DDS statistics on: {}", pmu::dds::statistics_property(cfg.dds_statistics));
  if (participant.secure())
    spdlog::info("DDS-Security on: identity {}, permissions {}", cfg.security.files.identity_certificate,
                 cfg.security.files.permissions);
  const auto canopen_deadline = canopen ? std::optional<milliseconds>(3 * canopen_longest) : std::nullopt;
  service::DdsPublisher publisher(participant, 3 * longest, cfg.vehicle, cfg.low_rate_period, canopen_deadline);
  // also_serve_contract: the previous contract's names on a participant of their own (one
  // participant cannot have two topics of one name), with the same values and commands.
  // Declared after the service's own, so destroyed before it.
  std::unique_ptr<pmu::dds::DdsContext> previous_participant;
  std::unique_ptr<service::DdsPublisher> previous_publisher;
  if (cfg.also_serve_contract) {
    previous_participant = std::make_unique<pmu::dds::DdsContext>(
        cfg.domain, cfg.qos_file, pmu::dds::kServiceParticipantName, cfg.security.files, cfg.dds_transport, network,
        pmu::dds::Partitions{partitions, partitions}, std::vector<std::string>{}, false, *cfg.also_serve_contract);
    previous_publisher = std::make_unique<service::DdsPublisher>(*previous_participant, 3 * longest, cfg.vehicle,
                                                                 cfg.low_rate_period, canopen_deadline);
    spdlog::info("DDS: also serving contract v{} on a second participant (also_serve_contract)",
                 *cfg.also_serve_contract);
  }
  // Once, before any session reads a device: a reader compares pmu/config with it.
  publisher.publish_baselines(cfg.buses);
  for (const auto& b : cfg.buses)
    for (const auto& d : b.devices)
      if (d.baseline) spdlog::info("{}/{}: watched against baseline {}", b.name, d.address, d.baseline_path);
  std::vector<service::StateSink*> sinks{&publisher};
  if (previous_publisher) sinks.push_back(previous_publisher.get());
  // ROS 2's names and types, on the service's own participant (this build's contract).
  std::unique_ptr<pmu::service::Ros2Publisher> ros2;
  if (cfg.ros2.enabled) {
    ros2 = std::make_unique<pmu::service::Ros2Publisher>(participant, cfg.ros2, cfg.vehicle, cfg.buses, clock);
    sinks.push_back(ros2.get());
    spdlog::info("ROS 2: sensor_msgs/BatteryState and /diagnostics under '{}' (ros2)",
                 cfg.ros2.name_space.empty() ? "/" : cfg.ros2.name_space);
  }
  service::StateFanout fanout(sinks);
  // One of a hot-standby pair: the state topics are written only while this instance owns the
  // bus (docs/design.md, "Hot standby"); the trackers behind the gate keep running.
  std::unique_ptr<standby::RoleGate> gate;
  if (cfg.redundancy)
    gate = std::make_unique<standby::RoleGate>(fanout, [&publisher, &previous_publisher] {
      publisher.clear_histories();
      if (previous_publisher) previous_publisher->clear_histories();
    });
  service::StateSink& published = gate ? static_cast<service::StateSink&>(*gate) : fanout;
  // In front of the publishers: pmu/readiness from what the sessions report.
  service::ReadinessTracker readiness(cfg.buses, cfg.timeouts.stale_periods, published, clock);
  // In front of readiness: pmu/energy from each PMU's voltages and currents.
  service::EnergyTracker state_sink(cfg.buses, cfg.timeouts.stale_periods, readiness);

  std::unique_ptr<standby::RoleHolder> holder;
  // pmu/role and pmu/role_move, on the service's own participant (the current contract's).
  std::unique_ptr<service::DdsRoleEndpoint> role_topics;
  // `commands` exists once the workers do, before they run.
  service::CommandService* commands_ptr = nullptr;
  std::unique_ptr<standby::Ownership> ownership;
  service::BusWorker* pair_worker = nullptr;  // the pair's one bus, once its worker exists
  if (cfg.redundancy) {
    // What the former owner left: each recorded request settled once (failover_record.hpp).
    ownership = std::make_unique<standby::Ownership>(*gate, [&commands_ptr, &clock] {
      if (commands_ptr) commands_ptr->took_over(clock.steady_now());
    });
    role_topics = std::make_unique<service::DdsRoleEndpoint>(participant, cfg.vehicle);
    standby::RoleHolder::Outputs outputs;
    outputs.publish = [&role_topics](const redundancy::RoleReport& r) { role_topics->publish(r); };
    // A peer that joins while this instance owns the bus hears the devices' stored values
    // answered, so its configuration is warm (docs/design.md, "Hot standby"). Posted: the
    // holder may be in the middle of a session's send.
    outputs.peer_joined = [&pair_worker] {
      if (pair_worker) pair_worker->post([w = pair_worker] { w->repeat_readings(); });
    };
    outputs.changed = [&ownership, &systemd, &holder](const standby::RoleChange& c) {
      ownership->on_change(c);
      if (c.from != c.to)
        spdlog::warn(
            "role: {} -> {} (term {}{})", redundancy::role_name(c.from), redundancy::role_name(c.to), c.term,
            c.alarm == redundancy::PeerAlarm::None ? "" : ", alarm " + std::string(redundancy::alarm_name(c.alarm)));
      else
        spdlog::warn("role: {}, alarm {}", redundancy::role_name(c.to), redundancy::alarm_name(c.alarm));
      if (holder) systemd.status(holder->status());
    };
    holder = std::make_unique<standby::RoleHolder>(*cfg.redundancy, clock.steady_now(), std::move(outputs));
    ownership->judge_with(*holder, clock);
    role_topics->on_report([&holder](const redundancy::RoleReport& r, std::chrono::steady_clock::time_point arrived) {
      holder->on_report(r, arrived);
    });
    role_topics->on_move(cfg.redundancy->name, [&holder, &clock](const redundancy::MoveRequest&) {
      return holder->hand_over(clock.steady_now());
    });
    role_topics->start();
    spdlog::info("hot standby: instance {}, priority {}, peer {}; CAN heartbeat id 0x{:08X}", cfg.redundancy->name,
                 cfg.redundancy->priority, cfg.redundancy->peer, redundancy::can_beat_id(cfg.redundancy->priority));
  }
  service::MovedAddressStore moved(service::moved_addresses_path(std::getenv("STATE_DIRECTORY")), cfg);
  std::vector<BusRuntime> buses(cfg.buses.size());
  for (std::size_t i = 0; i < cfg.buses.size(); ++i) {
    auto bus = open_bus(cfg.buses[i], clock, buses[i], holder != nullptr);
    // What a standby hears of its peer's commands on the bus, for the takeover.
    if (holder)
      bus = std::make_unique<standby::FencedBus>(
          std::move(bus), *holder, clock,
          [&commands_ptr, &clock](const std::string& name, const transport::ReceivedFrame& rx) {
            if (commands_ptr) commands_ptr->heard_on_can(name, rx.frame, clock.steady_now());
          });
    buses[i].worker =
        std::make_unique<service::BusWorker>(cfg.buses[i], std::move(bus), clock, cfg.timeouts, state_sink);
    if (holder) {
      pair_worker = buses[i].worker.get();
      buses[i].worker->every(std::chrono::duration_cast<milliseconds>(redundancy::poll_period(holder->settings())),
                             [&holder, &ownership, &commands_ptr](std::chrono::steady_clock::time_point t) {
                               holder->tick(t);
                               // A request recorded just as the gate opened is settled here.
                               if (ownership->executing() && commands_ptr) commands_ptr->took_over(t);
                             });
    }
    // Only a device from the config file has an `address:` that can go stale.
    buses[i].worker->on_moved([&moved](const service::BusWorker::Moved& m) {
      if (!m.config_line.empty()) moved.record(m.bus, m.first, m.to, m.serial);
    });
    // A unit recorded as moved is followed by its serial before it is heard at its old address.
    for (const auto& m : moved.moves())
      if (auto* s = m.bus == cfg.buses[i].name && m.serial ? buses[i].worker->session(m.configured) : nullptr)
        s->expect_serial(*m.serial);
  }
  service::DdsCommandEndpoint command_topics(participant, &publisher, cfg.vehicle);
  std::unique_ptr<service::DdsCommandEndpoint> previous_command_topics;
  if (previous_participant)
    previous_command_topics =
        std::make_unique<service::DdsCommandEndpoint>(*previous_participant, previous_publisher.get(), cfg.vehicle);
  std::vector<service::BusWorker*> workers;
  for (auto& b : buses) workers.push_back(b.worker.get());
  // A reply goes out in both contracts: a ground station takes the replies to its own
  // request ids, whichever contract the others' commands came in.
  service::CommandService commands(workers, cfg.policy, cfg.timeouts, clock, [&](const service::CommandReplyData& r) {
    command_topics.publish(r);
    if (previous_command_topics) previous_command_topics->publish(r);
  });
  if (network.link.profile != pmu::dds::LinkProfile::None || network.link.round_trip.set()) commands.link_configured();
  if (ownership) {
    commands.set_role_gate([&ownership] { return ownership->executing(); });
    commands_ptr = &commands;
  }
  // Acknowledgements, like commands, in both contracts (they exist from contract v4 on, and
  // no version since changed their types), each reply in both.
  service::DdsAlarmAckEndpoint ack_topics(participant, cfg.vehicle);
  std::unique_ptr<service::DdsAlarmAckEndpoint> previous_ack_topics;
  if (previous_participant)
    previous_ack_topics = std::make_unique<service::DdsAlarmAckEndpoint>(*previous_participant, cfg.vehicle);
  service::AlarmAckService acks(workers, cfg.vehicle, cfg.policy.lifetimes, clock,
                                [&](const service::AlarmAckReplyData& r) {
                                  ack_topics.publish(r);
                                  if (previous_ack_topics) previous_ack_topics->publish(r);
                                });
  if (ownership) acks.set_role_gate([&ownership] { return ownership->executing(); });
  // Declared after everything the running threads use, so it is destroyed first, on every
  // way out of this function: commands stop first (no new request reaches `commands`, and
  // the bus workers are still there to finish the ones in flight), then the worker threads
  // end (nothing runs posted command work or writes a reply any more), and only then are
  // `commands`, the endpoint, the workers and the publisher destroyed.
  struct Shutdown {
    service::DdsCommandEndpoint& command_topics;
    service::DdsCommandEndpoint* previous_command_topics;
    service::DdsAlarmAckEndpoint& ack_topics;
    service::DdsAlarmAckEndpoint* previous_ack_topics;
    std::vector<BusRuntime>& buses;
    ~Shutdown() {
      command_topics.stop();
      ack_topics.stop();
      if (previous_command_topics) previous_command_topics->stop();
      if (previous_ack_topics) previous_ack_topics->stop();
      for (auto& b : buses) b.worker->stop();
      for (auto& b : buses) {
        if (b.thread.joinable()) b.thread.join();
        if (b.simulator) b.simulator->stop();
      }
      spdlog::info("pmu-service stopped");
    }
  } shutdown{command_topics, previous_command_topics.get(), ack_topics, previous_ack_topics.get(), buses};
  for (auto& b : buses) {
    if (b.simulator) b.simulator->start();
    b.thread = std::thread([w = b.worker.get()] { w->run(); });
  }
  command_topics.start(commands);
  // The owner's replies, for a standby's record of what it answered.
  if (holder) command_topics.follow_peer_replies();
  if (previous_command_topics) previous_command_topics->start(commands);
  ack_topics.start(acks);
  if (previous_ack_topics) previous_ack_topics->start(acks);
  spdlog::info("pmu-service ready on DDS domain {}: {}", cfg.domain, summary(buses));
  systemd.ready(summary(buses));

  // Feed the watchdog only while every bus loop keeps turning.
  const milliseconds check = systemd.watchdog_enabled()
                                 ? std::chrono::duration_cast<milliseconds>(systemd.watchdog_interval())
                                 : milliseconds(1000);
  std::vector<std::uint64_t> last(buses.size(), 0);
  for (;;) {
    if (const int sig = stop.wait_for(std::max(check, milliseconds(10)))) {
      spdlog::info("signal {} received: stopping", sig);
      break;
    }
    bool progressing = true;
    for (std::size_t i = 0; i < buses.size(); ++i) {
      const auto now = buses[i].worker->progress();
      if (now == last[i]) {
        progressing = false;
        spdlog::warn("bus {}: event loop made no progress in {} ms", cfg.buses[i].name, check.count());
      }
      last[i] = now;
    }
    if (progressing) systemd.watchdog();
    systemd.status((holder ? holder->status() + "; " : std::string()) + summary(buses) + ", " +
                   std::to_string(publisher.samples_written()) + " samples published");
  }

  // The bus owner hands over: its release on CAN and its LEAVING heartbeat, sent on the bus's
  // thread before the workers stop, so the peer claims at once (docs/design.md, "Hand-over").
  if (holder) {
    std::promise<void> left;
    auto done = left.get_future();
    buses.front().worker->post_urgent([&holder, &clock, &left] {
      holder->leave(clock.steady_now());
      holder->tick(clock.steady_now());
      left.set_value();
    });
    if (done.wait_for(milliseconds(500)) != std::future_status::ready)
      spdlog::warn("hot standby: the release was not sent within 500 ms; the peer takes over after can_silence");
  }
  systemd.stopping();
  return 0;
}

// check_startup's findings, printed: errors as "pmu-service: FILE:LINE: what is wrong",
// warnings (expiry within warn_days, a key readable by others) logged. The start and
// --check-config both come here, so they accept the same configurations. Sets the QoS file
// to the one checked, so that is the one the participant loads.
bool startup_ok(service::Config& cfg) {
  const auto check = service::check_startup(cfg);
  for (const auto& w : check.warnings) spdlog::warn("{}", w);
  for (const auto& e : check.errors) std::fprintf(stderr, "pmu-service: %s\n", e.c_str());
  if (!check.ok()) std::fprintf(stderr, "pmu-service: configuration rejected: not starting (nothing was sent)\n");
  cfg.qos_file = check.qos_file;
  return check.ok();
}

// discovery: and interfaces: with every name looked up (interfaces, host names), before any
// participant or bus is opened; --check-config does it too. A failure ends the start with
// exit status 1, like a bus that cannot be opened: the interface or the name server may be
// there at a later start (systemd restarts the unit), unlike a config error (status 2).
std::optional<pmu::dds::ResolvedNetwork> resolved_network(const service::Config& cfg) {
  try {
    return pmu::dds::resolve_network(cfg.network, pmu::dds::system_lookup());
  } catch (const pmu::dds::NetworkError& e) {
    std::fprintf(stderr, "pmu-service: %s\n", e.what());
    return std::nullopt;
  }
}

// --check-config: the configured addresses that the running service found moved (its state
// directory's record, moved_addresses.hpp). False, with FILE:LINE and the value to write, when
// one is stale.
bool addresses_current(const service::Config& cfg) {
  const auto path = service::moved_addresses_path(std::getenv("STATE_DIRECTORY"));
  const auto record = service::read_moved_addresses(path);
  for (const auto& e : record.errors) std::fprintf(stderr, "pmu-service: warning: %s (line ignored)\n", e.c_str());
  const auto stale = service::stale_addresses(cfg, record.moves);
  for (const auto& s : stale) std::fprintf(stderr, "pmu-service: %s\n", s.c_str());
  return stale.empty();
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"pmu-service: Millswood 250W PMUs on CAN, served on DDS"};
  app.set_version_flag("--version", "pmu-service " PMU_VERSION_TEXT);
  std::string config_path, bus_spec, log_level;
  std::optional<int> domain;
  bool check_only = false;
  app.add_option("--config", config_path, std::string("YAML config file (default ") + kDefaultConfig + ")");
  app.add_option("--bus", bus_spec,
                 "sim (built-in simulated PMU) or socketcan:IFACE; replaces the config's buses "
                 "(fd:N: an inherited fd carrying struct can_frame records, for benchmarks)");
  app.add_option("--domain", domain, "DDS domain id (0..232)")->check(CLI::Range(0, 232));
  app.add_option("--log-level", log_level, "trace, debug, info, warn, error, critical or off");
  app.add_flag("--check-config", check_only, "Validate the configuration and exit");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // app.exit prints the help or the reason; bad usage is exit status 2 (the man page),
    // not CLI11's own codes (105 for a value out of range).
    return app.exit(e) == 0 ? 0 : 2;
  }

  service::Config cfg;
  try {
    if (!config_path.empty()) {
      cfg = service::load_config(config_path);
    } else if (bus_spec.empty() ||
               ::access(kDefaultConfig, R_OK) == 0) {  // no open: a FIFO would block; load_config refuses one
      cfg = service::load_config(kDefaultConfig);
    } else {
      cfg = service::default_sim_config();
    }
    if (!bus_spec.empty()) service::override_bus(cfg, bus_spec);
    if (domain) cfg.domain = *domain;
  } catch (const service::ConfigError& e) {
    std::fprintf(stderr, "pmu-service: %s\n", e.what());
    return 2;
  }
  const std::string level = service::choose_log_level(log_level, cfg.log_level);
  if (!service::is_log_level(level)) {
    std::fprintf(stderr, "pmu-service: log level '%s' is not one of trace, debug, info, warn, error, critical, off\n",
                 level.c_str());
    return 2;
  }
  service::setup_logging(level);
  if (!startup_ok(cfg)) return 2;
  const auto network = resolved_network(cfg);
  if (!network) return 1;
  if (check_only) {
    if (!addresses_current(cfg)) return 2;
    std::printf("%s: configuration OK (%zu bus(es)%s)\n", cfg.source.c_str(), cfg.buses.size(),
                cfg.security.files.empty() ? "" : ", DDS-Security files OK");
    std::printf("%s: QoS profiles %s OK\n", cfg.source.c_str(), cfg.qos_file.c_str());
    std::printf("%s: DDS %s\n", cfg.source.c_str(), network->summary.c_str());
    // What `link:` sets, each value with the profile or the key it came from.
    for (const auto& line : network->link.explain()) std::printf("%s: %s\n", cfg.source.c_str(), line.c_str());
    return 0;
  }
  try {
    return run(cfg, *network);
  } catch (const std::exception& e) {
    spdlog::critical("cannot start: {}", e.what());
    return 1;
  }
}
