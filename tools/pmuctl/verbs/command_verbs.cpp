#include "pmuctl/verbs/command_verbs.hpp"

#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fastdds/dds/core/status/PublicationMatchedStatus.hpp>
#include <fastdds/dds/core/status/SubscriptionMatchedStatus.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <map>
#include <optional>
#include <set>
#include <thread>
#include <vector>

#include "pmu/codec/ids.hpp"
#include "pmu/codec/messages.hpp"
#include "pmu/codec/parameters.hpp"
#include "pmu/command/command.hpp"
#include "pmu/dds/dds_context.hpp"
#include "pmu/idl/alarms.h"
#include "pmu/idl/alarmsPubSubTypes.h"
#include "pmu/idl/command.h"
#include "pmu/idl/commandPubSubTypes.h"
#include "pmu/idl/guarded_type.hpp"
#include "pmu/idl/state.h"
#include "pmu/idl/statePubSubTypes.h"
#include "pmu/idl/topics.hpp"
#include "pmuctl/verbs/alarm_names.hpp"
#include "pmuctl/call/command_channel.hpp"
#include "pmuctl/call/exit_status.hpp"
#include "pmuctl/call/service_presence.hpp"
#include "pmuctl/view/mask_names.hpp"
#include "pmuctl/view/sample_json.hpp"
#include "pmuctl/call/context_lease.hpp"

