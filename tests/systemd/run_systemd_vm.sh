#!/usr/bin/env bash
# System test under a real systemd: boots a Debian bookworm root file system (made with
# mmdebstrap, cached) with Debian's kernel in qemu TCG, systemd as PID 1, installs the
# pmu-dds packages there with dpkg -i and runs tests/systemd/scenarios.sh against the
# packaged unit. See tests/systemd/README.md.
#
#   run_systemd_vm.sh [--build-dir DIR] [--deb-dir DIR] [--scenario NAME]... [--list]
#                     [--timeout S] [--log FILE] [--keep] [--verbose] [--rebuild-rootfs]
#
# Exit status: 0 when every scenario passed, 1 when one failed or did not report, 2 for a
# usage error or something missing that the test needs (packages not built, mmdebstrap,
# the root file system cannot be made), 77 (ctest: skipped) only when this machine cannot
# run qemu at all.
set -euo pipefail

script_dir=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
source_dir=$(cd "$script_dir/../.." && pwd)
build_dir=""
deb_dir=""
scenarios=()
list_only=0
vm_timeout=${PMU_VM_TIMEOUT:-900}
cache_root=${PMU_VM_CACHE:-${HOME:-/tmp}/.cache/pmu-dds-vm}
log_file=""
keep=0
verbose=0
rebuild=0

die() { echo "run_systemd_vm: $*" >&2; exit 2; }
skip() { echo "run_systemd_vm: SKIP: $*" >&2; exit 77; }
note() { echo "run_systemd_vm: $*" >&2; }
. "$(dirname "${BASH_SOURCE[0]}")/../system/vm_host_lib.sh"
usage() { sed -n '2,14p' "${BASH_SOURCE[0]}" | sed 's/^# \{0,1\}//'; exit "${1:-0}"; }

while [ $# -gt 0 ]; do
  case "$1" in
    --build-dir) build_dir=$2; shift 2 ;;
    --deb-dir) deb_dir=$2; shift 2 ;;
    --scenario) scenarios+=("$2"); shift 2 ;;
    --timeout) vm_timeout=$2; shift 2 ;;
    --log) log_file=$2; shift 2 ;;
    --keep) keep=1; shift ;;
    --verbose) verbose=1; shift ;;
    --rebuild-rootfs) rebuild=1; shift ;;
    --list) list_only=1; shift ;;
    -h|--help) usage 0 ;;
    *) echo "run_systemd_vm: unknown argument '$1'" >&2; usage 2 ;;
  esac
done

suite_script="$script_dir/scenarios.sh"
all_scenarios=$(sed -n 's/^ALL_SCENARIOS="\(.*\)"$/\1/p' "$suite_script")
[ -n "$all_scenarios" ] || die "cannot read ALL_SCENARIOS from $suite_script"
if [ "$list_only" = 1 ]; then tr ' ' '\n' <<<"$all_scenarios"; exit 0; fi
if [ ${#scenarios[@]} -eq 0 ]; then
  read -r -a scenarios <<<"$all_scenarios"
else
  for s in "${scenarios[@]}"; do
    case " $all_scenarios " in *" $s "*) ;; *) die "unknown scenario '$s' (known: $all_scenarios)" ;; esac
  done
fi

[ -n "$build_dir" ] || build_dir="$source_dir/build/release"
mkdir -p "$build_dir" && build_dir=$(cd "$build_dir" && pwd)
# scripts/package.sh writes build/packages/<arch>/ beside the build directories.
if [ -z "$deb_dir" ]; then
  deb_dir="$build_dir/../packages/amd64"
  [ -d "$deb_dir" ] || deb_dir="$source_dir/build/packages/amd64"
fi
[ -n "$log_file" ] || log_file="$build_dir/systemd-vm-console.log"

t0=$(date +%s.%N)
phase_names=() phase_secs=()
phase_mark=$t0
phase() {  # NAME: the time since the previous mark is NAME's
  local t; t=$(date +%s.%N)
  phase_names+=("$1"); phase_secs+=("$(awk -v a="$phase_mark" -v b="$t" 'BEGIN { printf "%.1f", b - a }')")
  phase_mark=$t
}

