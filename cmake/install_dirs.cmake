# Install directories (GNUInstallDirs) and the one place the configuration directory is named.
#
# The configuration lives in /etc/pmu-dds whatever the prefix: the systemd unit, install.sh
# and the documentation name it, and a service built for /usr/local must still find the
# config the site installed. So sysconfdir defaults to /etc (GNUInstallDirs alone would make
# it PREFIX/etc); a packager may still pass -DCMAKE_INSTALL_SYSCONFDIR or -DPMU_SYSCONFDIR.
set(CMAKE_INSTALL_SYSCONFDIR /etc CACHE PATH "read-only single-machine data (/etc)")
include(GNUInstallDirs)
set(PMU_SYSCONFDIR "${CMAKE_INSTALL_FULL_SYSCONFDIR}/pmu-dds" CACHE PATH
    "Where pmu-service and pmuctl look for pmu-service.yaml and qos.xml")
# Read-only data for clients: the IDL and a copy of qos.xml. A machine with only the client
# tools (pmu-dds-tools, no daemon and so no /etc/pmu-dds) finds its QoS profiles here.
set(PMU_DATADIR "${CMAKE_INSTALL_FULL_DATADIR}/pmu-dds" CACHE PATH
    "Where the IDL and the clients' fallback qos.xml are installed")
# Debian bookworm's systemd and debhelper expect package units in /lib/systemd/system, while
# an install under /usr/local wants PREFIX/lib/systemd/system: debian/rules sets it.
set(PMU_SYSTEMD_UNITDIR "${CMAKE_INSTALL_PREFIX}/lib/systemd/system" CACHE PATH
    "Where the systemd units are installed")
# User units (pmuctl-agent@.service): /usr/lib/systemd/user under the /usr prefix, as Debian has them.
set(PMU_SYSTEMD_USERUNITDIR "${CMAKE_INSTALL_PREFIX}/lib/systemd/user" CACHE PATH
    "Where the systemd user units are installed")

# The binaries learn the directory from this one generated header, so nothing else in the
# sources names it and no build-tree path reaches an installed binary.
configure_file(${CMAKE_CURRENT_LIST_DIR}/sysconf_dir.hpp.in
               ${PROJECT_BINARY_DIR}/generated/include/pmu/sysconf_dir.hpp @ONLY)
add_library(pmu_sysconf_dir INTERFACE)
target_include_directories(pmu_sysconf_dir INTERFACE ${PROJECT_BINARY_DIR}/generated/include)
add_library(pmu::sysconf_dir ALIAS pmu_sysconf_dir)

# The release and contract versions every program's --version prints (pmu::version). The
# release is the package's: a version in CMakeLists.txt that debian/changelog does not carry
# would make `--version` lie about the installed package.
set(PMU_CONTRACT_VERSION 5)
file(STRINGS ${PROJECT_SOURCE_DIR}/debian/changelog pmu_changelog_head LIMIT_COUNT 1)
if(NOT pmu_changelog_head MATCHES "^pmu-dds \\(${PROJECT_VERSION}-[^)]+\\)")
  message(FATAL_ERROR "debian/changelog's newest entry (${pmu_changelog_head}) is not version ${PROJECT_VERSION} "
                      "of CMakeLists.txt's project(): change both together")
endif()
configure_file(${CMAKE_CURRENT_LIST_DIR}/version.hpp.in
               ${PROJECT_BINARY_DIR}/generated/include/pmu/version.hpp @ONLY)
add_library(pmu_version INTERFACE)
target_include_directories(pmu_version INTERFACE ${PROJECT_BINARY_DIR}/generated/include)
add_library(pmu::version ALIAS pmu_version)
