#include "pmu/dds_settings/statistics_settings.hpp"

#include <fastdds/statistics/topic_names.hpp>  // constants only: no Fast DDS library call

#include <algorithm>

namespace pmu::dds {

const std::vector<std::string>& statistics_topic_names() {
  namespace st = eprosima::fastdds::statistics;
  static const std::vector<std::string> names = {
      st::HISTORY_LATENCY_TOPIC,
      st::NETWORK_LATENCY_TOPIC,
      st::PUBLICATION_THROUGHPUT_TOPIC,
      st::SUBSCRIPTION_THROUGHPUT_TOPIC,
      st::RTPS_SENT_TOPIC,
      st::RTPS_LOST_TOPIC,
      st::RESENT_DATAS_TOPIC,
      st::HEARTBEAT_COUNT_TOPIC,
      st::ACKNACK_COUNT_TOPIC,
      st::NACKFRAG_COUNT_TOPIC,
      st::GAP_COUNT_TOPIC,
      st::DATA_COUNT_TOPIC,
      st::PDP_PACKETS_TOPIC,
      st::EDP_PACKETS_TOPIC,
      st::DISCOVERY_TOPIC,
      st::SAMPLE_DATAS_TOPIC,
      st::PHYSICAL_DATA_TOPIC,
  };
  return names;
}

bool is_statistics_topic(const std::string& name) {
  const auto& names = statistics_topic_names();
  return std::find(names.begin(), names.end(), name) != names.end();
}

std::string statistics_property(const std::vector<std::string>& topics) {
  std::string s;
  for (const auto& t : topics) s += (s.empty() ? "" : ";") + t;
  return s;
}

}  // namespace pmu::dds