# ---- prerequisites ---------------------------------------------------------------------
# Only a machine that cannot run qemu at all skips; everything else the test needs is a
# failure with its reason, so a CI machine missing a package does not pass silently.
command -v qemu-system-x86_64 >/dev/null ||
  skip "needs qemu-system-x86 (scripts/setup.sh installs it): qemu-system-x86_64 not found"
command -v mmdebstrap >/dev/null || die "needs mmdebstrap (scripts/setup.sh installs it)"
for tool in mkfs.ext4 dpkg-deb apt-cache sha256sum; do
  command -v "$tool" >/dev/null || die "needs '$tool' (e2fsprogs, dpkg, apt)"
done

pick_deb() {  # PACKAGE: the newest PACKAGE_*_amd64.deb in deb_dir
  local f
  f=$(ls -t "$deb_dir/$1"_*_amd64.deb 2>/dev/null | head -n1 || true)
  [ -n "$f" ] || die "no $1_*_amd64.deb in $deb_dir: build the packages first (scripts/package.sh), or pass --deb-dir DIR"
  echo "$f"
}
deb_main=$(pick_deb pmu-dds)
deb_tools=$(pick_deb pmu-dds-tools)
note "packages: $(basename "$deb_main") $(basename "$deb_tools") (from $deb_dir)"

# ---- the root file system: what goes in, and its cache key -----------------------------
# The kernel is the one linux-image-amd64 depends on, as for tests/system (same cache
# root); it is installed in the image so that networkd's vcan and the CAN modules load
# the ordinary way (modprobe from /lib/modules), and its vmlinuz and an initramfs made by
# initramfs-tools in the image boot the VM.
kernel_pkg=$(kernel_package)
# libpam-systemd: a user's systemd manager (user@UID.service) gets its XDG_RUNTIME_DIR from it,
# as on an ordinary Debian install; the agent_user scenario runs pmuctl-agent@ under one.
base_packages="systemd udev dbus libnss-systemd libpam-systemd kmod iproute2 can-utils openssl initramfs-tools"
# The packages' own run-time dependencies are installed in the image ahead of time, so
# that the test's `dpkg -i` needs no archive; the packages themselves are not.
deb_depends() {  # DEB...: first alternative of each Depends/Pre-Depends, no versions
  local d
  for d in "$@"; do
    { dpkg-deb -f "$d" Depends; dpkg-deb -f "$d" Pre-Depends; } 2>/dev/null
  done | tr ',' '\n' | sed 's/|.*//; s/(.*)//; s/:any//; s/[[:space:]]//g' | grep -v '^$' |
    grep -vx -e pmu-dds -e pmu-dds-tools | sort -u | tr '\n' ' '
}
dep_packages=$(deb_depends "$deb_main" "$deb_tools")

suites=("deb http://deb.debian.org/debian bookworm main"
        "deb http://deb.debian.org/debian bookworm-updates main"
        "deb http://deb.debian.org/debian-security bookworm-security main")
# The recipe is everything the image depends on: the package lists, the kernel, the
# archive, and this script's hook (its text between the markers below).
recipe=$(printf '%s\n' "kernel=$kernel_pkg" "base=$base_packages" "deps=$dep_packages" "${suites[@]}"
         sed -n '/^# ---- rootfs recipe begin/,/^# ---- rootfs recipe end/p' "${BASH_SOURCE[0]}")
key=$(sha256sum <<<"$recipe" | cut -c1-16)
rootfs_cache="$cache_root/systemd-rootfs"
img_dir="$rootfs_cache/$key"

