#pragma once
// Request ids are unique per sender (interface.md 2.4), so the services that deduplicate
// requests key them by both. Senders are DDS GUIDs, which hold no NUL.

#include <string>

namespace pmu::service {

inline std::string sender_key(const std::string& sender, const std::string& request_id) {
  std::string key = sender;
  key += '\0';
  key += request_id;
  return key;
}

}  // namespace pmu::service
