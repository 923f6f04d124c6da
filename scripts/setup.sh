#!/usr/bin/env bash
# Installs the Debian packages of one set:
#   run   what building and running pmu-dds need (a tree with PMU_BUILD_TESTS and
#         PMU_BUILD_BENCH off, as a plain `cmake -S . -B build` configures it), and the ROS 2
#         message definitions from npm (npm ci in ros2/): scripts/run.sh
#   test  everything: the run set, the tests' and benchmarks' libraries, the VMs, the Debian
#         packaging and its arm64 cross build, ccache, tests/mcap's, tests/browser's and
#         tests/mavlink's npm packages: scripts/test.sh
#   scripts/setup.sh [run|test]        install the set (default: test)
#   scripts/setup.sh --list run|test   print the set's Debian packages, one per line
# Idempotent: packages already present are left alone, and apt is not touched at all
# when nothing is missing (so repeated test runs stay fast and work offline).
set -euo pipefail

usage() {
  echo "usage: scripts/setup.sh [run|test] | scripts/setup.sh --list run|test" >&2
  exit 2
}
list=0
set_name="test"
case "$#:${1:-}" in
  0:) ;;
  1:run | 1:test) set_name=$1 ;;
  2:--list)
    case "$2" in run | test) list=1; set_name=$2 ;; *) echo "setup: unknown set '$2'" >&2; usage ;; esac ;;
  *) echo "setup: bad arguments: $*" >&2; usage ;;
esac

# Debian's Build-Depends (debian/control) without the test ones: the CMake files find these
# whatever the options.
run_packages=(
  build-essential cmake ninja-build pkg-config
  libfastrtps-dev libfastcdr-dev fastddsgen
  libspdlog-dev libfmt-dev libsystemd-dev libcli11-dev libyaml-cpp-dev nlohmann-json3-dev
  # pmuctl serve: a WebSocket server (header-only) on standalone asio
  libwebsocketpp-dev libasio-dev
  libssl-dev libtinyxml2-dev
  # ros2/: rosidl_adapter turns ROS 2 .msg files into IDL (python3-rosidl; its rosidl_adapter
  # imports em, which the package does not depend on). tests/contract's IDL layout guard
  # parses idl/ with the IDL 4.2 grammar (lark) of the same package.
  python3-rosidl python3-empy
)
test_only_packages=(
  ccache
  # scripts/format.sh and its check (tests/rooms): the layout .clang-format describes
  clang-format-14
  clang-14 libclang-rt-14-dev lld-14
  libgtest-dev libgmock-dev libbenchmark-dev
  # fastdds: the Discovery Server of the discovery tests; openssl: the DDS-Security PKI
  fastdds-tools openssl
  cyclonedds-dev cyclonedds-tools
  can-utils iproute2 python3 python3-can
  # The VM of the system tests and the network lab (tests/lab: iproute2's ip and tc with
  # netem's distribution tables go into it; its kernel is downloaded, not installed)
  qemu-system-x86 busybox-static cpio kmod
  # eu-stack: the hot-standby suite prints each live instance's thread stacks on a failure
  elfutils
  # Debian packages (scripts/package.sh): debhelper, lintian; arm64 cross-built, its tests
  # under qemu-user
  debhelper dpkg-dev lintian crossbuild-essential-arm64 qemu-user-static
  # The systemd system test (tests/systemd): a bookworm root file system made with mmdebstrap
  # and written into an image with mkfs.ext4 -d
  mmdebstrap e2fsprogs
  # The browser test (tests/browser): a page in headless Chromium reads pmuctl serve
  chromium
)
# The arm64 build dependencies, from multiarch (dpkg --add-architecture arm64). yaml-cpp's
# -dev is not Multi-Arch: same, so the arm64 build takes the runtime library and the amd64
# headers (cmake/yaml_cpp.cmake); debian/control says the same.
arm64_packages=(
  libfastrtps-dev:arm64 libfastcdr-dev:arm64 libspdlog-dev:arm64 libfmt-dev:arm64
  libsystemd-dev:arm64 libyaml-cpp0.7:arm64 libssl-dev:arm64 libtinyxml2-dev:arm64
  libgtest-dev:arm64 libgmock-dev:arm64 pkg-config:arm64 libwebsocketpp-dev:arm64
)
# Node.js's npm, which fetches the ROS 2 message definitions (ros2/) and the MCAP tests'
# readers (tests/mcap) and the browser test's driver (tests/browser); installed below only when node or npm is missing.
node_packages=(nodejs npm)

