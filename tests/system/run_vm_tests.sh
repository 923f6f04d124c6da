#!/usr/bin/env bash
# System tests on real SocketCAN: boots Debian's own kernel in a small qemu VM (this
# machine's kernel has no CAN), with an initramfs holding busybox, can-utils, iproute2,
# the project's binaries and tests/system/scenarios.sh, and checks what the scenarios
# print on the VM's console. See tests/system/README.md.
# --suite lab boots the same kernel with the network lab instead (tests/lab/README.md):
# veth, bridge and sch_netem, iproute2's ip and tc, pmu-service, pmuctl, lab_ground,
# fast-discovery-server, a DDS-Security PKI (make_pki.sh) and tests/lab/lab.sh, whose
# scenarios print the same RESULT lines.
# --suite standby boots it with the hot-standby suite (tests/standby/README.md): vcan, vxcan,
# can-gw, veth and bridge, can-utils' cangw, pmu-service, pmu-sim, pmuctl, lab_ground,
# standby_consumer and tests/standby/standby.sh: two instances of a pair in two hosts on one bus.
#
#   run_vm_tests.sh [--suite system|lab|standby] [--build-dir DIR] [--source-dir DIR] [--scenario NAME]...
#                   [--list] [--timeout S] [--log FILE] [--keep] [--verbose] [--service-log-level L]
#                   [--capture]
# --capture (lab): tcpdump on the ground link during the fleet8 scenario, which then prints on
# the console (lines "CAPTURE ...") the link's bytes in each of its phases, by direction and by
# kind (discovery, user data, to the Discovery Server). Needs tcpdump on this machine.
#
# Exit status: 0 when every scenario passed (a SKIP is allowed only for a scenario that
# waits for a pmuctl verb not written yet), 1 when a scenario failed or did not report,
# 2 for a usage error or a missing binary, 77 (ctest: skipped) when this machine cannot
# run the VM at all: no qemu-system-x86_64, or no kernel package to be had.
set -euo pipefail

script_dir=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
source_dir=$(cd "$script_dir/../.." && pwd)
build_dir=""
suite=system
list_only=0
scenarios=()
vm_timeout=${PMU_VM_TIMEOUT:-900}
cache_dir=${PMU_VM_CACHE:-${HOME:-/tmp}/.cache/pmu-dds-vm}
log_file=""
keep=0
verbose=0
service_log=""
capture=0
# Scenarios that may report SKIP without failing the run: they wait for a feature that is
# still being written and turn on by themselves once it exists.
skip_allowed=" commands_candump "

die() { echo "run_vm_tests: $*" >&2; exit 2; }
# Not a failure of the code under test: the machine lacks what the VM needs. ctest shows
# the test as skipped (SKIP_RETURN_CODE 77) and the reason is the last line of its output.
skip() { echo "run_vm_tests: SKIP: $*" >&2; exit 77; }
note() { echo "run_vm_tests: $*" >&2; }
. "$(dirname "${BASH_SOURCE[0]}")/vm_host_lib.sh"

usage() {
  sed -n '2,24p' "${BASH_SOURCE[0]}" | sed 's/^# \{0,1\}//'
  exit "${1:-0}"
}

while [ $# -gt 0 ]; do
  case "$1" in
    --suite) suite=$2; shift 2 ;;
    --build-dir) build_dir=$2; shift 2 ;;
    --source-dir) source_dir=$2; shift 2 ;;
    --scenario) scenarios+=("$2"); shift 2 ;;
    --timeout) vm_timeout=$2; shift 2 ;;
    --log) log_file=$2; shift 2 ;;
    --keep) keep=1; shift ;;
    --verbose) verbose=1; shift ;;
    --service-log-level) service_log=$2; shift 2 ;;
    --capture) capture=1; shift ;;
    --list) list_only=1; shift ;;
    -h|--help) usage 0 ;;
    *) echo "run_vm_tests: unknown argument '$1'" >&2; usage 2 ;;
  esac
