#include "pmuctl/verbs/config_file_verbs.hpp"

#include <unistd.h>

#include <CLI/CLI.hpp>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <fastdds/dds/core/status/SubscriptionMatchedStatus.hpp>
#include <fastdds/dds/subscriber/InstanceState.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <thread>
#include <utility>

#include "pmu/baseline/apply_plan.hpp"
#include "pmu/baseline/config_diff.hpp"
#include "pmu/baseline/config_file.hpp"
#include "pmu/command/command.hpp"
#include "pmu/dds/baseline_sample.hpp"
#include "pmu/dds/command_sample.hpp"
#include "pmu/dds/dds_context.hpp"
#include "pmu/files/bounded_file.hpp"
#include "pmu/idl/guarded_type.hpp"
#include "pmu/idl/state.h"
#include "pmu/idl/statePubSubTypes.h"
#include "pmu/idl/topics.hpp"
#include "pmu/mcap/output_file.hpp"
#include "pmuctl/call/command_channel.hpp"
#include "pmuctl/call/exit_status.hpp"
#include "pmuctl/call/service_presence.hpp"
#include "pmuctl/call/context_lease.hpp"

namespace pmu::tools {
// A namespace of its own: the unity builds put this file in one translation unit with the
// other verbs, whose helpers have the same names.
namespace config_file_verbs {
namespace {

using namespace eprosima::fastdds::dds;
using Clock = std::chrono::steady_clock;
using Json = nlohmann::json;
using baseline::Setting;

Clock::time_point deadline_after(double seconds) {
  return Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seconds));
}

using service::settings_of;  // pmu/config as raw wire values (dds/baseline_sample.hpp)

// The chosen PMU's pmu/config and pmu/info as the service publishes them (TRANSIENT_LOCAL:
// the current values come at once), kept up to date while the verb runs.
class DeviceReader {
 public:
  DeviceReader(pmu::dds::DdsContext& dds, std::string vehicle)
      : vehicle_(std::move(vehicle)),
        config_(dds.reader(dds.topic(topics::kConfig, TypeSupport(new idl::Guarded<pmu::v5::ConfigPubSubType>())),
                           qos_profiles::kState)),
        info_(dds.reader(dds.topic(topics::kInfo, TypeSupport(new idl::Guarded<pmu::v5::DeviceInfoPubSubType>())),
                         qos_profiles::kState)),
        baseline_(dds.reader(dds.topic(topics::kBaseline, TypeSupport(new idl::Guarded<pmu::v5::BaselinePubSubType>())),
                             qos_profiles::kState)),
        health_(dds.reader(dds.topic(topics::kHealth, TypeSupport(new idl::Guarded<pmu::v5::HealthPubSubType>())),
                           qos_profiles::kState)) {}

