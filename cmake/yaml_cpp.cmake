# yaml-cpp as the target `yaml-cpp`, also when cross-building.
#
# Debian bookworm's libyaml-cpp-dev is not Multi-Arch: same, so libyaml-cpp-dev:arm64 cannot
# be installed next to the amd64 one the native builds need. A cross build gets the arm64
# runtime library (libyaml-cpp0.7:arm64, Multi-Arch: same) and the build machine's headers,
# which are the same for every architecture; this builds the target from those two.
find_package(yaml-cpp QUIET)
if(NOT TARGET yaml-cpp)
  find_path(PMU_YAML_CPP_INCLUDE_DIR yaml-cpp/yaml.h)
  find_library(PMU_YAML_CPP_LIBRARY NAMES yaml-cpp libyaml-cpp.so.0.7)
  if(NOT PMU_YAML_CPP_INCLUDE_DIR OR NOT PMU_YAML_CPP_LIBRARY)
    message(FATAL_ERROR "yaml-cpp not found: install libyaml-cpp-dev (cross builds: libyaml-cpp-dev "
                        "for the build machine and libyaml-cpp0.7 for the target architecture)")
  endif()
  message(STATUS "yaml-cpp: ${PMU_YAML_CPP_LIBRARY} with the headers in ${PMU_YAML_CPP_INCLUDE_DIR}")
  add_library(yaml-cpp SHARED IMPORTED GLOBAL)
  set_target_properties(yaml-cpp PROPERTIES IMPORTED_LOCATION ${PMU_YAML_CPP_LIBRARY}
                                            INTERFACE_INCLUDE_DIRECTORIES ${PMU_YAML_CPP_INCLUDE_DIR})
endif()
