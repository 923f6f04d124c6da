#include "pmuctl/view/table_text.hpp"

#include <algorithm>
#include <cstdio>
#include <map>

namespace pmu::tools {

std::string age_text(double seconds) {
  char buf[32];
  const double s = seconds > 0 ? seconds : 0.0;
  if (s < 10)
    std::snprintf(buf, sizeof buf, "%.1fs", s);
  else if (s < 600)
    std::snprintf(buf, sizeof buf, "%.0fs", s);
  else if (s < 36000)
    std::snprintf(buf, sizeof buf, "%.0fm", s / 60);
  else
    std::snprintf(buf, sizeof buf, "%.0fh", s / 3600);
  return buf;
}

std::string freshness(std::optional<pmu::v5::HealthState> state, double age_seconds) {
  return std::string(to_string(state.value_or(pmu::v5::UNKNOWN))) + " " + age_text(age_seconds);
}

std::string row_values(const SampleFields& fields) {
  std::string row;
  for (const auto& f : fields) row += (row.empty() ? "" : " ") + f.name + "=" + text_with_unit(f, true);
  return row;
}

std::vector<std::string> aligned_columns(const std::vector<std::vector<std::string>>& rows) {
  std::vector<std::size_t> width;
  for (const auto& r : rows) {
    if (r.size() > width.size()) width.resize(r.size(), 0);
    for (std::size_t c = 0; c + 1 < r.size(); ++c) width[c] = std::max(width[c], r[c].size());
  }
  std::vector<std::string> lines;
  for (const auto& r : rows) {
    std::string line;
    for (std::size_t c = 0; c < r.size(); ++c) {
      line += r[c];
      if (c + 1 < r.size()) line += std::string(width[c] - r[c].size() + 2, ' ');
    }
    lines.push_back(line);
  }
  return lines;
}

std::vector<std::string> watch_table(const std::vector<WatchRow>& rows, const std::vector<AlarmEntry>& alarms) {
  std::vector<std::string> lines;
  std::map<std::string, std::string> markers;  // by source, so buses come before their devices
  for (const auto& a : alarms) {
    const std::string source = alarm_source(a);
    if (markers.count(source)) continue;
    const std::string m = alarm_marker(alarms_of(alarms, source));
    if (!m.empty()) markers[source] = m;
  }
  if (!markers.empty()) {
    std::vector<std::vector<std::string>> cells;
    for (const auto& [source, m] : markers) cells.push_back({source, m});
    lines.push_back("alarms:");
    for (auto& l : aligned_columns(cells)) lines.push_back(std::move(l));
  }
  const auto marker_of = [&markers](const std::string& label) {
    const auto it = markers.find(label);
    return it == markers.end() ? std::string() : it->second;
  };
  std::vector<std::string> topics;
  for (const auto& r : rows)
    if (std::find(topics.begin(), topics.end(), r.topic) == topics.end()) topics.push_back(r.topic);
  for (const auto& t : topics) {
    bool with_marker = false;
    for (const auto& r : rows) with_marker = with_marker || (r.topic == t && !marker_of(r.label).empty());
    std::vector<std::vector<std::string>> cells;
    for (const auto& r : rows) {
      if (r.topic != t) continue;
      cells.push_back({r.label, to_string(r.state.value_or(pmu::v5::UNKNOWN)), age_text(r.age)});
      if (with_marker) cells.back().push_back(marker_of(r.label));
      cells.back().push_back(row_values(r.values));
    }
    lines.push_back(t + ":");
    for (auto& l : aligned_columns(cells)) lines.push_back(std::move(l));
  }
  return lines;
}

std::string value_block(const std::string& label, const SampleFields& fields) {
  std::string out = label + "\n";
  for (const auto& f : fields) {
    char name[64];
    std::snprintf(name, sizeof name, "  %-24s ", f.name.c_str());
    out += name + text_with_unit(f) + "\n";
  }
  return out;
}

}  // namespace pmu::tools
