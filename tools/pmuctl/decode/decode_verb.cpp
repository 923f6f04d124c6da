#include "pmuctl/decode/decode_verb.hpp"

#include <sys/types.h>

#include <CLI/CLI.hpp>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <string>

#include "pmu/codec/firmware.hpp"
#include "pmuctl/decode/log_decoder.hpp"
#include "pmuctl/record/mcap_decode.hpp"
#include "pmuctl/call/global_options.hpp"

namespace pmu::tools {
namespace {

struct FileCloser {
  void operator()(std::FILE* f) const {
    if (f && f != stdin) std::fclose(f);
  }
};

int run_decode(const std::string& path, const DecodeOptions& options) {
  std::unique_ptr<std::FILE, FileCloser> in(path == "-" ? stdin : std::fopen(path.c_str(), "r"));
  if (!in) {
    std::fprintf(stderr, "pmuctl decode: cannot open %s: %s\n", path.c_str(), std::strerror(errno));
    return 2;
  }
  LogDecoder decoder(options);
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
  if (c.relative_times > 0)
    std::fprintf(stderr,
                 "pmuctl decode: %llu lines have times before 1973, as candump -td (deltas) or -tz (since its "
                 "start) writes them: printed as given, not as dates (candump -L or -ta logs absolute times)\n",
                 static_cast<unsigned long long>(c.relative_times));
  std::fprintf(stderr, "pmuctl decode: %llu lines, %llu frames decoded, %llu errors\n",
               static_cast<unsigned long long>(c.lines), static_cast<unsigned long long>(c.frames),
               static_cast<unsigned long long>(c.errors));
  return 0;
}

class DecodeVerb : public Verb {
 public:
  explicit DecodeVerb(CLI::App& app) {
    decode_ = app.add_subcommand("decode", "Decode a candump log (-L or screen format) offline");
    decode_->add_option("file", path_, "Log file, or - for standard input")->capture_default_str();
    decode_->add_option("--firmware", firmware_,
                        "Firmware X.Y assumed for devices whose firmware reply is not in the log "
                        "(default: current, 1.17)");
    decode_->add_option("--mcap", mcap_out_,
                        "Write the PMU telemetry frames as an MCAP file with the channels of `record` "
                        "(candump -L logs: the log time is the frame's timestamp) instead of printing them; "
                        "a FIFO or a character device is written in place, - is standard output");
  }
  bool chosen() const override { return decode_->parsed(); }
  std::optional<int> take_values(const GlobalOptions& g) override {
    DecodeOptions options;
    options.json = g.json;
    if (!firmware_.empty()) {
      options.firmware = pmu::codec::parse_firmware(firmware_);
      if (!options.firmware) {
        std::fprintf(stderr, "pmuctl decode: --firmware '%s' is not a version like 1.16\n", firmware_.c_str());
        return 2;
      }
    }
    if (!mcap_out_.empty()) return run_decode_mcap(path_, mcap_out_, options.firmware);
    return run_decode(path_, options);
  }
  // Never reached: take_values ends every decode call.
  int run(GlobalOptions&) override { return 2; }

 private:
  CLI::App* decode_;
  std::string path_ = "-";
  std::string firmware_;
  std::string mcap_out_;
};

}  // namespace

std::unique_ptr<Verb> add_decode_verb(CLI::App& app) { return std::make_unique<DecodeVerb>(app); }

}  // namespace pmu::tools
