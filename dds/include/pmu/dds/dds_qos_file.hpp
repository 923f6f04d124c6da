#pragma once
// The QoS profile file (deploy/qos.xml), loaded into Fast DDS once per process and checked
// without creating a participant: pmu-service's start-up check and DdsContext both load it
// through load_qos_profiles, so what the check accepted is what the participant gets.
// Start-up only; call from the thread that starts the program.

#include <string>
#include <vector>

#include "pmu/dds/dds_capacity.hpp"

namespace pmu::dds {

// Loads `file` into Fast DDS's process-wide profile registry, once per file. Throws DdsError
// (dds_context.hpp) when it cannot be read or Fast DDS refuses it.
void load_qos_profiles(const std::string& file);

// A profile a program creates endpoints with, and what for (for messages).
struct ProfileUse {
  const char* profile;  // profile_name in the file
  EndpointKind kind;
  const char* used_for;  // e.g. "the telemetry topics' writers"
};

// What is wrong with `file` for endpoints made with `uses`, each "FILE[:LINE]: what"
// (LINE: the file's own line, where the XML has one); empty when nothing is. Checks, in
// order: it opens, it is well-formed XML, Fast DDS's parser reads it, each profile exists in
// this file and holds the declared capacity (capacity_shortfall), and Fast DDS loads it.
// Profiles are judged from the file's own parse, never from the process-wide registry, which
// keeps the first file's profile of each name. Loads the file into Fast DDS when it is sound.
std::vector<std::string> qos_file_problems(const std::string& file, const std::vector<ProfileUse>& uses);

}  // namespace pmu::dds