packages=("${run_packages[@]}")
if [ "$set_name" = test ]; then packages+=("${test_only_packages[@]}" "${arm64_packages[@]}"); fi

if [ "$list" = 1 ]; then
  printf '%s\n' "${packages[@]}" "${node_packages[@]}"
  exit 0
fi

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

add_arm64=0
if [ "$set_name" = test ]; then
  dpkg --print-foreign-architectures | grep -qx arm64 || add_arm64=1
fi

SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
need_root() {
  [ -z "$SUDO" ] || command -v sudo >/dev/null || { echo "setup: need root (or sudo) to install: $*" >&2; exit 1; }
}

if [ ${#missing[@]} -eq 0 ] && [ "$add_arm64" -eq 0 ]; then
  echo "setup: all ${#packages[@]} packages of the $set_name set present"
else
  need_root "${missing[*]}"
  if [ "$add_arm64" -eq 1 ]; then
    echo "setup: adding the arm64 architecture (dpkg multiarch, for the arm64 packages)"
    $SUDO dpkg --add-architecture arm64
  fi
  echo "setup: installing ${missing[*]}"
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -q
  $SUDO apt-get install -y -q --no-install-recommends "${missing[@]}"
fi

# npm packages, each folder's from its lock file (npm ci), and only when the lock file changed
# since the last install. Node.js may come from elsewhere (NodeSource bundles npm): Debian's
# nodejs and npm are installed only when the commands are missing.
if ! command -v node >/dev/null || ! command -v npm >/dev/null; then
  need_root "${node_packages[*]}"
  echo "setup: installing ${node_packages[*]} (Debian) for npm"
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -q
  $SUDO apt-get install -y -q --no-install-recommends "${node_packages[@]}"
fi
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
npm_ci() {  # npm_ci FOLDER WHAT
  local stamp="$root/$1/node_modules/.package-lock.json"
  if [ ! -f "$stamp" ] || [ "$root/$1/package-lock.json" -nt "$stamp" ]; then
    echo "setup: npm ci in $1 ($2)"
    (cd "$root/$1" && npm ci --no-audit --no-fund --loglevel=error)
  else
    echo "setup: $1 npm packages present"
  fi
}

# The build generates ROS 2's types from the upstream .msg files, which no Debian package has
# for ROS 2 (ros2/CMakeLists.txt).
npm_ci ros2 "@foxglove/rosmsg-msgs-common: the ROS 2 .msg definitions"

[ "$set_name" = test ] || exit 0

# The MCAP tests (tests/mcap) read pmuctl's files with the ecosystem's own npm packages.
npm_ci tests/mcap "@mcap/core, @foxglove/ws-protocol, ws, @foxglove/omgidl-parser, @foxglove/omgidl-serialization"

# The browser test (tests/browser) drives Debian's Chromium with puppeteer-core and bundles
# Foxglove's omgidl decoder for the page with esbuild.
npm_ci tests/browser "puppeteer-core, esbuild, @foxglove/omgidl-parser, @foxglove/omgidl-serialization"

# The MAVLink cross-check (tests/mavlink) reads and writes pmu::mavlink's frames with
# node-mavlink, a MAVLink implementation generated from the same XML by other hands.
npm_ci tests/mavlink "node-mavlink"
