#!/usr/bin/env bash
# Installs every Debian package that building, testing and running pmu-dds needs.
# Idempotent: packages already present are left alone, and apt is not touched at all
# when nothing is missing (so repeated test runs stay fast and work offline).
set -euo pipefail

packages=(
  build-essential cmake ninja-build pkg-config
  clang-14 libclang-rt-14-dev lld-14
  libgtest-dev libgmock-dev libbenchmark-dev
  libfastrtps-dev libfastcdr-dev fastddsgen fastdds-tools
  libspdlog-dev libfmt-dev libsystemd-dev libcli11-dev libyaml-cpp-dev nlohmann-json3-dev
  # pmuctl serve: a WebSocket server (header-only) on standalone asio
  libwebsocketpp-dev libasio-dev
  libssl-dev libtinyxml2-dev openssl
  cyclonedds-dev cyclonedds-tools
  can-utils iproute2 python3 python3-can
  # The VM of the system tests and the network lab (tests/lab: iproute2's ip and tc with
  # netem's distribution tables go into it; its kernel is downloaded, not installed)
  qemu-system-x86 busybox-static cpio kmod
  # Debian packages (scripts/package.sh): debhelper, lintian; arm64 cross-built, its tests
  # under qemu-user
  debhelper dpkg-dev lintian crossbuild-essential-arm64 qemu-user-static
  # The systemd system test (tests/systemd): a bookworm root file system made with mmdebstrap
  # and written into an image with mkfs.ext4 -d
  mmdebstrap e2fsprogs
)
# The arm64 build dependencies, from multiarch (dpkg --add-architecture arm64). yaml-cpp's
# -dev is not Multi-Arch: same, so the arm64 build takes the runtime library and the amd64
# headers (cmake/yaml_cpp.cmake); debian/control says the same.
arm64_packages=(
  libfastrtps-dev:arm64 libfastcdr-dev:arm64 libspdlog-dev:arm64 libfmt-dev:arm64
  libsystemd-dev:arm64 libyaml-cpp0.7:arm64 libssl-dev:arm64 libtinyxml2-dev:arm64
  libgtest-dev:arm64 libgmock-dev:arm64 pkg-config:arm64 libwebsocketpp-dev:arm64
)
packages+=("${arm64_packages[@]}")

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

add_arm64=0
dpkg --print-foreign-architectures | grep -qx arm64 || add_arm64=1

SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
need_root() {
  [ -z "$SUDO" ] || command -v sudo >/dev/null || { echo "setup: need root (or sudo) to install: $*" >&2; exit 1; }
}

if [ ${#missing[@]} -eq 0 ] && [ "$add_arm64" -eq 0 ]; then
  echo "setup: all ${#packages[@]} packages present"
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

# The MCAP tests (tests/mcap) read pmuctl's files with the ecosystem's own npm packages on
# Node.js. Node.js may come from elsewhere (NodeSource bundles npm): Debian's nodejs and npm
# are installed only when the commands are missing. The packages come from the lock file
# (npm ci), and only when it changed since the last install.
if ! command -v node >/dev/null || ! command -v npm >/dev/null; then
  need_root nodejs npm
  echo "setup: installing nodejs npm (Debian) for tests/mcap"
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -q
  $SUDO apt-get install -y -q --no-install-recommends nodejs npm
fi
mcap_dir="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)/tests/mcap"
stamp="$mcap_dir/node_modules/.package-lock.json"
if [ ! -f "$stamp" ] || [ "$mcap_dir/package-lock.json" -nt "$stamp" ]; then
  echo "setup: npm ci in tests/mcap (@mcap/core, @foxglove/ws-protocol, ws, @foxglove/omgidl-parser, @foxglove/omgidl-serialization)"
  (cd "$mcap_dir" && npm ci --no-audit --no-fund --loglevel=error)
else
  echo "setup: tests/mcap npm packages present"
fi
