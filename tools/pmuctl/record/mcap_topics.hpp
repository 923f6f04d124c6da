#pragma once
// The topics pmuctl writes into MCAP files (`record`, `decode --mcap`): one channel per
// topic, message encoding `cdr`, schema encoding `omgidl`, schema name = the DDS type name,
// schema text = the idl/ file that defines the type (docs/interface.md, "MCAP recordings").
// No DDS here: the names and texts only.

#include <string>
#include <string_view>
#include <vector>

namespace pmu::tools {

struct RecordedTopic {
  const char* topic;        // "pmu/voltages"
  const char* type_name;    // "pmu::v5::Voltages": the DDS type name and the MCAP schema name
  std::string_view idl;     // the schema text
  const char* qos_profile;  // deploy/qos.xml's reader profile
  bool by_default;          // recorded when no --topic is given
};

// Every topic `record` knows, in the contract's order.
const std::vector<RecordedTopic>& recorded_topics();
// By its name ("pmu/voltages") or its last part after "pmu/" ("voltages", "low_rate/voltages");
// nullptr when none.
const RecordedTopic* find_recorded_topic(std::string_view name);

// The topics `--topic NAME` options name (each once, in the order given), or every topic
// recorded by default when there are none: the selection of both `record` and `serve`.
// Empty, with `error` set ("--topic x is not a topic of the contract (pmu/voltages, ...)"),
// when a name is unknown.
std::vector<const RecordedTopic*> select_topics(const std::vector<std::string>& names, std::string& error);

}  // namespace pmu::tools
