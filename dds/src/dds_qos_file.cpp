#include "pmu/dds/dds_qos_file.hpp"

#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastrtps/attributes/PublisherAttributes.h>
#include <fastrtps/attributes/SubscriberAttributes.h>
#include <fastrtps/xmlparser/XMLProfileManager.h>
#include <sys/stat.h>
#include <tinyxml2.h>

#include <cerrno>
#include <cstring>
#include <map>
#include <mutex>

#include "pmu/dds/dds_context.hpp"

namespace pmu::dds {
namespace {

using eprosima::fastrtps::xmlparser::XMLP_ret;
using eprosima::fastrtps::xmlparser::XMLProfileManager;

// "" when `file` can be opened for reading, else why not.
std::string unreadable(const std::string& file) {
  struct stat st {};
  if (::stat(file.c_str(), &st) != 0) return std::string("cannot open: ") + std::strerror(errno);
  if (S_ISDIR(st.st_mode)) return "is a directory, not a QoS profile file";
  if (std::FILE* f = std::fopen(file.c_str(), "rb")) {
    std::fclose(f);
    return {};
  }
  return std::string("cannot open: ") + std::strerror(errno);
}

// The line of <data_writer|data_reader profile_name="..."> anywhere in the document, or 0.
int profile_line(const tinyxml2::XMLElement* e, const char* tag, const char* profile) {
  for (; e; e = e->NextSiblingElement()) {
    if (std::strcmp(e->Name(), tag) == 0 && e->Attribute("profile_name", profile)) return e->GetLineNum();
    if (const int line = profile_line(e->FirstChildElement(), tag, profile)) return line;
  }
  return 0;
}

}  // namespace

void load_qos_profiles(const std::string& file) {
  // Fast DDS keeps loaded profiles in a process-wide registry: load each file once.
  static std::mutex mutex;
  static std::map<std::string, bool> loaded;
  std::lock_guard<std::mutex> lock(mutex);
  if (loaded[file]) return;
  if (const auto why = unreadable(file); !why.empty()) throw DdsError("QoS profile file " + file + ": " + why);
  using eprosima::fastdds::dds::DomainParticipantFactory;
  if (DomainParticipantFactory::get_instance()->load_XML_profiles_file(file) != ReturnCode_t::RETCODE_OK)
    throw DdsError("cannot load QoS profiles from " + file + " (see the Fast DDS XML error above)");
  loaded[file] = true;
}

std::vector<std::string> qos_file_problems(const std::string& file, const std::vector<ProfileUse>& uses) {
  if (const auto why = unreadable(file); !why.empty()) return {file + ": " + why};
  // Fast DDS only logs where its XML parser stopped; tinyxml2 (its parser too) gives the line.
  tinyxml2::XMLDocument doc;
  if (doc.LoadFile(file.c_str()) != tinyxml2::XML_SUCCESS)
    return {file + ":" + std::to_string(doc.ErrorLineNum()) + ": not well-formed XML: " + doc.ErrorStr()};
  try {
    load_qos_profiles(file);
  } catch (const DdsError& e) {
    return {e.what()};
  }
  std::vector<std::string> problems;
  for (const auto& use : uses) {
    const bool writer = use.kind == EndpointKind::Writer;
    const char* tag = writer ? "data_writer" : "data_reader";
    const std::string element = std::string("<") + tag + " profile_name=\"" + use.profile + "\">";
    eprosima::fastrtps::TopicAttributes topic;
    bool found = false;
    if (writer) {
      eprosima::fastrtps::PublisherAttributes a;
      found = XMLProfileManager::fillPublisherAttributes(use.profile, a, false) == XMLP_ret::XML_OK;
      topic = a.topic;
    } else {
      eprosima::fastrtps::SubscriberAttributes a;
      found = XMLProfileManager::fillSubscriberAttributes(use.profile, a, false) == XMLP_ret::XML_OK;
      topic = a.topic;
    }
    if (!found) {
      problems.push_back(file + ": no " + element + ", needed for " + use.used_for);
      continue;
    }
    if (const auto s = capacity_shortfall(use.profile, use.kind, topic.resourceLimitsQos, topic.historyQos);
        !s.empty()) {
      const int line = profile_line(doc.RootElement(), tag, use.profile);
      problems.push_back(file + (line > 0 ? ":" + std::to_string(line) : std::string()) + ": " + element + " (" +
                         use.used_for + "): " + s +
                         ": raise its <resourceLimitsQos> (deploy/qos.xml says how each number is derived)");
    }
  }
  return problems;
}

}  // namespace pmu::dds
