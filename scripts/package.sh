#!/usr/bin/env bash
# Builds the Debian packages pmu-dds and pmu-dds-tools and checks them with lintian.
#
#   scripts/package.sh [--arch amd64|arm64] [--out DIR]
#
#   --arch ARCH  the architecture to build for (default: this machine's). Another one is
#                cross-built with Debian multiarch; its tests run under qemu-user.
#   --out DIR    where the .deb, .buildinfo and .changes go (default build/packages/ARCH)
#
# DEB_BUILD_OPTIONS=nocheck builds no tests at all (scripts/test.sh does this for amd64,
# whose release build has run every test). Build dependencies: scripts/setup.sh.
# The build runs in a copy of the source tree under build/, so the tree stays clean and the
# packages do not land in the repository's parent directory, where dpkg-buildpackage
# would put them. Exit status: 0 when built and lintian-clean, 1 otherwise, 2 on bad usage.
set -euo pipefail

root=$(cd "$(dirname "$0")/.." && pwd)
arch=$(dpkg --print-architecture)
out=

usage() { sed -n '2,/^$/p' "$0" | sed 's/^# \{0,1\}//'; }
die() { echo "package.sh: $*" >&2; exit 1; }

while [ $# -gt 0 ]; do
  case "$1" in
    --arch) [ $# -ge 2 ] || { usage >&2; exit 2; }; arch=$2; shift 2 ;;
    --arch=*) arch=${1#*=}; shift ;;
    --out) [ $# -ge 2 ] || { usage >&2; exit 2; }; out=$2; shift 2 ;;
    --out=*) out=${1#*=}; shift ;;
    -h|--help) usage; exit 0 ;;
    *) echo "package.sh: unknown argument '$1'" >&2; usage >&2; exit 2 ;;
  esac
done
case "$arch" in amd64|arm64) ;; *) echo "package.sh: --arch must be amd64 or arm64, not '$arch'" >&2; exit 2 ;; esac
out=${out:-$root/build/packages/$arch}
mkdir -p "$out"
out=$(cd "$out" && pwd)

build_arch=$(dpkg --print-architecture)
args=(-b -us -uc)
profiles=()
if [ "$arch" != "$build_arch" ]; then
  args+=(--host-arch "$arch")
  profiles+=(cross)
fi
case " ${DEB_BUILD_OPTIONS:-} " in *" nocheck "*) profiles+=(nocheck) ;; esac
if [ ${#profiles[@]} -gt 0 ]; then args+=(--build-profiles="$(IFS=,; echo "${profiles[*]}")"); fi
# dpkg-buildpackage turns this into DEB_BUILD_OPTIONS parallel=N.
args+=(--jobs-try="$(nproc)")

version=$(dpkg-parsechangelog -l "$root/debian/changelog" -S Version)
upstream=${version%-*}
# The changelog and CMakeLists.txt must not disagree about what is being packaged.
project_version=$(sed -n 's/^project(pmu_dds VERSION \([0-9.]*\).*/\1/p' "$root/CMakeLists.txt")
[ "$upstream" = "$project_version" ] ||
  die "debian/changelog says $upstream but CMakeLists.txt says $project_version: add a changelog entry (dch -v $project_version-1)"

# ---- a copy of the source: what git tracks plus new files it does not ignore -------------
stage=$root/build/packages/.stage-$arch
src=$stage/pmu-dds-$upstream
rm -rf "$stage"
mkdir -p "$src"
if git -C "$root" rev-parse --git-dir >/dev/null 2>&1; then
  (cd "$root" && git ls-files -z --cached --others --exclude-standard |
     tar --null --ignore-failed-read -T - -cf -) | tar -xf - -C "$src"
else
  tar -C "$root" --exclude=./build --exclude=./.git -cf - . | tar -xf - -C "$src"
fi
# The ROS 2 .msg files the build generates types from are npm's (scripts/setup.sh), which git
# ignores; Debian has no package of them for the Build-Depends.
if [ -d "$root/ros2/node_modules" ] && [ ! -d "$src/ros2/node_modules" ]; then
  cp -a "$root/ros2/node_modules" "$src/ros2/"
fi

echo "package.sh: building pmu-dds $version for $arch (${profiles[*]:-no profiles}) in $src"
start=$(date +%s)
(cd "$src" && nice dpkg-buildpackage "${args[@]}") || die "dpkg-buildpackage failed for $arch (log above; tree kept in $src)"
echo "package.sh: built in $(( $(date +%s) - start )) s"

changes=$stage/pmu-dds_${version}_${arch}.changes
[ -f "$changes" ] || die "dpkg-buildpackage left no $changes"
# Move what this build made (named in the .changes), plus the .changes itself.
files=$(sed -n '/^Files:/,/^[^ ]/s/^ [0-9a-f]\{32\} [0-9]* [^ ]* [^ ]* \(.*\)$/\1/p' "$changes")
[ -n "$files" ] || die "no files listed in $changes"
rm -f "$out"/pmu-dds*_"$arch".deb "$out"/pmu-dds*_"$arch".ddeb "$out"/pmu-dds_*_"$arch".buildinfo "$out"/pmu-dds_*_"$arch".changes
for f in $files; do mv "$stage/$f" "$out/"; done
mv "$changes" "$out/"
rm -rf "$stage"

echo "package.sh: lintian $out/$(basename "$changes")"
# Fails on warnings as well as errors; the overrides in debian/*.lintian-overrides carry
# their reasons.
lintian --fail-on error,warning --display-info "$out/$(basename "$changes")" ||
  die "lintian found errors or warnings in the $arch packages (above)"
ls -l "$out"