  void poll() {
    SampleInfo si;
    pmu::v5::Config c;
    while (config_.take_next_sample(&c, &si) == ReturnCode_t::RETCODE_OK)
      if (si.valid_data && c.vehicle().to_string() == vehicle_) configs_[{c.bus().to_string(), c.address()}] = c;
    pmu::v5::DeviceInfo i;
    while (info_.take_next_sample(&i, &si) == ReturnCode_t::RETCODE_OK)
      if (si.valid_data && i.vehicle().to_string() == vehicle_) infos_[{i.bus().to_string(), i.address()}] = i;
    pmu::v5::Health h;
    while (health_.take_next_sample(&h, &si) == ReturnCode_t::RETCODE_OK) {
      health_heard_ = health_heard_ || (si.valid_data && h.vehicle().to_string() == vehicle_);
      if (si.valid_data && h.vehicle().to_string() == vehicle_ && h.kind() == pmu::v5::KIND_PMU) {
        pmus_[si.instance_handle] = {h.bus().to_string(), h.address()};
      } else if (!si.valid_data && si.instance_state != ALIVE_INSTANCE_STATE) {
        pmus_.erase(si.instance_handle);  // disposed: a PMU that moved is no longer at its old address
      }
    }
    pmu::v5::Baseline b;
    while (baseline_.take_next_sample(&b, &si) == ReturnCode_t::RETCODE_OK) {
      if (si.valid_data) {
        if (b.vehicle().to_string() == vehicle_) baselines_[{b.bus().to_string(), b.address()}] = b;
      } else if (si.instance_state == NOT_ALIVE_DISPOSED_INSTANCE_STATE) {
        disposed_.insert(si.instance_handle);
      }
    }
  }
  // What the service said of the baseline of the PMU at (bus, address): its sample, that it
  // has none (the instance disposed, interface.md 1.9), or nothing yet. Each topic's samples
  // come on their own, so the PMU's configuration may well come before either.
  enum class Said { Nothing, NoBaseline, Baseline };
  Said baseline_said(const std::string& bus, std::uint16_t address) {
    if (baselines_.count({bus, address})) return Said::Baseline;
    pmu::v5::Baseline key;
    key.vehicle(vehicle_);
    key.bus(bus);
    key.address(address);
    InstanceHandle_t handle;
    if (baseline_key_.getKey(&key, &handle) && disposed_.count(handle)) return Said::NoBaseline;
    return Said::Nothing;
  }
  // Polls until the service has said either, or the deadline passed.
  Said await_baseline(const std::string& bus, std::uint16_t address, Clock::time_point deadline) {
    poll_until([&] { return baseline_said(bus, address) != Said::Nothing; }, deadline);
    return baseline_said(bus, address);
  }
  const pmu::v5::Baseline* baseline(const std::string& bus, std::uint16_t address) const {
    const auto it = baselines_.find({bus, address});
    return it == baselines_.end() ? nullptr : &it->second;
  }
  const pmu::v5::Config* config(const std::string& bus, std::uint16_t address) const {
    const auto it = configs_.find({bus, address});
    return it == configs_.end() ? nullptr : &it->second;
  }
  const pmu::v5::DeviceInfo* info(const std::string& bus, std::uint16_t address) const {
    const auto it = infos_.find({bus, address});
    return it == infos_.end() ? nullptr : &it->second;
  }
  // Whether the service serves a PMU at `address` on `bus` (a pmu/health instance: the
  // service's sessions, configured or discovered, read or not), as it judges an address
  // change (interface.md 2.6). Its health is TRANSIENT_LOCAL and comes in one burst: once
  // `own`'s has come, so have the others.
  bool pmu_served(const std::string& bus, std::uint16_t address, std::uint16_t own, Clock::time_point deadline) {
    const auto seen = [&](std::uint16_t a) {
      for (const auto& [handle, pmu] : pmus_)
        if (pmu.first == bus && pmu.second == a) return true;
      return false;
    };
    poll_until([&] { return seen(own); }, deadline);
    return seen(address);
  }
  // Both read, or the deadline passed.
  bool wait(const std::string& bus, std::uint16_t address, Clock::time_point deadline) {
    return poll_until([&] { return config(bus, address) && info(bus, address); }, deadline);
  }
  // Whether the vehicle's service sent its pmu/health during the call: a live service's
  // comes at once (TRANSIENT_LOCAL), with an instance for each PMU it serves, read or not.
  bool service_heard() const { return health_heard_; }
  // Whether this participant matched a service's pmu/health writer (an agent's worker still
  // matches a service that was killed, until its lease ends: service_presence.hpp).
  bool service_matched() const {
    SubscriptionMatchedStatus st;
    health_.get_subscription_matched_status(st);
    return st.current_count > 0;
  }