namespace pmu::tools {
namespace {

using namespace eprosima::fastdds::dds;
using Clock = std::chrono::steady_clock;

}  // namespace

int run_alarm_ack(const GlobalOptions& o, const std::string& code, const std::string& kind) {
  const double timeout = o.timeout.value_or(5.0);
  const auto deadline = wait_end(o, timeout);
  const std::string vehicle = o.vehicle.value_or(std::string());
  pmu::v5::AlarmSource source = pmu::v5::SOURCE_PMU;
  if (kind == "battery")
    source = pmu::v5::SOURCE_BATTERY;
  else if (kind == "mppt")
    source = pmu::v5::SOURCE_MPPT;
  else if (kind == "bus")
    source = pmu::v5::SOURCE_BUS;
  else if (kind != "pmu")
    return fail(o, ExitStatus::BadUsage, "--kind '" + pmu::service::printable(kind) + "': pmu, battery, mppt or bus");
  if (source == pmu::v5::SOURCE_BUS && o.bus.empty()) return fail(o, ExitStatus::BadUsage, "a bus alarm needs --bus");
  if ((source == pmu::v5::SOURCE_BATTERY || source == pmu::v5::SOURCE_MPPT) && (o.bus.empty() || !o.address))
    return fail(o, ExitStatus::BadUsage,
                "a " + kind + " alarm needs --bus and --address (the " +
                    (source == pmu::v5::SOURCE_BATTERY ? "CANopen node" : "MPPT device id") + ")");
  ContextLease lease(o, kPmuctlParticipant);
  pmu::dds::DdsContext& dds = *lease;
  DataReader& replies =
      dds.reader(dds.topic(topics::kAlarmAckReply, TypeSupport(new idl::Guarded<pmu::v5::AlarmAckReplyPubSubType>())),
                 qos_profiles::kCommand);
  DataWriter& writer =
      dds.writer(dds.topic(topics::kAlarmAck, TypeSupport(new pmu::v5::AlarmAckPubSubType())), qos_profiles::kCommand);
  std::string bus = o.bus;
  std::uint16_t device = source == pmu::v5::SOURCE_BUS ? 0 : o.address.value_or(0);
  if (source == pmu::v5::SOURCE_PMU)
    if (const auto failed = resolve_target(o, vehicle, dds, deadline, bus, device)) return *failed;
  if (const auto failed = wait_for_match(o, dds, writer, replies, vehicle, deadline, "accepts alarm acknowledgements"))
    return *failed;

  pmu::v5::AlarmAck a;
  const std::string id = request_id();
  a.request_id(id);
  a.vehicle(vehicle);
  a.bus(bus);
  a.kind(source);
  a.device(device);
  a.code(code);
  // The end of this wait, which finding the PMU and the match have used part of: an
  // acknowledgement pmuctl gave up on is never applied (docs/safety.md H9).
  a.expires_at(o.deadline_ns ? o.deadline_ns : epoch_ns_at(deadline));
  if (!writer.write(&a)) return fail(o, ExitStatus::NotDone, "the acknowledgement could not be written to DDS");

  // Unanswered after 1 s: sent again with the same id, which the service answers again and
  // never applies twice (interface.md 2.4, and 1.6 for acknowledgements).
  constexpr auto kResendAfter = std::chrono::seconds(1);
  auto next_resend = Clock::now() + kResendAfter;
  const auto wait_until = deadline + std::chrono::milliseconds(500);
  while (Clock::now() < wait_until) {
    if (Clock::now() >= next_resend && Clock::now() < deadline) {
      (void)writer.write(&a);
      next_resend = Clock::now() + kResendAfter;
    }
    pmu::v5::AlarmAckReply r;
    SampleInfo info;
    while (replies.take_next_sample(&r, &info) == ReturnCode_t::RETCODE_OK) {
      if (!info.valid_data || r.request_id().to_string() != id || r.vehicle().to_string() != vehicle) continue;
      const bool done = r.result() == pmu::v5::ACK_COMPLETED;
      const char* result = done ? "COMPLETED" : "REJECTED";
      if (o.json) {
        Json j{{"request_id", id},
               {"vehicle", r.vehicle().to_string()},
               {"bus", r.bus().to_string()},
               {"kind", kind},
               {"device", r.device()},
               {"code", r.code().to_string()},
               {"result", result},
               {"reason", r.reason().to_string()},
               {"state", alarm_state_name(r.state())}};
        std::printf("%s\n", j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace).c_str());
      }
      std::fprintf(stderr, "%s: %s (now %s)\n", result, r.reason().c_str(), alarm_state_name(r.state()));
      return static_cast<int>(done ? ExitStatus::Ok : ExitStatus::NotDone);
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  char waited[96];
  std::snprintf(waited, sizeof waited, "no reply from pmu-service within %.1f s (request ", timeout);
  const std::string message = waited + id + ")";
  std::fprintf(stderr, "pmuctl: %s\n", message.c_str());
  if (o.json) {
    Json j{{"request_id", id},  {"vehicle", vehicle}, {"bus", bus},
           {"kind", kind},      {"device", device},   {"code", code},
           {"result", nullptr}, {"reason", message},  {"exit_status", static_cast<int>(ExitStatus::NoAnswer)}};
    std::printf("%s\n", j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace).c_str());
  }
  return static_cast<int>(ExitStatus::NoAnswer);
}

bool output_mask(const std::vector<std::string>& names, std::uint8_t& mask) {
  mask = 0;
  for (const auto& n : names) {
    if (n == "none") continue;
    if (n == "all") {
      mask = codec::output_bit::All;
      continue;
    }
    const auto bit = codec::bit_named(codec::kOutputNames, n);
    if (!bit) {
      std::fprintf(stderr, "pmuctl: unknown output '%s' (outputs: %s)\n", n.c_str(),
                   codec::names_of(codec::kOutputNames, codec::output_bit::All, ", ").c_str());
      return false;
    }
    mask = static_cast<std::uint8_t>(mask | *bit);
  }
  return true;
}

bool group_mask(const std::vector<std::string>& names, std::uint8_t& mask) {
  mask = 0;
  for (const auto& n : names) {
    const auto bit = codec::bit_named(codec::kGroupNames, n);
    if (!bit) {
      std::fprintf(stderr, "pmuctl: unknown measurement group '%s' (%s)\n", n.c_str(),
                   codec::names_of(codec::kGroupNames, codec::group_bit::All, ", ").c_str());
      return false;
    }
    mask = static_cast<std::uint8_t>(mask | *bit);
  }
  return true;
}

std::string broadcast_refusal(const GlobalOptions& o, int kind) {
  if (!o.address || *o.address != codec::kBroadcastAddress || kind == pmu::v5::ENGINE_STOP) return {};
  return "--address 65535 (broadcast) is only for `engine stop`: every other command names one PMU";
}

int run_command(const GlobalOptions& o, const CommandSpec& spec) {
  const double timeout = o.timeout.value_or(5.0);
  const auto deadline = wait_end(o, timeout);
  CommandChannel channel(o);
  // A stop to the broadcast address needs no PMU seen: with --bus it goes to that bus, without
  // to every bus of the service (bus ""), so an engine can be stopped whatever the service
  // has read so far.
  const bool broadcast = spec.kind == pmu::v5::ENGINE_STOP && o.address && *o.address == codec::kBroadcastAddress;
  std::string bus = broadcast ? o.bus : std::string();
  std::uint16_t address = broadcast ? codec::kBroadcastAddress : 0;
  using Find = CommandChannel::Find;
  if (const auto failed = channel.open(deadline, bus, address, broadcast ? Find::Broadcast : Find::MayRecall))
    return *failed;

  const auto timeout_left = [&deadline] {
    return std::max(0.0, std::chrono::duration<double>(deadline - Clock::now()).count());
  };
  // Expires when its caller stops waiting (docs/safety.md H9).
  auto out = channel.send(spec, bus, address, timeout_left(), o.deadline_ns);
  // The PMU this agent's worker commanded before is no longer there (it moved, or its service
  // restarted without it); the service executed nothing, so the command goes, under a new
  // request id, to the PMU found now.
  if (channel.recalled_target_gone(out, bus, address)) {
    if (const auto failed = channel.open(deadline, bus, address)) return *failed;
    out = channel.send(spec, bus, address, timeout_left(), o.deadline_ns);
  }
  if (!out.written) return fail(o, ExitStatus::NotDone, "the command could not be written to DDS");
  if (const auto& r = out.reply) {
    // A bus the service does not serve, or no such device on it, is no such target (2), as
    // when pmuctl finds that out itself; the service executed nothing (interface.md 3.2).
    const ExitStatus status =
        r->result() == pmu::v5::COMPLETED ? ExitStatus::Ok
        : r->result() == pmu::v5::REJECTED && pmu::service::says_no_such_target(r->reason().to_string(), bus, address)
            ? ExitStatus::BadUsage
            : ExitStatus::NotDone;
    if (o.json) {
      Json j{{"request_id", out.request_id},       {"vehicle", r->vehicle().to_string()},
             {"bus", r->bus().to_string()},        {"address", r->address()},
             {"result", result_name(r->result())}, {"reason", r->reason().to_string()}};
      if (r->has_value()) j["value"] = r->value();
      if (!(r->value_text().size() == 0)) j["value_text"] = r->value_text().to_string();
      // A failure of status 2 or 3 carries its status on its line (interface.md 3.2).
      if (status == ExitStatus::BadUsage) j["exit_status"] = static_cast<int>(status);
      std::printf("%s\n", j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace).c_str());
    } else if (r->has_value() || !(r->value_text().size() == 0)) {
      if (!(r->value_text().size() == 0))
        std::printf("%s\n", r->value_text().c_str());
      else
        std::printf("%g\n", r->value());
    }
    std::fprintf(stderr, "%s%s%s\n", result_name(r->result()), (r->reason().size() == 0) ? "" : ": ",
                 r->reason().c_str());
    return static_cast<int>(status);
  }
  char waited[96];
  std::snprintf(waited, sizeof waited, "no reply from pmu-service within %.1f s (request ", timeout);
  const std::string message = waited + out.request_id + ")";
  std::fprintf(stderr, "pmuctl: %s\n", message.c_str());
  if (o.json) {
    // The line of a reply that never came: the same keys, a null result.
    Json j{{"request_id", out.request_id},
           {"vehicle", channel.vehicle()},
           {"bus", bus},
           {"address", address},
           {"result", nullptr},
           {"reason", message},
           {"exit_status", static_cast<int>(ExitStatus::NoAnswer)}};
    std::printf("%s\n", j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace).c_str());
  }
  return static_cast<int>(ExitStatus::NoAnswer);
}