# ---- rootfs recipe begin
# Runs in the new root after the essential packages, before the others: the initramfs
# only needs to find an ext4 root on virtio (MODULES=list keeps it small and quick to make
# under a loaded machine's dpkg).
essential_hook() {
  local r=$1
  mkdir -p "$r/etc/initramfs-tools/conf.d" "$r/etc/initramfs-tools/hooks"
  printf 'MODULES=list\nCOMPRESS=gzip\n' >"$r/etc/initramfs-tools/conf.d/pmu-vm"
  cat >"$r/etc/initramfs-tools/hooks/pmu-vm" <<'EOF'
#!/bin/sh
[ "$1" = prereqs ] && exit 0
. /usr/share/initramfs-tools/hook-functions
manual_add_modules virtio_pci virtio_blk ext4
EOF
  chmod 755 "$r/etc/initramfs-tools/hooks/pmu-vm"
}
# Runs last: the system the scenarios expect.
customize_hook() {
  local r=$1
  echo pmu-vm >"$r/etc/hostname"
  printf '127.0.0.1 localhost\n127.0.1.1 pmu-vm\n' >"$r/etc/hosts"
  : >"$r/etc/fstab"
  chroot "$r" systemctl enable systemd-networkd.service >/dev/null 2>&1
  # deploy/README.md's advice for a machine whose networkd manages only CAN links: without
  # a link required for online, wait-online would hold network-online.target (and so
  # pmu-service, which wants it) for its 2 min timeout.
  chroot "$r" systemctl disable systemd-networkd-wait-online.service >/dev/null 2>&1 || true
  # The console belongs to the scenario lines, not to a login prompt.
  chroot "$r" systemctl mask serial-getty@ttyS0.service getty@tty1.service >/dev/null 2>&1
  # The test runner: after boot, mount the second disk (the packages and scenarios of this
  # run) and run its run.sh with its output on the serial console; power off either way.
  cat >"$r/etc/systemd/system/pmu-vm-test.service" <<'EOF'
[Unit]
Description=pmu-dds systemd VM test (scenarios from the payload disk)
After=multi-user.target
[Service]
Type=oneshot
ExecStartPre=/bin/mkdir -p /run/payload
ExecStartPre=/bin/mount -o ro /dev/vdb /run/payload
ExecStart=/bin/sh /run/payload/run.sh
StandardOutput=tty
StandardError=tty
TTYPath=/dev/ttyS0
SuccessAction=poweroff-force
FailureAction=poweroff-force
[Install]
WantedBy=multi-user.target
EOF
  chroot "$r" systemctl enable pmu-vm-test.service >/dev/null 2>&1
  rm -rf "$r"/var/cache/apt/archives/*.deb "$r"/var/lib/apt/lists/* "$r"/usr/share/doc/* "$r"/usr/share/man/* "$r"/usr/share/locale/*
}
# Only vmlinuz and the initramfs leave the image; the kernel's modules stay for modprobe
# (vcan, can-dev, ...), minus the large trees a VM with virtio and vcan never loads, which
# dpkg does not even unpack (the kernel's postinst runs depmod over the rest).
mm_opts=()
for d in sound drivers/gpu drivers/media drivers/infiniband drivers/staging drivers/net/wireless \
         drivers/net/ethernet drivers/scsi drivers/usb drivers/bluetooth drivers/isdn drivers/iio \
         drivers/hid drivers/input drivers/mtd drivers/platform drivers/hwmon drivers/thunderbolt \
         drivers/video net/wireless net/mac80211 net/bluetooth fs/btrfs fs/xfs fs/ocfs2 fs/nfs fs/smb; do
  mm_opts+=("--dpkgopt=path-exclude=/lib/modules/*/kernel/$d/*")
done
# dpkg syncs every file it writes; on a busy machine that is most of the build, and this
# image is thrown away on any doubt. mmdebstrap's eatmydata hook turns the syncs off.
[ -d /usr/share/mmdebstrap/hooks/eatmydata ] && mm_opts+=(--hook-dir=/usr/share/mmdebstrap/hooks/eatmydata)
# ---- rootfs recipe end

build_rootfs() {
  # --mode=root: the image's files must belong to root, as mkfs.ext4 -d copies ownership.
  [ "$(id -u)" = 0 ] || die "building the root file system needs root (mmdebstrap --mode=root); run once as root to fill $rootfs_cache"
  [ -n "$kernel_pkg" ] || die "apt-cache knows no linux-image-amd64 (run apt-get update): cannot choose the VM's kernel"
  local tmp="$rootfs_cache/tmp-$key" includes
  rm -rf "$tmp"; mkdir -p "$tmp"
  includes=$(tr ' ' '\n' <<<"$base_packages $dep_packages $kernel_pkg" | grep -v '^$' | paste -sd, -)
  note "building the root file system (mmdebstrap bookworm, cache key $key): $includes"
  # mmdebstrap runs a hook with sh -c; these functions are bash, hence `bash FILE NAME ROOT`.
  { declare -f essential_hook customize_hook; echo '"$@"'; } >"$tmp/hooks.sh"
  # The downloaded packages are kept (debs/) so that a new recipe, e.g. a changed package
  # list, downloads only what changed: downloading is most of a cold build here.
  mkdir -p "$rootfs_cache/debs"
  if ! mmdebstrap --variant=minbase --mode=root --format=directory --include="$includes" \
      --skip=essential/unlink "${mm_opts[@]}" \
      --setup-hook='mkdir -p "$1"/var/cache/apt/archives/' \
      --setup-hook="sync-in $rootfs_cache/debs /var/cache/apt/archives/" \
      --customize-hook="sync-out /var/cache/apt/archives $rootfs_cache/debs" \
      --essential-hook="bash $tmp/hooks.sh essential_hook \"\$1\"" \
      --customize-hook="bash $tmp/hooks.sh customize_hook \"\$1\"" \
      bookworm "$tmp/root" "${suites[@]}" >"$tmp/mmdebstrap.log" 2>&1; then
    tail -n 15 "$tmp/mmdebstrap.log" >&2
    die "mmdebstrap failed (log: $tmp/mmdebstrap.log)"
  fi
  local vmlinuz initrd
  vmlinuz=$(ls "$tmp"/root/boot/vmlinuz-* 2>/dev/null | head -n1 || true)
  initrd=$(ls "$tmp"/root/boot/initrd.img-* 2>/dev/null | head -n1 || true)
  [ -n "$vmlinuz" ] && [ -n "$initrd" ] || die "the root file system has no /boot/vmlinuz-* and initrd.img-* (log: $tmp/mmdebstrap.log)"
  cp "$vmlinuz" "$tmp/vmlinuz"; cp "$initrd" "$tmp/initrd.img"
  # Room for the packages, the PKI and the journal on top of what is there.
  local mb
  mb=$(( $(du -sm "$tmp/root" | cut -f1) + 256 ))
  mkfs.ext4 -q -F -L pmuroot -d "$tmp/root" "$tmp/root.img" "${mb}M" || die "mkfs.ext4 -d failed"
  rm -rf "$tmp/root"
  printf '%s\n' "$recipe" >"$tmp/recipe"
  rm -rf "$img_dir"; mv "$tmp" "$img_dir"
}

mkdir -p "$rootfs_cache" || die "cannot create $rootfs_cache (set PMU_VM_CACHE)"
# Two runs at once (two worktrees, say) must not build into the same directory.
exec 9>"$rootfs_cache/.lock"
flock 9
rootfs_state=warm
if [ "$rebuild" = 1 ] || [ ! -f "$img_dir/root.img" ]; then
  rootfs_state=cold
  build_rootfs
  # Older images (another package list) are of no further use.
  for d in "$rootfs_cache"/*/; do
    case "${d%/}" in "$img_dir"|"$rootfs_cache/debs") ;; *) rm -rf "$d" ;; esac
  done