 private:
  // Polls until `done()`, or the deadline passed; whether `done()`.
  template <class Done>
  bool poll_until(Done done, Clock::time_point deadline) {
    for (;;) {
      poll();
      if (done()) return true;
      if (Clock::now() >= deadline) return false;
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
  }

  std::string vehicle_;
  DataReader& config_;
  DataReader& info_;
  DataReader& baseline_;
  DataReader& health_;
  // The key of a PMU's baseline instance, computed on this thread: the reader's type support
  // computes keys on Fast DDS's receive thread into a buffer of its own, so it is not shared.
  pmu::v5::BaselinePubSubType baseline_key_;
  std::map<InstanceHandle_t, std::pair<std::string, std::uint16_t>> pmus_;  // pmu/health of PMUs
  std::map<std::pair<std::string, std::uint16_t>, pmu::v5::Config> configs_;
  std::map<std::pair<std::string, std::uint16_t>, pmu::v5::Baseline> baselines_;
  std::set<InstanceHandle_t> disposed_;  // pmu/baseline instances of PMUs without one
  bool health_heard_ = false;            // a pmu/health sample of the vehicle came
  std::map<std::pair<std::string, std::uint16_t>, pmu::v5::DeviceInfo> infos_;
};

codec::FirmwareVersion firmware_of(const pmu::v5::DeviceInfo& i) { return {i.firmware_major(), i.firmware_minor()}; }

// The file's text, or the exit status after saying why it cannot be read.
// Regular and bounded only (the reader the service uses): `config diff /dev/zero` or a FIFO
// is refused at once, never read without end (docs/safety.md H12).
std::optional<std::string> read_text(const GlobalOptions& o, const std::string& path, int& status) {
  auto file = files::read_bounded_file(path, baseline::kMaxConfigFileBytes);
  if (!file.ok()) {
    status = fail(o, ExitStatus::BadUsage, path + ": cannot be read: " + file.error);
    return std::nullopt;
  }
  return std::move(file.text);
}

// The file read and checked, or the exit status (2) after saying FILE:LINE: what.
std::optional<baseline::ConfigFile> read_file(const GlobalOptions& o, const std::string& path, int& status) {
  const auto text = read_text(o, path, status);
  if (!text) return std::nullopt;
  auto f = baseline::read_config_file(*text);
  if (!f) {
    status = fail(o, ExitStatus::BadUsage, baseline::describe(f.error(), path));
    return std::nullopt;
  }
  return std::move(f).value();
}

// The PMU to work on and its configuration and identity, read from its service.
struct Target {
  std::string bus;
  std::uint16_t address = 0;
};
// Both of the PMU's state samples, or the exit status after saying which did not come and
// why. Only a service that answered (its pmu/health came) can be said not to have read the
// PMU: with --bus and --address nothing before this waited for the service, and a service
// that is not there, or whose discovery outlasted the wait, is "no pmu-service", as every
// verb says it.
std::optional<int> await_device(const GlobalOptions& o, const pmu::dds::DdsContext& dds, DeviceReader& device,
                                const std::string& vehicle, const Target& t, Clock::time_point deadline) {
  if (device.wait(t.bus, t.address, deadline)) return std::nullopt;
  if (!device.service_heard()) return device.service_matched() ? nothing_heard(o) : no_service(o, dds);
  return fail(o, ExitStatus::NoAnswer,
              device_label(vehicle, t.bus, t.address) + ": its " +
                  (device.config(t.bus, t.address) ? "identity (pmu/info)" : "configuration (pmu/config)") +
                  " did not come in time: the service has not read the PMU yet");
}

std::optional<Target> find_device(const GlobalOptions& o, pmu::dds::DdsContext& dds, DeviceReader& device,
                                  const std::string& vehicle, Clock::time_point deadline, int& status) {
  Target t;
  if (const auto failed = resolve_target(o, vehicle, dds, deadline, t.bus, t.address)) {
    status = *failed;
    return std::nullopt;
  }
  if (const auto failed = await_device(o, dds, device, vehicle, t, deadline)) {
    status = *failed;
    return std::nullopt;
  }
  return t;
}

// A participant that only reads (snapshot and diff need no command writer, which an identity
// of a mission computer may not be granted), and the PMU it found.
class ReadOnlyView {
 public:
  explicit ReadOnlyView(const GlobalOptions& o)
      : o_(o),
        vehicle_(o.vehicle.value_or(std::string())),
        lease_(o, kPmuctlParticipant),
        dds_(*lease_),
        device_(dds_, vehicle_) {}
  // nullopt with `status` set when there is none.
  std::optional<Target> find(int& status) { return find_device(o_, dds_, device_, vehicle_, deadline_, status); }
  Clock::time_point deadline() const { return deadline_; }
  const std::string& vehicle() const { return vehicle_; }
  DeviceReader& device() { return device_; }

 private:
  const GlobalOptions& o_;
  std::string vehicle_;
  ContextLease lease_;
  pmu::dds::DdsContext& dds_;
  DeviceReader device_;
  Clock::time_point deadline_ = wait_end(o_, 5.0);
};

std::string utc_now() {
  const std::time_t now = std::time(nullptr);
  std::tm tm{};
  gmtime_r(&now, &tm);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", &tm);
  return buf;
}

Json difference_json(const baseline::Difference& d) {
  return {{"name", std::string(baseline::setting_name(d.setting))},
          {"line", d.line},
          {"device", d.device ? Json(baseline::value_text(d.setting, *d.device)) : Json(nullptr)},
          {"file", baseline::value_text(d.setting, d.file)}};
}

// The plan's own action as a command sample, so what is sent is what its confirm rule was
// judged on.
CommandSpec command_for(Setting s, std::uint32_t raw, bool confirm) {
  pmu::v5::Command c;
  pmu::dds::put_action(baseline::action_for(s, raw), c);
  CommandSpec spec;
  spec.kind = static_cast<int>(c.kind());
  spec.parameter = c.parameter().to_string();
  spec.value = c.value();
  spec.outputs = c.outputs();
  spec.enable = c.enable();
  spec.confirm = confirm;
  return spec;
}

// "COMPLETED", or "TIMEOUT: no reply within 5.0 s".
std::string outcome_text(const CommandChannel::Outcome& out, double timeout) {
  if (!out.written) return "FAILED: the command could not be written to DDS";
  if (!out.reply) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "no reply within %.1f s", timeout);
    return buf;
  }
  const std::string reason = out.reply->reason().to_string();
  return std::string(result_name(out.reply->result())) + (reason.empty() ? "" : ": " + reason);
}
bool completed(const CommandChannel::Outcome& out) {
  return out.written && out.reply && out.reply->result() == pmu::v5::COMPLETED;
}

// A GET of one setting, under the name `config get` takes.
CommandSpec read_spec(Setting s) {
  CommandSpec spec;
  spec.kind = pmu::v5::GET;
  spec.parameter = std::string(baseline::setting_name(s));
  return spec;
}