namespace {

// Every stored parameter's name, as `config set` lists them in its help and its refusal.
std::string parameter_names() {
  std::string names;
  for (const auto& spec : pmu::codec::parameter_table()) names += (names.empty() ? "" : ", ") + std::string(spec.name);
  return names;
}

// config set PARAM VALUE.
class ConfigSet : public Verb {
 public:
  ConfigSet(CLI::App& config, const bool& confirm) : confirm_(confirm), parameter_names_(parameter_names()) {
    set_ = config.add_subcommand("set", "Set a stored parameter; verified by reading it back");
    set_->add_option("param", param_, parameter_names_)->required();
    set_->add_option("value", value_,
                     "Value in the parameter's unit (V, s, degC, a number); a mask: names a,b or none, or a number")
        ->required();
  }
  bool chosen() const override { return set_->parsed(); }
  std::optional<int> check(const GlobalOptions& g) override {
    if (pmu::codec::parameter_from_name(param_)) return std::nullopt;
    // The two fields of pmu::v5::Config that are not stored parameters have verbs of their own.
    if (param_ == "outputs")
      return fail(g, ExitStatus::BadUsage,
                  "outputs are not a stored parameter: switch them with `pmuctl outputs set|enable|disable "
                  "NAME...` (their state at power-up is the parameter power_up_state)");
    if (param_ == "generation_enabled")
      return fail(g, ExitStatus::BadUsage,
                  "generation is not a stored parameter: switch it with `pmuctl generation on|off`");
    return fail(g, ExitStatus::BadUsage,
                "unknown parameter '" + pmu::service::printable(param_) + "' (parameters: " + parameter_names_ + ")");
  }
  int run(GlobalOptions& g) override {
    const auto parsed = parse_config_value(param_, value_);
    if (!parsed.value) return fail(g, ExitStatus::BadUsage, parsed.error);
    CommandSpec spec;
    spec.confirm = confirm_;
    spec.value = *parsed.value;
    spec.kind = pmu::v5::SET_PARAMETER;
    spec.parameter = param_;
    return run_command(g, spec);
  }