fi
flock -u 9
phase "rootfs ($rootfs_state)"

# ---- this run's payload: a second disk with the packages and the scenarios -------------
work=$(mktemp -d "${TMPDIR:-/tmp}/pmu-systemd-vm.XXXXXX")
qemu_pid=""
cleanup() {
  if [ "$keep" = 1 ]; then note "kept $work"; else rm -rf "$work"; fi
}
trap cleanup EXIT
trap 'exit 130' INT TERM

payload="$work/payload"
mkdir -p "$payload/debs" "$payload/upgrade"
cp "$deb_main" "$deb_tools" "$payload/debs/"
# The upgrade scenario's package: the same files under a higher version (what an apt
# upgrade would bring), so only dpkg's upgrade path (conffiles, maintainer scripts) differs.
version=$(dpkg-deb -f "$deb_main" Version)
dpkg-deb -R "$deb_main" "$work/up" || die "dpkg-deb -R $deb_main failed"
sed -i "s/^Version: .*/Version: ${version}+systemdtest1/" "$work/up/DEBIAN/control"
dpkg-deb --root-owner-group -Zgzip -z1 -b "$work/up" "$payload/upgrade/" >/dev/null || die "cannot repack the upgrade package"
rm -rf "$work/up"
cp "$suite_script" "$payload/scenarios.sh"
cp "$source_dir/tests/system/scenario_lib.sh" "$payload/scenario_lib.sh"
# For the security scenario, in case the package does not ship make_pki.sh.
cp "$source_dir/deploy/security/make_pki.sh" "$payload/make_pki.sh"
cat >"$payload/run.sh" <<'EOF'
#!/bin/sh
# Started by pmu-vm-test.service once multi-user.target is reached.
cd /run/payload || exit 1
echo   # the firmware's last escape sequence leaves the console mid-line
echo "VM: systemd $(systemctl --version | head -n1 | cut -d' ' -f2), kernel $(uname -r), $(nproc) cpu(s), multi-user.target reached $(cut -d' ' -f1 /proc/uptime) s after the kernel started"
sh /run/payload/scenarios.sh all
echo "VM: done, powering off"
# The root is a throw-away snapshot: nothing to save, so no orderly shutdown (which was
# seen to hang for minutes under TCG); the unit's SuccessAction= is the fallback.
echo o >/proc/sysrq-trigger
EOF
payload_mb=$(( $(du -sm "$payload" | cut -f1) + 16 ))
mkfs.ext4 -q -F -L pmupayload -d "$payload" "$work/payload.img" "${payload_mb}M" || die "mkfs.ext4 -d (payload) failed"
phase "payload"