// The raw value a GET of `s` read, from the reply's value in its unit (a mask or 0/1 for
// the switched states); nullopt when it read nothing.
std::optional<std::uint32_t> raw_value(Setting s, const CommandChannel::Outcome& out) {
  if (!completed(out) || !out.reply->has_value()) return std::nullopt;
  const auto p = baseline::parameter_of(s);
  const double raw = p ? out.reply->value() * codec::spec_of(*p).divisor : out.reply->value();
  if (!std::isfinite(raw) || raw < 0 || raw > 65535) return std::nullopt;
  return static_cast<std::uint32_t>(std::llround(raw));
}

// The commands of one apply (interface.md 2.8, docs/safety.md H11): each holds the device's
// configuration for this apply (groups bit 0x80, request ids APPLY#N, APPLY a request id of
// its own: "pmuctl-HOST-PID-NANOSECONDS", so a refusal names the holder's host and process),
// so another writer's change cannot land between them; the last gives the hold back. A
// service that knows no hold ignores the bits.
class HeldCommands {
 public:
  HeldCommands(CommandChannel& channel, std::string bus, double timeout)
      : channel_(channel), bus_(std::move(bus)), timeout_(timeout), apply_(request_id()) {}

  CommandChannel::Outcome send(CommandSpec spec, std::uint16_t address) {
    return send_with(std::move(spec), address, service::hold_bit::Hold);
  }
  // The apply's last command: a read of the outputs that releases the hold. Without its
  // reply the hold ends by itself at the expiry of the apply's latest command.
  void release(std::uint16_t address) {
    (void)send_with(read_spec(Setting::Outputs), address, service::hold_bit::Hold | service::hold_bit::Release);
  }

 private:
  CommandChannel::Outcome send_with(CommandSpec spec, std::uint16_t address, std::uint8_t bits) {
    spec.groups = bits;
    spec.request_id = apply_ + "#" + std::to_string(++sent_);
    return channel_.send(spec, bus_, address, timeout_);
  }

  CommandChannel& channel_;
  std::string bus_;
  double timeout_;
  std::string apply_;
  unsigned sent_ = 0;
};

// The plan's changes that need --confirm and do not have it, one message each.
std::vector<std::string> unconfirmed_in(const std::vector<baseline::Change>& plan, const std::string& file,
                                        bool confirm) {
  std::vector<std::string> out;
  for (const auto& c : plan)
    if (c.confirm && !confirm)
      out.push_back(file + ":" + std::to_string(c.line) + ": " + std::string(baseline::setting_name(c.setting)) + " " +
                    baseline::value_text(c.setting, c.to) + " " + std::string(service::rule_why(*c.confirm)) +
                    ": it needs --confirm (rule " + std::string(service::to_string(*c.confirm)) + ")");
  return out;
}
int refuse_unconfirmed(const GlobalOptions& o, const std::vector<std::string>& unconfirmed, const char* nothing) {
  for (std::size_t i = 0; i + 1 < unconfirmed.size(); ++i) std::fprintf(stderr, "pmuctl: %s\n", unconfirmed[i].c_str());
  return fail(o, ExitStatus::BadUsage, unconfirmed.back() + "; " + nothing);
}

}  // namespace

int snapshot(const GlobalOptions& o, const std::string& file, bool force) {
  if (file != "-" && !force && ::access(file.c_str(), F_OK) == 0)
    return fail(o, ExitStatus::BadUsage, file + ": exists; a snapshot never overwrites one (--force to replace it)");
  ReadOnlyView view(o);
  int status = 0;
  const auto t = view.find(status);
  if (!t) return status;
  const std::string& vehicle = view.vehicle();
  const DeviceReader& device = view.device();
  const auto& info = *device.info(t->bus, t->address);
  baseline::Header h;
  h.vehicle = vehicle;
  h.bus = t->bus;
  h.address = t->address;
  h.serial = info.serial_number();
  h.firmware = firmware_of(info);
  h.date = utc_now();
  const std::string text = baseline::write_config_file(h, settings_of(*device.config(t->bus, t->address)));
  // A unit may hold a value no set can write (a factory value, or one a newer firmware
  // wrote): such a file could never be applied, so it is not written.
  if (const auto back = baseline::read_config_file(text); !back)
    return fail(o, ExitStatus::NotDone,
                device_label(vehicle, t->bus, t->address) +
                    " holds a value no set can write, so a snapshot could not be " +
                    "applied: " + baseline::describe(back.error(), file == "-" ? "(stdout)" : file) +
                    "; the snapshot was not written");
  // The recordings' output file: a temporary file beside FILE, renamed over it only when
  // complete; "-" is standard output.
  pmu::mcap::OutputFile out;
  if (const auto why = out.open(file); !why.empty()) return fail(o, ExitStatus::BadUsage, why);
  int error = out.sink().write(reinterpret_cast<const std::uint8_t*>(text.data()), text.size());
  if (error == 0) error = out.close();
  if (error != 0) {
    out.discard();
    return fail(o, ExitStatus::NotDone, "the snapshot was not written: " + out.name() + ": " + std::strerror(error));
  }
  if (const auto why = out.commit(); !why.empty())
    return fail(o, ExitStatus::NotDone, "the snapshot was not written: " + why);
  if (out.streaming()) return 0;
  std::fprintf(stderr, "%s (serial %u, firmware %s): %zu settings written to %s\n",
               device_label(vehicle, t->bus, t->address).c_str(), unsigned{info.serial_number()},
               codec::to_string(firmware_of(info)).c_str(), baseline::kSettingCount, file.c_str());
  return 0;
}

