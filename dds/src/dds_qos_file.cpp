#include "pmu/dds/dds_qos_file.hpp"

#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastrtps/attributes/PublisherAttributes.h>
#include <fastrtps/attributes/SubscriberAttributes.h>
#include <fastrtps/xmlparser/XMLParser.h>
#include <fastrtps/xmlparser/XMLTree.h>
#include <tinyxml2.h>

#include <cerrno>
#include <cstring>
#include <map>
#include <mutex>

#include "pmu/dds/dds_context.hpp"
#include "pmu/files/bounded_file.hpp"

namespace pmu::dds {
namespace {

using eprosima::fastrtps::xmlparser::BaseNode;
using eprosima::fastrtps::xmlparser::DataNode;
using eprosima::fastrtps::xmlparser::NodeType;
using eprosima::fastrtps::xmlparser::XMLP_ret;
using eprosima::fastrtps::xmlparser::XMLParser;

// Far above any profile file; a bound, so a device named as the QoS file is refused.
constexpr std::size_t kMaxQosFileBytes = std::size_t{1} << 20;

// The file's text, or why it cannot be read: regular and bounded only, through the one
// reader, because a FIFO or /dev/zero named here would stop the start (docs/safety.md H12).
files::FileText qos_text(const std::string& file) { return files::read_bounded_file(file, kMaxQosFileBytes); }

// The line of <data_writer|data_reader profile_name="..."> anywhere in the document, or 0.
int profile_line(const tinyxml2::XMLElement* e, const char* tag, const char* profile) {
  for (; e; e = e->NextSiblingElement()) {
    if (std::strcmp(e->Name(), tag) == 0 && e->Attribute("profile_name", profile)) return e->GetLineNum();
    if (const int line = profile_line(e->FirstChildElement(), tag, profile)) return line;
  }
  return 0;
}

// The attributes of the file's own <data_writer> (T = PublisherAttributes, type PUBLISHER) or
// <data_reader> profile of that name, or null. Read from this file's parse tree, never from
// Fast DDS's process-wide registry: that one keeps the first file's profile of a name, so a
// process that had loaded another file would judge that file's profile instead of this one's.
template <class T>
const T* own_profile(BaseNode& node, NodeType type, const std::string& name) {
  if (node.getType() == type) {
    auto& data = static_cast<DataNode<T>&>(node);
    const auto& attributes = data.getAttributes();
    if (const auto it = attributes.find("profile_name"); it != attributes.end() && it->second == name)
      return data.get();
  }
  for (auto& child : node.getChildren())
    if (const T* found = own_profile<T>(*child, type, name)) return found;
  return nullptr;
}

}  // namespace

void load_qos_profiles(const std::string& file) {
  // Fast DDS keeps loaded profiles in a process-wide registry: load each file once.
  static std::mutex mutex;
  static std::map<std::string, bool> loaded;
  std::lock_guard<std::mutex> lock(mutex);
  if (loaded[file]) return;
  // Fast DDS reads the file itself, by its path: it is handed only a file just found to be
  // regular and within the bound.
  if (const auto text = qos_text(file); !text.ok())
    throw DdsError("QoS profile file " + file + ": cannot be read: " + text.error);
  using eprosima::fastdds::dds::DomainParticipantFactory;
  if (DomainParticipantFactory::get_instance()->load_XML_profiles_file(file) != ReturnCode_t::RETCODE_OK)
    throw DdsError("cannot load QoS profiles from " + file + " (see the Fast DDS XML error above)");
  loaded[file] = true;
}

std::vector<std::string> qos_file_problems(const std::string& file, const std::vector<ProfileUse>& uses) {
  const auto text = qos_text(file);
  if (!text.ok()) return {file + ": cannot be read: " + text.error};
  // Fast DDS only logs where its XML parser stopped; tinyxml2 (its parser too) gives the line.
  tinyxml2::XMLDocument doc;
  if (doc.Parse(text.text.data(), text.text.size()) != tinyxml2::XML_SUCCESS)
    return {file + ":" + std::to_string(doc.ErrorLineNum()) + ": not well-formed XML: " + doc.ErrorStr()};
  eprosima::fastrtps::xmlparser::up_base_node_t tree;
  if (XMLParser::loadXML(doc, tree) != XMLP_ret::XML_OK || !tree)
    return {file + ": Fast DDS cannot read its profiles (see the Fast DDS XML error above)"};
  std::vector<std::string> problems;
  for (const auto& use : uses) {
    const bool writer = use.kind == EndpointKind::Writer;
    const char* tag = writer ? "data_writer" : "data_reader";
    const std::string element = std::string("<") + tag + " profile_name=\"" + use.profile + "\">";
    const eprosima::fastrtps::TopicAttributes* own = nullptr;
    if (writer) {
      if (const auto* a = own_profile<eprosima::fastrtps::PublisherAttributes>(*tree, NodeType::PUBLISHER, use.profile))
        own = &a->topic;
    } else if (const auto* a =
                   own_profile<eprosima::fastrtps::SubscriberAttributes>(*tree, NodeType::SUBSCRIBER, use.profile)) {
      own = &a->topic;
    }
    const bool found = own != nullptr;
    if (!found) {
      problems.push_back(file + ": no " + element + ", needed for " + use.used_for);
      continue;
    }
    if (const auto s = capacity_shortfall(use.profile, use.kind, own->resourceLimitsQos, own->historyQos); !s.empty()) {
      const int line = profile_line(doc.RootElement(), tag, use.profile);
      problems.push_back(file + (line > 0 ? ":" + std::to_string(line) : std::string()) + ": " + element + " (" +
                         use.used_for + "): " + s +
                         ": raise its <resourceLimitsQos> (deploy/qos.xml says how each number is derived)");
    }
  }
  // Loaded only once judged sound, so the registry holds no file the check refused.
  if (problems.empty()) {
    try {
      load_qos_profiles(file);
    } catch (const DdsError& e) {
      return {e.what()};
    }
  }
  return problems;
}

}  // namespace pmu::dds