done
# What differs between the suites: the scenario script, the kernel modules (each with what it
# depends on), and which scenarios may SKIP. Both share the kernel, the cache and the verdict.
# Every module of either suite is extracted into the one cache.
all_modules="can can-raw can-dev vcan vxcan can-gw veth bridge sch_netem"
case "$suite" in
  system)
    suite_script="$script_dir/scenarios.sh"
    suite_modules="can can-raw can-dev vcan"
    suite_title="system tests (real SocketCAN in a VM"
    suite_label="system tests"
    ;;
  lab)
    suite_script="$script_dir/../lab/lab.sh"
    suite_modules="veth bridge sch_netem"
    suite_title="network lab (namespaces and netem in a VM"
    suite_label="network lab"
    skip_allowed=" "
    ;;
  standby)
    suite_script="$script_dir/../standby/standby.sh"
    suite_modules="can can-raw can-dev vcan vxcan can-gw veth bridge"
    suite_title="hot standby (two hosts on one CAN bus in a VM"
    suite_label="hot standby"
    skip_allowed=" "
    ;;
  *) echo "run_vm_tests: unknown suite '$suite' (system, lab or standby)" >&2; usage 2 ;;
esac
[ -f "$suite_script" ] || die "$suite_script not found"
suite_script=$(cd "$(dirname "$suite_script")" && pwd)/$(basename "$suite_script")
if [ "$list_only" = 1 ]; then
  sed -n 's/^ALL_SCENARIOS="\(.*\)"$/\1/p' "$suite_script" | tr ' ' '\n'; exit 0
fi
[ -n "$build_dir" ] || build_dir="$source_dir/build-vm"
build_dir=$(cd "$build_dir" 2>/dev/null && pwd) || die "build directory '$build_dir' does not exist"
[ -n "$log_file" ] || log_file="$build_dir/$suite-vm-console.log"

all_scenarios=$(sed -n 's/^ALL_SCENARIOS="\(.*\)"$/\1/p' "$suite_script")
[ -n "$all_scenarios" ] || die "cannot read ALL_SCENARIOS from $suite_script"
# Scenarios run only when named (--scenario), never in the whole suite.
named_scenarios=$(sed -n 's/^NAMED_SCENARIOS="\(.*\)"$/\1/p' "$suite_script")
if [ ${#scenarios[@]} -eq 0 ]; then
  read -r -a scenarios <<<"$all_scenarios"
else
  for s in "${scenarios[@]}"; do
    case " $all_scenarios $named_scenarios " in *" $s "*) ;; *) die "unknown scenario '$s' (known: $all_scenarios $named_scenarios)" ;; esac
  done
fi

wall_start=$(date +%s.%N)

# ---- prerequisites ---------------------------------------------------------------------
command -v qemu-system-x86_64 >/dev/null ||
  skip "system tests need qemu-system-x86 (scripts/setup.sh installs it): qemu-system-x86_64 not found"
for tool in cpio gzip dpkg-deb modinfo ldd; do
  command -v "$tool" >/dev/null || die "system tests need '$tool' (scripts/setup.sh installs cpio, kmod)"
done
busybox_bin=""
for b in /bin/busybox /usr/bin/busybox; do
  if [ -x "$b" ] && ! ldd "$b" >/dev/null 2>&1; then busybox_bin=$b; break; fi  # static: ldd fails
done
[ -n "$busybox_bin" ] || die "system tests need busybox-static (scripts/setup.sh installs it)"
can_utils=()
can_tools=""
case "$suite" in
  system) can_tools="candump cansend cangen" ;;
  standby) can_tools="candump cansend cangw" ;;
esac
if [ -n "$can_tools" ]; then
  for t in $can_tools; do
    p=$(command -v "$t" || true)
    [ -n "$p" ] || die "system tests need can-utils ($t not found; scripts/setup.sh installs it)"
    can_utils+=("$p")
  done