int diff(const GlobalOptions& o, const std::string& path) {
  int status = 0;
  std::optional<baseline::ConfigFile> f;
  if (!path.empty()) {
    f = read_file(o, path, status);
    if (!f) return status;
  }
  ReadOnlyView view(o);
  const auto t = view.find(status);
  if (!t) return status;
  const std::string& vehicle = view.vehicle();
  DeviceReader& device = view.device();
  std::string file = path;
  if (!f) {
    switch (device.await_baseline(t->bus, t->address, view.deadline())) {
      case DeviceReader::Said::Baseline: break;
      case DeviceReader::Said::NoBaseline:
        return fail(o, ExitStatus::BadUsage,
                    "no baseline configured for PMU " + device_label(vehicle, t->bus, t->address) +
                        " (pmu-service.yaml `baseline:`, interface.md 1.9): name a file, pmuctl config diff FILE");
      case DeviceReader::Said::Nothing:
        return fail(o, ExitStatus::NoAnswer,
                    device_label(vehicle, t->bus, t->address) + ": its service did not say within the timeout " +
                        "whether it has a baseline (pmu/baseline, interface.md 1.9): name a file, pmuctl config " +
                        "diff FILE");
    }
    const auto* b = device.baseline(t->bus, t->address);
    f = service::config_file_of(*b);
    file = b->file().to_string();
  }
  const auto have = settings_of(*device.config(t->bus, t->address));
  const auto diffs = baseline::differences(have, *f);
  const auto missing = baseline::not_in_file(have, *f);
  const std::size_t compared = baseline::kSettingCount - missing.size();
  const std::string label = device_label(vehicle, t->bus, t->address);
  const auto& info = *device.info(t->bus, t->address);
  const bool other_unit = f->header.serial && *f->header.serial != info.serial_number();
  // A baseline's serial pins it to one unit (serial_differs, interface.md 1.7): another unit
  // is a difference of its own, so it is never "matches" (exit 1). A file named here was
  // only read from a unit, which the summary mentions.
  const bool serial_differs = other_unit && path.empty();
  const bool equal = diffs.empty() && !serial_differs;
  if (o.json) {
    Json j{
        {"vehicle", vehicle}, {"bus", t->bus},        {"address", t->address},        {"file", file},
        {"equal", equal},     {"compared", compared}, {"differences", Json::array()}, {"not_in_file", Json::array()}};
    if (serial_differs)
      j["differences"].push_back({{"name", "serial"},
                                  {"line", 0},
                                  {"device", std::to_string(info.serial_number())},
                                  {"file", std::to_string(*f->header.serial)}});
    for (const auto& d : diffs) j["differences"].push_back(difference_json(d));
    for (const auto s : missing) j["not_in_file"].push_back(std::string(baseline::setting_name(s)));
    std::printf("%s\n", j.dump(-1, ' ', false, Json::error_handler_t::replace).c_str());
  } else {
    if (serial_differs)
      std::printf("%s: serial: device %u, baseline %u: another unit than the baseline's\n", file.c_str(),
                  unsigned{info.serial_number()}, unsigned{*f->header.serial});
    for (const auto& d : diffs)
      if (d.line > 0)
        std::printf("%s:%d: %s\n", file.c_str(), d.line, baseline::describe(d).c_str());
      else  // the service's baseline: its lines are not published
        std::printf("%s: %s\n", file.c_str(), baseline::describe(d).c_str());
  }
  if (equal)
    std::fprintf(stderr, "%s matches %s (%zu settings)\n", label.c_str(), file.c_str(), compared);
  else if (diffs.empty())
    std::fprintf(stderr,
                 "%s differs from %s: it is another unit (serial %u, the baseline's %u); its %zu settings match\n",
                 label.c_str(), file.c_str(), unsigned{info.serial_number()}, unsigned{*f->header.serial}, compared);
  else
    std::fprintf(stderr, "%s differs from %s in %zu of %zu settings%s\n", label.c_str(), file.c_str(), diffs.size(),
                 compared, serial_differs ? ", and is another unit than the baseline's" : "");
  if (!missing.empty()) {
    std::string names;
    for (const auto s : missing) names += (names.empty() ? "" : ", ") + std::string(baseline::setting_name(s));
    std::fprintf(stderr, "not in the file, so not compared: %s\n", names.c_str());
  }
  if (other_unit && !path.empty())
    std::fprintf(stderr, "the file was read from serial %u; this PMU is serial %u\n", unsigned{*f->header.serial},
                 unsigned{info.serial_number()});
  return static_cast<int>(equal ? ExitStatus::Ok : ExitStatus::NotDone);
}

