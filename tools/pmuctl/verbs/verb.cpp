#include "pmuctl/verbs/verb.hpp"

#include <CLI/CLI.hpp>

namespace pmu::tools {
namespace {

class StateReadingVerb final : public Verb {
 public:
  StateReadingVerb(CLI::App& app, const char* name, const char* description, int (*call)(const GlobalOptions&))
      : subcommand_(app.add_subcommand(name, description)), call_(call) {}
  bool chosen() const override { return subcommand_->parsed(); }
  bool reads_state() const override { return true; }
  int run(GlobalOptions& g) override { return call_(g); }

 private:
  CLI::App* subcommand_;
  int (*call_)(const GlobalOptions&);
};

}  // namespace

std::unique_ptr<Verb> add_state_reading_verb(CLI::App& app, const char* name, const char* description,
                                             int (*run)(const GlobalOptions&)) {
  return std::make_unique<StateReadingVerb>(app, name, description, run);
}

}  // namespace pmu::tools