fi
ip_bin=""
for p in /usr/sbin/ip /sbin/ip /usr/bin/ip /bin/ip; do [ -x "$p" ] && { ip_bin=$p; break; }; done
[ -n "$ip_bin" ] || die "system tests need iproute2's ip (scripts/setup.sh installs iproute2)"
tc_bin="" tc_lib=""
if [ "$suite" = lab ]; then
  for p in /usr/sbin/tc /sbin/tc; do [ -x "$p" ] && { tc_bin=$p; break; }; done
  [ -n "$tc_bin" ] || die "the lab needs iproute2's tc (scripts/setup.sh installs iproute2)"
  # netem's delay distributions (normal.dist ...) are files tc reads from its library folder.
  for d in /usr/lib/x86_64-linux-gnu/tc /usr/lib/tc /usr/lib64/tc; do [ -f "$d/normal.dist" ] && { tc_lib=$d; break; }; done
  [ -n "$tc_lib" ] || die "the lab needs tc's distribution tables (normal.dist; iproute2)"
  ds_bin=$(command -v fast-discovery-server || true)
  [ -n "$ds_bin" ] || die "the lab needs fast-discovery-server (scripts/setup.sh installs fastdds-tools)"
  command -v openssl >/dev/null || die "the lab needs openssl for its DDS-Security PKI (scripts/setup.sh installs it)"
fi
tcpdump_bin=""
if [ "$capture" = 1 ]; then
  [ "$suite" = lab ] || die "--capture is for the lab suite"
  tcpdump_bin=$(command -v tcpdump || true)
  [ -n "$tcpdump_bin" ] || die "--capture needs tcpdump (apt-get install tcpdump)"
fi

find_binary() {  # NAME EXPECTED-RELATIVE-PATH
  local p="$build_dir/$2"
  [ -x "$p" ] || p=$(find "$build_dir" -type f -name "$1" -perm -u+x 2>/dev/null | head -n1 || true)
  [ -n "$p" ] && [ -x "$p" ] || die "$1 not found under $build_dir; build it first:
  cmake -S $source_dir -B $build_dir -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo && cmake --build $build_dir -j2 --target pmu-service pmuctl pmu-sim"
  echo "$p"
}
svc_bin=$(find_binary pmu-service service/pmu-service)
ctl_bin=$(find_binary pmuctl tools/pmuctl)
case "$suite" in
  system) sim_bin=$(find_binary pmu-sim tools/pmu-sim) ;;
  lab) ground_bin=$(find_binary lab_ground tests/lab/lab_ground) ;;
  standby)
    sim_bin=$(find_binary pmu-sim tools/pmu-sim)
    ground_bin=$(find_binary lab_ground tests/lab/lab_ground)
    consumer_bin=$(find_binary standby_consumer tests/standby/standby_consumer)
    ;;
esac
qos_file="$source_dir/deploy/qos.xml"
[ -f "$qos_file" ] || die "$qos_file not found (--source-dir?)"

# ---- temporary space, removed on every exit --------------------------------------------
work=$(mktemp -d "${TMPDIR:-/tmp}/pmu-vm.XXXXXX")
qemu_pid=""
cleanup() {
  if [ -n "$qemu_pid" ] && kill -0 "$qemu_pid" 2>/dev/null; then kill "$qemu_pid" 2>/dev/null || true; fi
  if [ "$keep" = 1 ]; then note "kept $work"; else rm -rf "$work"; fi
}
trap cleanup EXIT
trap 'exit 130' INT TERM

# ---- the Debian kernel and its CAN modules (downloaded once into the cache) ------------
mkdir -p "$cache_dir" || die "cannot create cache directory $cache_dir (set PMU_VM_CACHE)"