int apply(const GlobalOptions& o, const std::string& file, bool dry_run, bool confirm, bool other_unit) {
  int status = 0;
  const auto f = read_file(o, file, status);
  if (!f) return status;
  const double timeout = o.timeout.value_or(5.0);
  CommandChannel channel(o);
  DeviceReader device(channel.dds(), channel.vehicle());
  std::string bus;
  std::uint16_t address = 0;
  if (const auto failed = channel.open(deadline_after(timeout), bus, address)) return *failed;
  if (const auto failed =
          await_device(o, channel.dds(), device, channel.vehicle(), {bus, address}, deadline_after(timeout)))
    return *failed;
  const std::string label = device_label(channel.vehicle(), bus, address);
  const auto firmware = firmware_of(*device.info(bus, address));

  // Everything is judged before the first frame: a file this device cannot take is refused
  // whole.
  if (const auto e = baseline::check_firmware(*f, firmware))
    return fail(o, ExitStatus::BadUsage,
                baseline::describe(*e, file) + " (" + label + " has firmware " + codec::to_string(firmware) + ")");
  if (f->header.min_firmware && firmware < *f->header.min_firmware)
    return fail(o, ExitStatus::BadUsage,
                file + ":" + std::to_string(f->min_firmware_line) + ": " + label + " has firmware " +
                    codec::to_string(firmware) + ", older than min_firmware " +
                    codec::to_string(*f->header.min_firmware));
  // A file read from another unit is that unit's configuration: applied only when the
  // operator says so (interface.md 3.2), as a diff says it of another serial.
  const auto serial = device.info(bus, address)->serial_number();
  if (f->header.serial && *f->header.serial != serial && !other_unit)
    return fail(o, ExitStatus::BadUsage,
                file + ":" + std::to_string(f->serial_line) + ": the file was read from serial " +
                    std::to_string(*f->header.serial) + ", and " + label + " is serial " + std::to_string(serial) +
                    ": another unit; nothing was sent (--other-unit applies it to this unit)");
  // Judged first on the configuration the service publishes: a file with nothing to change,
  // or with a change that lacks --confirm, sends nothing at all.
  const auto seen = baseline::apply_plan(baseline::differences(settings_of(*device.config(bus, address)), *f));
  // The service refuses a can_address another PMU it serves has (interface.md 2.6); judged
  // here too, so that the dry run says what the apply would meet and the apply sends nothing.
  for (const auto& c : seen)
    if (c.setting == Setting::CanAddress && c.to != address &&
        device.pmu_served(bus, static_cast<std::uint16_t>(c.to), address, deadline_after(timeout)))
      return fail(o, ExitStatus::BadUsage,
                  file + ":" + std::to_string(c.line) + ": can_address " + std::to_string(c.to) + ": address " +
                      std::to_string(c.to) + " is already in use on " + bus + " (a PMU the service serves); " +
                      "nothing was sent");
  if (seen.empty()) {
    std::fprintf(stderr, "%s already matches %s: nothing to apply\n", label.c_str(), file.c_str());
    return 0;
  }
  if (dry_run) {
    for (std::size_t i = 0; i < seen.size(); ++i) {
      const auto& c = seen[i];
      const std::string rule =
          c.confirm ? " (needs --confirm: " + std::string(service::to_string(*c.confirm)) + ")" : std::string();
      std::printf("%zu. %s:%d: %s: %s -> %s%s\n", i + 1, file.c_str(), c.line,
                  std::string(baseline::setting_name(c.setting)).c_str(),
                  baseline::value_text(c.setting, c.from).c_str(), baseline::value_text(c.setting, c.to).c_str(),
                  rule.c_str());
    }
    std::fprintf(stderr, "%s: %zu change(s) to apply from %s; nothing was sent (--dry-run)\n", label.c_str(),
                 seen.size(), file.c_str());
    return 0;
  }
  if (const auto unconfirmed = unconfirmed_in(seen, file, confirm); !unconfirmed.empty())
    return refuse_unconfirmed(o, unconfirmed, "nothing was sent");

  // Then under the apply's hold (interface.md 2.8, docs/safety.md H11), from the device
  // itself: pmu/config may not yet show another writer's last change, and each change's
  // undo must know the value it replaces. A hold another apply has is refused here, before
  // anything changed.
  HeldCommands held(channel, bus, timeout);
  baseline::Settings read;
  for (std::size_t i = 0; i < baseline::kSettingCount; ++i) {
    const auto s = static_cast<Setting>(i);
    if (!f->settings[s]) continue;
    const auto out = held.send(read_spec(s), address);
    read[s] = raw_value(s, out);
    if (read[s]) continue;
    const bool denied = out.reply && out.reply->result() == pmu::v5::DENIED;
    if (!denied) held.release(address);
    return fail(o, ExitStatus::NotDone,
                label + ": " + file + " not applied: reading " + std::string(baseline::setting_name(s)) + ": " +
                    outcome_text(out, timeout) + "; nothing was changed");
  }
  const auto plan = baseline::apply_plan(baseline::differences(read, *f));
  if (plan.empty()) {
    held.release(address);
    std::fprintf(stderr, "%s already matches %s: nothing to apply\n", label.c_str(), file.c_str());
    return 0;
  }
  if (const auto unconfirmed = unconfirmed_in(plan, file, confirm); !unconfirmed.empty()) {
    held.release(address);
    return refuse_unconfirmed(o, unconfirmed, "nothing was changed");
  }

  Json changes = Json::array();
  std::vector<const baseline::Change*> applied;
  std::string failure;
  std::uint16_t at = address;  // the unit's address now: can_address, applied last, moves it
  for (const auto& c : plan) {
    const auto out = held.send(command_for(c.setting, c.to, confirm && c.confirm), at);
    const std::string result = outcome_text(out, timeout);
    // One line per change, like the service's audit line for the command.
    std::fprintf(stderr, "%s: %s %s -> %s: %s\n", label.c_str(), std::string(baseline::setting_name(c.setting)).c_str(),
                 baseline::value_text(c.setting, c.from).c_str(), baseline::value_text(c.setting, c.to).c_str(),
                 result.c_str());
    changes.push_back({{"name", std::string(baseline::setting_name(c.setting))},
                       {"from", baseline::value_text(c.setting, c.from)},
                       {"to", baseline::value_text(c.setting, c.to)},
                       {"result", result}});
    if (!completed(out)) {
      failure = std::string(baseline::setting_name(c.setting)) + " (" + result + ")";
      break;
    }
    applied.push_back(&c);
    if (c.setting == Setting::CanAddress) at = static_cast<std::uint16_t>(c.to);
  }

  if (!failure.empty()) {
    // Undo, newest first, what this apply changed and nothing else: each setting goes back to
    // the value it replaced only while the device still holds the value the apply set
    // (compare, then set, under the hold: docs/safety.md H11). A value someone else wrote
    // since is theirs and stays. Each restore is sent confirmed: it returns the device to a
    // state it was in.
    Json restored = Json::array();
    std::size_t ok = 0, others = 0;
    for (auto it = applied.rbegin(); it != applied.rend(); ++it) {
      const auto& c = **it;
      const std::string name(baseline::setting_name(c.setting));
      const auto now_out = held.send(read_spec(c.setting), at);
      const auto now = raw_value(c.setting, now_out);
      std::string result;
      switch (baseline::undo_of(c, now)) {
        case baseline::Undo::Restore: {
          const auto out = held.send(command_for(c.setting, c.from, true), at);
          result = outcome_text(out, timeout);
          std::fprintf(stderr, "%s: restored %s to %s: %s\n", label.c_str(), name.c_str(),
                       baseline::value_text(c.setting, c.from).c_str(), result.c_str());
          if (completed(out)) ++ok;
          if (c.setting == Setting::CanAddress && completed(out)) at = static_cast<std::uint16_t>(c.from);
          break;
        }
        case baseline::Undo::ChangedByAnother:
          ++others;
          result = "NOT RESTORED: the device holds " + baseline::value_text(c.setting, *now) + ", not the " +
                   baseline::value_text(c.setting, c.to) + " this apply set: another writer changed it since";
          std::fprintf(stderr, "%s: %s %s; left as it is\n", label.c_str(), name.c_str(), result.c_str());
          break;
        case baseline::Undo::NotRead:
          result = "NOT RESTORED: its value could not be read (" + outcome_text(now_out, timeout) + ")";
          std::fprintf(stderr, "%s: %s %s; left as it is\n", label.c_str(), name.c_str(), result.c_str());
          break;
      }
      restored.push_back({{"name", name}, {"to", baseline::value_text(c.setting, c.from)}, {"result", result}});
    }
    held.release(at);
    const std::string summary =
        "apply stopped at " + failure + "; " + std::to_string(ok) + " of " + std::to_string(applied.size()) +
        " applied change(s) restored" +
        (others ? "; " + std::to_string(others) + " changed by another writer since, left as they are" : "") +
        (ok == applied.size() ? "" : ": THE DEVICE IS PARTLY CHANGED, see the lines above");
    std::fprintf(stderr, "%s: %s\n", label.c_str(), summary.c_str());
    if (o.json) {
      Json j{{"vehicle", channel.vehicle()},
             {"bus", bus},
             {"address", address},
             {"file", file},
             {"applied", false},
             {"changes", changes},
             {"restored", restored},
             {"reason", summary},
             {"exit_status", static_cast<int>(ExitStatus::NotDone)}};
      std::printf("%s\n", j.dump(-1, ' ', false, Json::error_handler_t::replace).c_str());
    }
    return static_cast<int>(ExitStatus::NotDone);
  }
  held.release(at);

  // Each change was read back by the service; the final diff is the file against the whole
  // configuration as the service now publishes it (at the unit's address now).
  std::vector<baseline::Difference> left;
  const auto settle = deadline_after(timeout);
  for (;;) {
    device.poll();
    const auto* now = device.config(bus, at);
    left = now ? baseline::differences(settings_of(*now), *f) : baseline::differences({}, *f);
    if (left.empty() || Clock::now() >= settle) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  const std::string final_label = device_label(channel.vehicle(), bus, at);
  for (const auto& d : left) std::printf("%s:%d: %s\n", file.c_str(), d.line, baseline::describe(d).c_str());
  if (left.empty())
    std::fprintf(stderr, "%s: %zu change(s) applied; it matches %s\n", final_label.c_str(), plan.size(), file.c_str());
  else
    std::fprintf(stderr, "%s: %zu change(s) applied and verified, but it still differs from %s in %zu setting(s)\n",
                 final_label.c_str(), plan.size(), file.c_str(), left.size());
  if (o.json) {
    Json j{{"vehicle", channel.vehicle()},
           {"bus", bus},
           {"address", at},
           {"file", file},
           {"applied", left.empty()},
           {"changes", changes},
           {"differences", Json::array()}};
    for (const auto& d : left) j["differences"].push_back(difference_json(d));
    std::printf("%s\n", j.dump(-1, ' ', false, Json::error_handler_t::replace).c_str());
  }
  return static_cast<int>(left.empty() ? ExitStatus::Ok : ExitStatus::NotDone);
}

}  // namespace config_file_verbs

