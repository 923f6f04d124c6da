// pmuctl: the operator's command line (interface.md section 2): the DDS verbs that read
// what pmu-service publishes, and the offline decoder for candump logs.

#include <sys/types.h>

#include <CLI/CLI.hpp>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <optional>
#include <string>

#include "pmu/codec/firmware.hpp"
#include "pmuctl/dds_verbs.hpp"
#include "pmuctl/log_decoder.hpp"

namespace {

struct FileCloser {
  void operator()(std::FILE* f) const {
    if (f && f != stdin) std::fclose(f);
  }
};

int run_decode(const std::string& path, const pmu::tools::DecodeOptions& options) {
  std::unique_ptr<std::FILE, FileCloser> in(path == "-" ? stdin : std::fopen(path.c_str(), "r"));
  if (!in) {
    std::fprintf(stderr, "pmuctl decode: cannot open %s: %s\n", path.c_str(), std::strerror(errno));
    return 2;
  }
  pmu::tools::LogDecoder decoder(options);
  std::string out = decoder.header();
  out.reserve(1 << 17);
  char* line = nullptr;
  std::size_t cap = 0;
  ssize_t len = 0;
  while ((len = ::getline(&line, &cap, in.get())) >= 0) {
    std::size_t n = static_cast<std::size_t>(len);
    while (n > 0 && (line[n - 1] == '\n' || line[n - 1] == '\r')) --n;
    decoder.decode_line(std::string_view(line, n), out);
    if (out.size() >= (1 << 16)) {
      std::fwrite(out.data(), 1, out.size(), stdout);
      out.clear();
    }
  }
  const bool read_error = std::ferror(in.get()) != 0;
  std::free(line);
  std::fwrite(out.data(), 1, out.size(), stdout);
  std::fflush(stdout);
  if (read_error) {
    std::fprintf(stderr, "pmuctl decode: error reading %s\n", path.c_str());
    return 2;
  }
  const auto& c = decoder.counts();
  std::fprintf(stderr, "pmuctl decode: %llu lines, %llu frames decoded, %llu errors\n",
               static_cast<unsigned long long>(c.lines), static_cast<unsigned long long>(c.frames),
               static_cast<unsigned long long>(c.errors));
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"pmuctl: operate and inspect Millswood 250W PMUs served by pmu-service"};
  app.require_subcommand(1);
  app.fallthrough();  // global options may follow the verb: `pmuctl decode --json`
  pmu::tools::GlobalOptions g;
  int address = -1;
  double timeout = -1;
  app.add_option("--domain", g.domain, "DDS domain id")->check(CLI::Range(0, 232));
  app.add_option("--bus", g.bus, "Only this bus (the service's name for it, e.g. can0)");
  app.add_option("--address", address, "Only the PMU at this CAN address")->check(CLI::Range(0, 65534));
  app.add_flag("--json", g.json, "Machine-readable output: one JSON object per line");
  app.add_option("--timeout", timeout, "Seconds to wait (state verbs: default 3; watch: forever)")
      ->check(CLI::PositiveNumber);
  app.add_option("--qos-file", g.qos_file, "QoS profiles (default: $PMU_QOS_FILE or /etc/pmu-dds/qos.xml)");

  auto* watch = app.add_subcommand("watch", "Live telemetry: a refreshing table, or one JSON object per sample");
  long count = 0;
  watch->add_option("--count", count, "Stop after N samples")->check(CLI::PositiveNumber);
  app.add_subcommand("list", "PMUs the service knows, with health");
  app.add_subcommand("info", "Serial number, firmware and features");
  app.add_subcommand("health", "Link, bus and device health");
  auto* config = app.add_subcommand("config", "Stored parameters");
  config->require_subcommand(1);
  auto* config_get = config->add_subcommand("get", "Show the stored parameters (or one)");
  std::string parameter;
  config_get->add_option("param", parameter, "A parameter name, e.g. avionics_voltage");

  auto* decode = app.add_subcommand("decode", "Decode a candump log (-L or screen format) offline");
  std::string path = "-";
  std::string firmware;
  decode->add_option("file", path, "Log file, or - for standard input")->capture_default_str();
  decode->add_option("--firmware", firmware,
                     "Firmware X.Y assumed for devices whose firmware reply is not in the log "
                     "(default: current, 1.17)");

  CLI11_PARSE(app, argc, argv);
  if (address >= 0) g.address = static_cast<std::uint16_t>(address);
  if (timeout > 0) g.timeout = timeout;

  if (*decode) {
    pmu::tools::DecodeOptions options;
    options.json = g.json;
    if (!firmware.empty()) {
      options.firmware = pmu::codec::parse_firmware(firmware);
      if (!options.firmware) {
        std::fprintf(stderr, "pmuctl decode: --firmware '%s' is not a version like 1.16\n", firmware.c_str());
        return 2;
      }
    }
    return run_decode(path, options);
  }
  try {
    if (*watch) return pmu::tools::run_watch(g, count);
    if (app.got_subcommand("list")) return pmu::tools::run_list(g);
    if (app.got_subcommand("info")) return pmu::tools::run_info(g);
    if (app.got_subcommand("health")) return pmu::tools::run_health(g);
    if (*config_get) return pmu::tools::run_config_get(g, parameter);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "pmuctl: %s\n", e.what());
    return 2;
  }
  return 2;
}