# Extracts vmlinuz and MODULES (names) plus every module they depend on (modinfo -F
# depends, followed recursively) into DEST, and writes DEST/load-order: dependencies first.
extract_kernel() {  # DEB DEST MODULE...
  local deb=$1 dest=$2; shift 2
  local tmp="$dest.tmp"
  rm -rf "$tmp"; mkdir -p "$tmp/x" "$tmp/modules"
  dpkg-deb --fsys-tarfile "$deb" | tar -t >"$tmp/listing" || return 1
  local vmlinuz
  vmlinuz=$(grep -E '^\./boot/vmlinuz-' "$tmp/listing" | head -n1 || true)
  [ -n "$vmlinuz" ] || { echo "no /boot/vmlinuz-* in $deb" >&2; return 1; }
  dpkg-deb --fsys-tarfile "$deb" | tar -x -C "$tmp/x" "$vmlinuz" || return 1
  cp "$tmp/x/$vmlinuz" "$tmp/vmlinuz"

  local queue=("$@") done_list=" " order=() name norm path f deps d
  # Extract every module asked for, then their dependencies, one tar pass per round.
  while [ ${#queue[@]} -gt 0 ]; do
    local paths=() names=()
    for name in "${queue[@]}"; do
      norm=${name//_/-}
      case "$done_list" in *" $norm "*) continue ;; esac
      done_list+="$norm "
      path=$(grep -E "/kernel/.*/$norm\.ko(\.xz|\.zst|\.gz)?$" "$tmp/listing" | head -n1 || true)
      if [ -z "$path" ]; then  # the file may spell it with underscores
        path=$(grep -E "/kernel/.*/${name//-/_}\.ko(\.xz|\.zst|\.gz)?$" "$tmp/listing" | head -n1 || true)
      fi
      [ -n "$path" ] || { echo "module $name not in $deb" >&2; return 1; }
      paths+=("$path"); names+=("$norm")
    done
    queue=()
    [ ${#paths[@]} -gt 0 ] || break
    dpkg-deb --fsys-tarfile "$deb" | tar -x -C "$tmp/x" "${paths[@]}" || return 1
    local i
    for i in "${!paths[@]}"; do
      f="$tmp/x/${paths[$i]}"
      case "$f" in
        *.ko.xz) xz -dc "$f" >"$tmp/modules/${names[$i]}.ko" ;;
        *.ko.zst) zstd -qdc "$f" >"$tmp/modules/${names[$i]}.ko" ;;
        *.ko.gz) gzip -dc "$f" >"$tmp/modules/${names[$i]}.ko" ;;
        *) cp "$f" "$tmp/modules/${names[$i]}.ko" ;;
      esac || { echo "cannot decompress $f" >&2; return 1; }
      deps=$(modinfo -F depends "$tmp/modules/${names[$i]}.ko" 2>/dev/null | tr ',' ' ')
      echo "${names[$i]}: $deps" >>"$tmp/deps"
      for d in $deps; do queue+=("$d"); done
    done
  done
  # Load order: a module after everything it depends on, otherwise in the order asked.
  local placed=" " progress=1
  local all=("$@")
  while read -r line; do all+=("${line%%:*}"); done <"$tmp/deps"
  while [ $progress = 1 ]; do
    progress=0
    for name in "${all[@]}"; do
      norm=${name//_/-}
      case "$placed" in *" $norm "*) continue ;; esac
      deps=$(sed -n "s/^$norm: //p" "$tmp/deps")
      local ready=1
      for d in $deps; do case "$placed" in *" ${d//_/-} "*) ;; *) ready=0 ;; esac; done
      if [ $ready = 1 ]; then placed+="$norm "; order+=("$norm"); progress=1; fi
    done
  done
  printf '%s\n' "${order[@]}" >"$tmp/load-order"
  rm -rf "$tmp/x" "$tmp/listing"
  rm -rf "$dest"; mv "$tmp" "$dest"
}

# True when DIR's cache holds every module named (an older cache may lack the lab's).
has_modules() {  # DIR MODULE...
  local dir=$1 m; shift
  [ -f "$dir/load-order" ] || return 1
  for m in "$@"; do grep -qx "${m//_/-}" "$dir/load-order" || return 1; done
}

kernel_dir=""
pkg=$(kernel_package)
# shellcheck disable=SC2086 # module lists are word lists
if [ -n "$pkg" ] && has_modules "$cache_dir/$pkg" $suite_modules; then
  kernel_dir="$cache_dir/$pkg"