int run_config_snapshot(const GlobalOptions& o, const std::string& file, bool force) {
  return config_file_verbs::snapshot(o, file, force);
}
int run_config_diff(const GlobalOptions& o, const std::string& file) { return config_file_verbs::diff(o, file); }
int run_config_apply(const GlobalOptions& o, const std::string& file, bool dry_run, bool confirm, bool other_unit) {
  return config_file_verbs::apply(o, file, dry_run, confirm, other_unit);
}

namespace {

// config snapshot FILE [--force], config diff [FILE], config apply FILE [--dry-run] [--other-unit].
class ConfigFileVerbs : public Verb {
 public:
  ConfigFileVerbs(CLI::App& config, const bool& confirm) : confirm_(confirm) {
    snapshot_ = config.add_subcommand(
        "snapshot", "Write the PMU's configuration to a file (- for stdout): what `config apply` reads back");
    snapshot_->add_option("file", file_, "The file to write; an existing one is kept unless --force")->required();
    snapshot_->add_flag("--force", force_, "Replace an existing file");
    diff_ = config.add_subcommand(
        "diff", "Compare the PMU with a configuration file (exit 0 equal, 1 different, 2 bad file, 3 no answer)");
    diff_->add_option("file", file_,
                      "A file written by `config snapshot` or by hand; without it the service's baseline of "
                      "the PMU (pmu-service.yaml `baseline:`)");
    apply_ = config.add_subcommand(
        "apply", "Write what differs from a configuration file, verified, in a safe order; undone on a failure");
    apply_->add_option("file", file_, "A file written by `config snapshot` or by hand")->required();
    apply_->add_flag("--dry-run", dry_run_, "Check the file and print the changes in order; send nothing");
    apply_->add_flag("--other-unit", other_unit_,
                     "Apply a file read from another unit (its device.serial is not this PMU's); refused "
                     "without it");
  }
  bool chosen() const override { return *snapshot_ || *diff_ || *apply_; }
  int run(GlobalOptions& g) override {
    if (*snapshot_) return run_config_snapshot(g, file_, force_);
    if (*diff_) return run_config_diff(g, file_);
    return run_config_apply(g, file_, dry_run_, confirm_, other_unit_);
  }

 private:
  const bool& confirm_;
  CLI::App* snapshot_;
  CLI::App* diff_;
  CLI::App* apply_;
  std::string file_;
  bool force_ = false, dry_run_ = false, other_unit_ = false;
};

}  // namespace

std::unique_ptr<Verb> add_config_file_verbs(CLI::App& config, const bool& confirm) {
  return std::make_unique<ConfigFileVerbs>(config, confirm);
}

}  // namespace pmu::tools