 private:
  const bool& confirm_;
  std::string parameter_names_;
  CLI::App* set_;
  std::string param_, value_;
};

// outputs get|set|enable|disable, generation on|off, engine start|stop, reset, measure.
class CommandVerbs : public Verb {
 public:
  CommandVerbs(CLI::App& app, const bool& confirm) : confirm_(confirm) {
    outputs_ = app.add_subcommand(
        "outputs",
        "Output states (" + pmu::codec::names_of(pmu::codec::kOutputNames, pmu::codec::output_bit::All, ", ") + ")");
    outputs_->require_subcommand(1);
    outputs_get_ = outputs_->add_subcommand("get", "Read the output states from the PMU");
    outputs_set_ = outputs_->add_subcommand("set", "Set exactly these outputs on (the others off)");
    outputs_set_->add_option("names", output_names_, "Outputs to have on (or none)")->required();
    outputs_enable_ = outputs_->add_subcommand("enable", "Switch these outputs on");
    outputs_enable_->add_option("names", output_names_, "Outputs")->required();
    auto* outputs_disable = outputs_->add_subcommand("disable", "Switch these outputs off");
    outputs_disable->add_option("names", output_names_, "Outputs")->required();
    generation_ = app.add_subcommand("generation", "Electrical power generation on|off");
    generation_->add_option("state", on_off_, "on or off")->required()->check(CLI::IsMember({"on", "off"}));
    engine_ = app.add_subcommand(
        "engine",
        "Engine start (verified by the generator speed) | stop (0x25: stops the starter cranking; a running engine "
        "keeps running, no PMU command stops it)");
    engine_
        ->add_option("action", start_stop_,
                     "start: crank until the engine runs; stop: stop the starter cranking (not a running engine)")
        ->required()
        ->check(CLI::IsMember({"start", "stop"}));
    reset_ = app.add_subcommand("reset", "Restart the PMU (outputs to power-up state, energies to zero)");
    measure_ = app.add_subcommand("measure", "Ask for measurements now (0x0F; firmware 1.14+)");
    measure_->add_option("groups", groups_,
                         pmu::codec::names_of(pmu::codec::kGroupNames, pmu::codec::group_bit::All, ", ") +
                             " (default all)");
  }
  bool chosen() const override { return *outputs_ || *generation_ || *engine_ || *reset_ || *measure_; }
  int command_kind() const override {
    return !*engine_ ? -1 : start_stop_ == "start" ? int{pmu::v5::ENGINE_START} : int{pmu::v5::ENGINE_STOP};
  }
  int run(GlobalOptions& g) override {
    CommandSpec spec;
    spec.confirm = confirm_;
    if (*outputs_get_) {
      spec.kind = pmu::v5::GET;
      spec.parameter = "outputs";
    } else if (*outputs_) {
      if (!output_mask(output_names_, spec.outputs)) return 2;
      spec.kind = *outputs_set_      ? pmu::v5::SET_OUTPUTS
                  : *outputs_enable_ ? pmu::v5::ENABLE_OUTPUTS
                                     : pmu::v5::DISABLE_OUTPUTS;
    } else if (*generation_) {
      spec.kind = pmu::v5::SET_GENERATION;
      spec.enable = on_off_ == "on";
    } else if (*engine_) {
      spec.kind = command_kind();
    } else if (*reset_) {
      spec.kind = pmu::v5::RESET;
    } else {
      if (!group_mask(groups_, spec.groups)) return 2;
      spec.kind = pmu::v5::REQUEST_MEASUREMENTS;
    }
    return run_command(g, spec);
  }

 private:
  const bool& confirm_;
  CLI::App* outputs_;
  CLI::App* outputs_get_;
  CLI::App* outputs_set_;
  CLI::App* outputs_enable_;
  CLI::App* generation_;
  CLI::App* engine_;
  CLI::App* reset_;
  CLI::App* measure_;
  std::vector<std::string> output_names_, groups_;
  std::string on_off_, start_stop_;
};

}  // namespace

std::unique_ptr<Verb> add_config_set(CLI::App& config, const bool& confirm) {
  return std::make_unique<ConfigSet>(config, confirm);
}

std::unique_ptr<Verb> add_command_verbs(CLI::App& app, const bool& confirm) {
  return std::make_unique<CommandVerbs>(app, confirm);
}

}  // namespace pmu::tools