# ---- boot ------------------------------------------------------------------------------
mkdir -p "$(dirname "$log_file")"
: >"$log_file"
append="root=/dev/vda rootfstype=ext4 rw init=/lib/systemd/systemd console=ttyS0 quiet panic=-1"
append+=" systemd.show_status=error pmu.scenarios=$(IFS=,; echo "${scenarios[*]}")"
note "booting qemu (TCG, systemd as PID 1, timeout ${vm_timeout}s), console log: $log_file"
set +e
# snapshot=on: writes go to a throw-away overlay, so every run starts from the same fresh
# root without copying the image.
timeout -k 10 "$vm_timeout" qemu-system-x86_64 -accel tcg -m 1024 -smp 2 -nographic -no-reboot -nic none \
  -kernel "$img_dir/vmlinuz" -initrd "$img_dir/initrd.img" -append "$append" \
  -drive "file=$img_dir/root.img,format=raw,if=virtio,snapshot=on" \
  -drive "file=$work/payload.img,format=raw,if=virtio,readonly=on" </dev/null 2>&1 |
  sed -u 's/\r$//' | tee "$log_file" | { if [ "$verbose" = 1 ]; then cat; else grep --line-buffered -E '^(RESULT|VM:|\[|SCENARIO)'; fi; }
qemu_status=${PIPESTATUS[0]}
set -e
phase "VM"
qemu_outcome "$qemu_status" "$vm_timeout" "$log_file"

# ---- verdict (the RESULT protocol of tests/system) -------------------------------------
echo
echo "== systemd system test (packages under a real systemd in a VM, $kernel_pkg) =="
failed=0
# No scenario here may skip: each checks something the packages must do.
print_verdict "$log_file" " " "${scenarios[@]}" || failed=1
phase "verdict"
total=$(awk -v a="$t0" -v b="$(date +%s.%N)" 'BEGIN { printf "%.1f", b - a }')
printf 'wall time: %s s total (' "$total"
for i in "${!phase_names[@]}"; do printf '%s%s %s s' "$([ "$i" = 0 ] || echo ', ')" "${phase_names[$i]}" "${phase_secs[$i]}"; done
echo ")"
if [ $failed = 0 ]; then echo "systemd system test: PASS"; else echo "systemd system test: FAIL (console log: $log_file)"; fi
exit $failed