elif [ -n "$pkg" ] || [ -n "${PMU_VM_KERNEL_DEB:-}" ]; then
  deb=${PMU_VM_KERNEL_DEB:-}
  if [ -z "$deb" ]; then
    note "downloading $pkg (once, into $cache_dir)"
    mkdir -p "$cache_dir/download"
    if ! out=$(cd "$cache_dir/download" && apt-get download "$pkg" 2>&1); then
      if [ "$(id -u)" = 0 ] && apt-get update -q >/dev/null 2>&1; then
        out=$(cd "$cache_dir/download" && apt-get download "$pkg" 2>&1) ||
          skip "cannot download $pkg: $(grep -E '^(E|W):' <<<"$out" | head -n3)"
      else
        skip "cannot download $pkg: $(grep -E '^(E|W):' <<<"$out" | head -n3)"
      fi
    fi
    deb=$(ls -t "$cache_dir/download/${pkg}"_*.deb 2>/dev/null | head -n1 || true)
    [ -n "$deb" ] || skip "cannot download $pkg: apt-get download left no .deb in $cache_dir/download"
  else
    pkg=$(dpkg-deb -f "$deb" Package) || die "PMU_VM_KERNEL_DEB=$deb is not a .deb"
  fi
  note "extracting vmlinuz and $all_modules from $(basename "$deb")"
  # shellcheck disable=SC2086
  extract_kernel "$deb" "$cache_dir/$pkg" $all_modules ||
    die "cannot extract the kernel and its modules from $deb"
  rm -f "$cache_dir/download/"*.deb  # the extracted files are all we keep
  kernel_dir="$cache_dir/$pkg"
else
  # apt knows no linux-image-amd64 (no package lists): use what an earlier run cached.
  kernel_dir=$(ls -td "$cache_dir"/linux-image-*/ 2>/dev/null | head -n1 || true)
  kernel_dir=${kernel_dir%/}
  [ -n "$kernel_dir" ] && [ -f "$kernel_dir/load-order" ] ||
    skip "cannot download linux-image-amd64's kernel package: apt-cache knows no linux-image-amd64 (run apt-get update, or set PMU_VM_KERNEL_DEB=/path/to/linux-image-*.deb)"
fi
# shellcheck disable=SC2086
has_modules "$kernel_dir" $suite_modules ||
  skip "the cached kernel $(basename "$kernel_dir") lacks modules of the $suite suite ($suite_modules) and no kernel package can be downloaded"
