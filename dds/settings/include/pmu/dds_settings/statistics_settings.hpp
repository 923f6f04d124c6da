#pragma once
// Fast DDS statistics topics (config `dds_statistics`, docs/interface.md 9.3): the topics
// eProsima's Fast DDS Monitor reads to show latency, throughput and traffic per endpoint.
// Debian's Fast DDS 2.9.1 is built with statistics (FASTDDS_STATISTICS); a participant
// writes a statistics topic when its participant property `fastdds.statistics` names it
// (topic names separated by ';'), or when the environment variable FASTDDS_STATISTICS does,
// which Fast DDS reads by itself for every participant of the process.
//
// Fast DDS itself only logs an unknown name; the config refuses it at its line instead.
// No DDS entity here: the names only, so the config can check them at their line.

#include <string>
#include <vector>

namespace pmu::dds {

// Every statistics topic Fast DDS 2.9.1 can write (fastdds/statistics/topic_names.hpp),
// e.g. "_fastdds_statistics_history2history_latency".
const std::vector<std::string>& statistics_topic_names();

bool is_statistics_topic(const std::string& name);

// The value of the participant property `fastdds.statistics` for `topics`: "a;b;c".
std::string statistics_property(const std::vector<std::string>& topics);

}  // namespace pmu::dds
