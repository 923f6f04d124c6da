// pmuctl: the operator's command line (interface.md section 2). This build carries the
// offline decoder; the DDS verbs (watch, list, info, health, config, outputs, ...) are
// added by the service issues.

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
  bool json = false;
  app.add_flag("--json", json, "Machine-readable output: one JSON object per line");

  auto* decode = app.add_subcommand("decode", "Decode a candump log (-L or screen format) offline");
  std::string path = "-";
  std::string firmware;
  decode->add_option("file", path, "Log file, or - for standard input")->capture_default_str();
  decode->add_option("--firmware", firmware,
                     "Firmware X.Y assumed for devices whose firmware reply is not in the log "
                     "(default: current, 1.17)");

  CLI11_PARSE(app, argc, argv);

  if (*decode) {
    pmu::tools::DecodeOptions options;
    options.json = json;
    if (!firmware.empty()) {
      options.firmware = pmu::codec::parse_firmware(firmware);
      if (!options.firmware) {
        std::fprintf(stderr, "pmuctl decode: --firmware '%s' is not a version like 1.16\n", firmware.c_str());
        return 2;
      }
    }
    return run_decode(path, options);
  }
  return 2;
}
