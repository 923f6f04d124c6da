#pragma once
// Hot standby's topics on DDS (interface.md 1.10, docs/design.md "Hot standby"): writes this
// instance's pmu/role heartbeat, hands every pmu/role sample of its vehicle written by another
// participant to the holder, and answers the pmu/role_move requests addressed to this instance
// on pmu/role_move_reply. The only place that converts between the service's plain values
// (pmu/redundancy/role.hpp) and pmu::v5::RoleHeartbeat / RoleMove / RoleMoveReply, each sample
// once, by total functions (pmu/dds/role_sample.hpp).
//
//   DdsRoleEndpoint role(dds, cfg.vehicle);
//   role.on_report([&](const redundancy::RoleReport& r, std::chrono::steady_clock::time_point at) {...});
//   role.on_move(name, [&](const redundancy::MoveRequest& m) { return holder.move(m); });
//   role.start();
//   role.publish(report);  // every heartbeat_period and on every change
//
// What is delivered: every sample of this vehicle whose enumerators are the IDL's, with the
// steady time it was taken, including the peer's and any other instance's (the holder keeps
// its peer's by name). Never this participant's own samples (a reader matches the writer of its
// own participant): dropped, counted in own(). A sample of another vehicle (a writer in every
// partition) is dropped and counted in not_ours(); one with an enumerator outside its literals
// is dropped and counted in malformed(), logged at most every 10 s.
//
// Moves: a request whose vehicle is this one and whose instance is `name`, from a writer in
// this vehicle's partition alone (as commands, interface.md 7.1), not expired by the wall clock
// (expires_at 0: not expired), calls the move function once and writes its result; a resend of
// the same id by the same writer is answered with the first result, never moved twice. Every
// move is logged: `audit: role move ID from REQUESTER (SENDER) -> accepted|refused: reason`.
// Requests for the peer are the peer's to answer: ignored.
//
// Lifetime and threads: `dds` outlives the endpoint. on_report() and on_move() before start();
// their functions run on Fast DDS's listener threads (one sample at a time per reader, the two
// readers possibly at once) until stop() returns, and must not block; nothing thrown escapes
// into Fast DDS. publish() from any thread. stop() (also the destructor) waits for a running
// callback.

#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>

#include "pmu/dds/dds_context.hpp"
#include "pmu/redundancy/role.hpp"
#include "pmu/redundancy/role_machine.hpp"

namespace pmu::service {

// Steady time a sample arrived, and the wall time (ns since the Unix epoch) move requests expire
// by: the system's clocks unless a test gives its own.
struct RoleEndpointClocks {
  std::function<std::chrono::steady_clock::time_point()> steady = [] { return std::chrono::steady_clock::now(); };
  std::function<std::uint64_t()> wall_ns = [] {
    return static_cast<std::uint64_t>(
        std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::system_clock::now().time_since_epoch())
            .count());
  };
};

class DdsRoleEndpoint {
 public:
  using ReportFn = std::function<void(const redundancy::RoleReport&, std::chrono::steady_clock::time_point arrived)>;
  using MoveFn = std::function<redundancy::MoveResult(const redundancy::MoveRequest&)>;
  using Clocks = RoleEndpointClocks;

  // Makes the pmu/role writer and the pmu/role_move_reply writer. Throws dds::DdsError at
  // start-up when Fast DDS refuses one (with DDS-Security: permissions that lack the topics).
  DdsRoleEndpoint(dds::DdsContext& dds, std::string vehicle, Clocks clocks = {});
  ~DdsRoleEndpoint();
  DdsRoleEndpoint(const DdsRoleEndpoint&) = delete;
  DdsRoleEndpoint& operator=(const DdsRoleEndpoint&) = delete;

  void on_report(ReportFn fn);
  void on_move(std::string name, MoveFn fn);
  // Makes the readers: pmu/role when on_report was given, pmu/role_move when on_move was.
  // Throws dds::DdsError like the constructor. Once.
  void start();
  // When it returns no callback runs or will. Idempotent.
  void stop();
  // Writes `report` under this vehicle; false when Fast DDS refused the write (logged).
  bool publish(const redundancy::RoleReport& report);

  std::uint64_t own() const noexcept;        // this participant's own samples, not delivered
  std::uint64_t not_ours() const noexcept;   // samples and requests of another vehicle or partition
  std::uint64_t malformed() const noexcept;  // samples whose enumerators are not the IDL's
  std::uint64_t expired() const noexcept;    // move requests past their expires_at, not answered

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace pmu::service
