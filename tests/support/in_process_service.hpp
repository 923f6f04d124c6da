#pragma once
// pmu-service assembled in the test process as service/app/src/main.cpp assembles it (participant
// in its vehicle's partitions, publisher, one bus worker, command endpoint and service) on a
// simulated bus of its own with one simulated PMU at address 1 streaming every packet every
// 0.5 s. Header-only: a test target using it links pmu::dds and pmu::sim_runner.
//
//   pmu::test::InProcessService::Options o;
//   o.vehicle = "uav1";
//   pmu::test::InProcessService svc(domain, o);
#include <chrono>
#include <cstdint>
#include <string>
#include <thread>

#include "pmu/dds_settings/vehicle.hpp"
#include "pmu/dds/dds_context.hpp"
#include "pmu/dispatch/command_service.hpp"
#include "pmu/endpoints/dds_commands.hpp"
#include "pmu/endpoints/dds_publisher.hpp"
#include "pmu/session/bus_worker.hpp"
#include "pmu/sim/bus_runner.hpp"
#include "pmu/transport/sim_bus.hpp"

namespace pmu::test {

class InProcessService {
 public:
  struct Options {
    std::string vehicle;            // "" = the unnamed vehicle
    std::string bus_name = "sim0";  // the `bus` key of every sample
    dds::SecurityFiles security;    // empty: no DDS-Security
    dds::Transport transport = dds::Transport::Default;
    // A pause between creating the participant and the command endpoint: discovery of the
    // peers already on the domain is then over before the endpoint exists, as it can be in
    // pmu-service when its start-up is slow.
    std::chrono::milliseconds endpoint_delay{0};
  };

  InProcessService(int domain, const Options& o)
      : network(clock),
        pmus(network.attach("pmu-sim"), clock),
        dds(domain, "", dds::kServiceParticipantName, o.security, o.transport, {},
            {dds::vehicle_partitions(o.vehicle), dds::vehicle_partitions(o.vehicle)}),
        publisher(dds, std::chrono::seconds(3), o.vehicle),
        worker(bus_config(o.bus_name), network.attach(o.bus_name), clock, service::Timeouts{}, publisher),
        pause_(o.endpoint_delay),
        endpoint(dds, &publisher, o.vehicle),
        commands({&worker}, service::PolicyConfig{}, service::Timeouts{}, clock,
                 [this](const service::CommandReplyData& r) { endpoint.publish(r); }) {
    sim::DeviceConfig d;
    d.address = 1;
    d.parameters.set_raw(codec::Parameter::PacketPeriod, 5);  // 0.5 s
    d.parameters.set_raw(codec::Parameter::PacketsStreamed, 0x1F);
    pmus.add(d);
    pmus.start();
    thread_ = std::thread([this] { worker.run(); });
    endpoint.start(commands);
  }
  ~InProcessService() {
    endpoint.stop();
    worker.stop();
    thread_.join();
    pmus.stop();
  }
  InProcessService(const InProcessService&) = delete;
  InProcessService& operator=(const InProcessService&) = delete;

  // What the simulated unit itself holds: a command that executed changed these.
  std::uint8_t outputs() {
    std::uint8_t o = 0;
    pmus.with_model(1, [&](sim::PmuModel& m) { o = m.outputs(); });
    return o;
  }
  std::uint32_t parameter(codec::Parameter p) {
    std::uint32_t v = 0;
    pmus.with_model(1, [&](sim::PmuModel& m) { v = m.parameter(p); });
    return v;
  }
  std::uint64_t handled() {
    std::uint64_t n = 0;
    pmus.with_model(1, [&](sim::PmuModel& m) { n = m.counters().handled; });
    return n;
  }

  transport::SystemClock clock;
  transport::SimulatedNetwork network;
  sim::BusRunner pmus;
  dds::DdsContext dds;
  service::DdsPublisher publisher;
  service::BusWorker worker;

 private:
  struct Pause {
    explicit Pause(std::chrono::milliseconds d) { std::this_thread::sleep_for(d); }
  } pause_;

 public:
  service::DdsCommandEndpoint endpoint;
  service::CommandService commands;

 private:
  static service::BusConfig bus_config(const std::string& name) {
    service::BusConfig b;
    b.name = name;
    b.interface = "sim";
    service::DeviceConfig d;
    d.address = 1;
    d.period = std::chrono::milliseconds(500);
    b.devices.push_back(d);
    return b;
  }
  std::thread thread_;
};

}  // namespace pmu::test