# The suite's modules and everything they depend on, in the cached load order (dependencies first).
suite_load_order() {
  local want=" " queue m d
  read -r -a queue <<<"$suite_modules"
  while [ ${#queue[@]} -gt 0 ]; do
    m=${queue[0]//_/-}; queue=("${queue[@]:1}")
    case "$want" in *" $m "*) continue ;; esac
    want+="$m "
    for d in $(sed -n "s/^$m: //p" "$kernel_dir/deps"); do queue+=("$d"); done
  done
  while read -r m; do case "$want" in *" $m "*) echo "$m" ;; esac; done <"$kernel_dir/load-order"
}
suite_load_order >"$work/load-order"
note "kernel: $(basename "$kernel_dir"), modules: $(tr '\n' ' ' <"$work/load-order")"

# ---- the initramfs ---------------------------------------------------------------------
root="$work/root"
mkdir -p "$root"/{bin,sbin,usr/bin,usr/sbin,proc,sys,dev,tmp,run,etc/pmu-dds,opt/pmu/bin,lib/modules,root}
cp "$busybox_bin" "$root/bin/busybox"
for applet in $("$busybox_bin" --list); do
  [ -e "$root/bin/$applet" ] || ln -s busybox "$root/bin/$applet"
done

declare -A copied=()
copy_with_libs() {  # BINARY DEST-IN-ROOT
  local bin=$1 dest=$2 lib
  mkdir -p "$root/$(dirname "$dest")"
  if command -v objcopy >/dev/null && objcopy --strip-debug "$bin" "$root/$dest" 2>/dev/null; then :; else cp "$bin" "$root/$dest"; fi
  chmod 755 "$root/$dest"
  # ldd lines: "libx.so.1 => /path/libx.so.1 (0x...)" and "/lib64/ld-linux-x86-64.so.2 (0x...)"
  for lib in $(ldd "$bin" 2>/dev/null | awk '$2 == "=>" && $3 ~ /^\// {print $3} $1 ~ /^\// {print $1}'); do
    [ -n "${copied[$lib]:-}" ] && continue
    copied[$lib]=1
    mkdir -p "$root/$(dirname "$lib")"
    cp -L "$lib" "$root/$lib"
  done
}
copy_with_libs "$svc_bin" opt/pmu/bin/pmu-service
copy_with_libs "$ctl_bin" opt/pmu/bin/pmuctl
if [ "$suite" = system ]; then
  copy_with_libs "$sim_bin" opt/pmu/bin/pmu-sim
elif [ "$suite" = standby ]; then
  copy_with_libs "$sim_bin" opt/pmu/bin/pmu-sim
  copy_with_libs "$ground_bin" opt/pmu/bin/lab_ground
  copy_with_libs "$consumer_bin" opt/pmu/bin/standby_consumer
  eu_stack=$(command -v eu-stack || true)
  [ -z "$eu_stack" ] || copy_with_libs "$eu_stack" usr/bin/eu-stack
else
  copy_with_libs "$ground_bin" opt/pmu/bin/lab_ground
  copy_with_libs "$tc_bin" usr/sbin/tc   # busybox's tc knows no netem
  rm -f "$root/bin/tc"
  mkdir -p "$root/$tc_lib" && cp "$tc_lib"/*.dist "$root/$tc_lib/"
  copy_with_libs "$ds_bin" usr/bin/fast-discovery-server
  [ -z "$tcpdump_bin" ] || copy_with_libs "$tcpdump_bin" usr/sbin/tcpdump
  # The security scenario's PKI, made fresh for every run (valid two days, every lab domain).
  "$source_dir/deploy/security/make_pki.sh" "$root/etc/pmu-dds/pki" --domain 0-232 --days 2 >"$work/pki.log" 2>&1 ||
    die "make_pki.sh failed: $(tail -n3 "$work/pki.log")"
  rm -rf "$root/etc/pmu-dds/pki/ca"   # the CA keys stay out of the image
fi
for t in "${can_utils[@]}"; do copy_with_libs "$t" "usr/bin/$(basename "$t")"; done
copy_with_libs "$ip_bin" usr/sbin/ip   # the real ip: busybox's cannot `type vcan`
rm -f "$root/bin/ip"
cp "$qos_file" "$root/etc/pmu-dds/qos.xml"
cp "$source_dir/deploy/discovery-server.xml" "$root/etc/pmu-dds/discovery-server.xml"
while read -r m; do cp "$kernel_dir/modules/$m.ko" "$root/lib/modules/"; done <"$work/load-order"
cp "$work/load-order" "$root/lib/modules/load-order"
cp "$suite_script" "$root/$(basename "$suite_script")"
chmod 755 "$root/$(basename "$suite_script")"
cp "$script_dir/scenario_lib.sh" "$root/scenario_lib.sh"   # sourced by either suite
cp "$source_dir/tests/data/config_every_setting.yaml" "$root/config_every_setting.yaml"   # scenario config_file
echo "root:x:0:0:root:/root:/bin/sh" >"$root/etc/passwd"
echo "root:x:0:" >"$root/etc/group"
echo "127.0.0.1 localhost" >"$root/etc/hosts"
echo "pmu-vm" >"$root/etc/hostname"

cat >"$root/init" <<'EOF'
#!/bin/sh
# PID 1 of the test VM: mount, load the modules, then either create vcan0 and run the system
# scenarios, or run the network lab (/lab.sh) or the hot-standby suite (/standby.sh); power off.
# Debian's busybox runs its own applets before PATH: iproute2's ip is called by path.
export PATH=/opt/pmu/bin:/usr/sbin:/usr/bin:/sbin:/bin HOME=/root
mount -t proc proc /proc
mount -t sysfs sysfs /sys
mount -t devtmpfs devtmpfs /dev 2>/dev/null || mount -t tmpfs tmpfs /dev
exec </dev/console >/dev/console 2>&1
mkdir -p /dev/shm /dev/pts
mount -t tmpfs -o mode=1777 tmpfs /dev/shm   # Fast DDS shared-memory transport
mount -t tmpfs -o mode=1777 tmpfs /tmp
mount -t tmpfs tmpfs /run
hostname pmu-vm
echo "VM: kernel $(uname -r), $(nproc) cpu(s), $(awk '/MemTotal/ {print $2/1024 " MiB"}' /proc/meminfo)"
ok=1
while read -r m; do
  if ! insmod "/lib/modules/$m.ko"; then echo "VM: insmod $m.ko failed"; ok=0; fi
done </lib/modules/load-order
/usr/sbin/ip link set lo up
if [ -f /standby.sh ]; then
  # The hot-standby suite builds its bus, gateway and hosts itself (standby.sh standby_up).
  if [ $ok = 1 ]; then
    echo "VM: standby modules loaded: $(tr '\n' ' ' </lib/modules/load-order), $(/usr/sbin/ip -V)"
    sh /standby.sh all
  else
    echo "RESULT setup FAIL could not load the standby suite's modules (vcan, vxcan, can-gw, veth, bridge)"
  fi
elif [ -f /lab.sh ]; then
  # The network lab builds its namespaces, bridge and ground link itself (lab.sh lab_up).
  if [ $ok = 1 ]; then
    echo "VM: lab modules loaded: $(tr '\n' ' ' </lib/modules/load-order), $(/usr/sbin/ip -V)"
    sh /lab.sh all
  else
    echo "RESULT setup FAIL could not load the lab's modules (veth, bridge, sch_netem)"
  fi
else
/usr/sbin/ip link add vcan0 type vcan && /usr/sbin/ip link set vcan0 up || ok=0
if [ $ok = 1 ]; then
  echo "VM: CAN ready: $(/usr/sbin/ip -br link show vcan0), $(/usr/sbin/ip -V)"
  sh /scenarios.sh all
else
  echo "VM: CAN setup failed"
  echo "RESULT setup FAIL could not load the CAN modules or create vcan0"
fi
fi
echo "VM: done, powering off"
sync
poweroff -f
EOF
chmod 755 "$root/init"
mknod -m 600 "$root/dev/console" c 5 1 2>/dev/null || true

initrd="$work/initrd.gz"
(cd "$root" && find . | cpio --quiet -o -H newc -R 0:0 | gzip -1 >"$initrd")
note "initramfs $(du -h "$initrd" | cut -f1) (binaries from $build_dir)"

# ---- boot ------------------------------------------------------------------------------
mkdir -p "$(dirname "$log_file")"
: >"$log_file"
append="console=ttyS0 quiet panic=-1 pmu.scenarios=$(IFS=,; echo "${scenarios[*]}")"
[ -n "$service_log" ] && append+=" pmu.service_log=$service_log"
[ "$capture" = 1 ] && append+=" pmu.capture=1"
note "booting qemu (TCG, timeout ${vm_timeout}s), console log: $log_file"
boot_start=$(date +%s.%N)
set +e
timeout -k 10 "$vm_timeout" qemu-system-x86_64 -accel tcg -m 1024 -smp 2 -nographic -no-reboot \
  -kernel "$kernel_dir/vmlinuz" -initrd "$initrd" -append "$append" </dev/null 2>&1 |
  tr -d '\r' | tee "$log_file" | { if [ "$verbose" = 1 ]; then cat; else grep --line-buffered -E '^(RESULT|VM:|\[|SCENARIO)'; fi; }
qemu_status=${PIPESTATUS[0]}
set -e
boot_end=$(date +%s.%N)
qemu_outcome "$qemu_status" "$vm_timeout" "$log_file"

# ---- verdict ---------------------------------------------------------------------------
echo
echo "== $suite_title, $(basename "$kernel_dir")) =="
failed=0
print_verdict "$log_file" "$skip_allowed" "${scenarios[@]}" || failed=1
if grep -q '^RESULT setup FAIL' "$log_file"; then failed=1; grep '^RESULT setup' "$log_file"; fi
wall_end=$(date +%s.%N)
awk -v a="$wall_start" -v b="$boot_start" -v c="$boot_end" -v d="$wall_end" \
  'BEGIN { printf "wall time: %.1f s total (preparing %.1f s, VM %.1f s)\n", d - a, b - a, c - b }'
if [ $failed = 0 ]; then echo "$suite_label: PASS"; else echo "$suite_label: FAIL (console log: $log_file)"; fi
exit $failed
