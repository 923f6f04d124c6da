#!/bin/bash
# install.sh: installs pmu-dds from a CMake build tree onto this machine (or into DESTDIR).
#
#   deploy/install.sh [--build-dir DIR] [--prefix PREFIX] [--destdir DIR] [--dry-run]
#
#   --build-dir DIR  CMake build tree holding service/pmu-service, tools/pmuctl and
#                    tools/pmu-sim (default: build/release under the repository root)
#   --prefix PREFIX  where binaries, the unit and the docs go (default /usr): PREFIX/bin,
#                    PREFIX/lib/systemd/system, PREFIX/share/{doc/,}pmu-dds. Configuration
#                    always goes to /etc (the service looks for /etc/pmu-dds: PMU_SYSCONFDIR,
#                    the CMake default).
#   --destdir DIR    stage everything under DIR (packaging, tests); same as DESTDIR=DIR.
#                    With a DESTDIR, systemctl is not called.
#   --dry-run        print what would be done, change nothing
#
# What goes where (DESTDIR prefixed to every path):
#   PREFIX/bin/{pmu-service,pmuctl,pmu-sim,pmu-mavlink}
#                                                    binaries (pmu-service is required)
#   /etc/pmu-dds/pmu-mavlink.yaml                    pmu-mavlink's config, only if absent, with
#   PREFIX/lib/systemd/system/pmu-mavlink.service      its unit and .example: with pmu-mavlink
#   /etc/pmu-dds/qos.xml                             QoS profiles; a different existing
#                                                    file is kept as qos.xml.old
#   /etc/pmu-dds/pmu-service.yaml                    example config, only if absent; the
#   /etc/pmu-dds/pmu-service.yaml.example              example itself is always refreshed
#   PREFIX/lib/systemd/system/pmu-service.service    the unit (ExecStart= follows PREFIX)
#   PREFIX/lib/systemd/system/pmu-discovery-server.service
#                                                    the Fast DDS Discovery Server unit
#                                                    (runs Debian's fast-discovery-server)
#   PREFIX/lib/systemd/user/pmuctl-agent@.service    a user's pmuctl agent (ExecStart= follows
#                                                    PREFIX), with pmuctl
#   /etc/pmu-dds/discovery-server.env                its id and address, only if absent; the
#   /etc/pmu-dds/discovery-server.env.example          example itself is always refreshed
#   /etc/pmu-dds/discovery-server.xml                its announcement period and lease, only
#   /etc/pmu-dds/discovery-server.xml.example          if absent; the example always refreshed
#   /etc/systemd/network/80-can0.network             CAN link setup, only if absent
#   PREFIX/share/doc/pmu-dds/README.md               deploy/README.md
#   PREFIX/share/doc/pmu-dds/security.md             deploy/security/README.md
#   PREFIX/share/pmu-dds/make_pki.sh                 the DDS-Security PKI maker (run it on
#                                                    the machine that keeps the CA keys)
# then `systemctl daemon-reload` when systemd is running (skipped, with a message,
# otherwise). The service is not enabled or started: see the message at the end.
#
# Idempotent: a file whose content is already in place is left alone ("unchanged"), so a
# second run changes nothing. Exit status: 0 on success, 1 on an error, 2 on bad usage.

set -euo pipefail

script_dir=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
repo_root=$(cd "$script_dir/.." && pwd)

build_dir="$repo_root/build/release"
prefix=/usr
destdir="${DESTDIR:-}"
dry_run=0

usage() { sed -n '2,/^$/p' "${BASH_SOURCE[0]}" | sed 's/^# \{0,1\}//'; }
die() { echo "install.sh: $*" >&2; exit 1; }

while [ $# -gt 0 ]; do
  case "$1" in
    --build-dir) [ $# -ge 2 ] || { usage >&2; exit 2; }; build_dir=$2; shift 2 ;;
    --build-dir=*) build_dir=${1#*=}; shift ;;
    --prefix) [ $# -ge 2 ] || { usage >&2; exit 2; }; prefix=$2; shift 2 ;;
    --prefix=*) prefix=${1#*=}; shift ;;
    --destdir) [ $# -ge 2 ] || { usage >&2; exit 2; }; destdir=$2; shift 2 ;;
    --destdir=*) destdir=${1#*=}; shift ;;
    --dry-run|-n) dry_run=1; shift ;;
    -h|--help) usage; exit 0 ;;
    *) echo "install.sh: unknown argument '$1'" >&2; usage >&2; exit 2 ;;
  esac
done

case "$prefix" in /*) ;; *) die "--prefix must be an absolute path, not '$prefix'" ;; esac
prefix=${prefix%/}
[ -n "$prefix" ] || prefix=/
destdir=${destdir%/}
if [ -n "$destdir" ]; then
  case "$destdir" in /*) ;; *) destdir="$PWD/$destdir" ;; esac
fi

# ---- what to install -------------------------------------------------------------------
find_binary() {  # NAME SUBDIR: the CMake build-tree location, else DIR/bin (an install tree)
  local name=$1 sub=$2
  for f in "$build_dir/$sub/$name" "$build_dir/bin/$name"; do
    if [ -f "$f" ] && [ -x "$f" ]; then echo "$f"; return 0; fi
  done
  return 1
}

[ -d "$build_dir" ] || die "build directory '$build_dir' does not exist (build first, or pass --build-dir DIR)"
service_bin=$(find_binary pmu-service service) ||
  die "no pmu-service in '$build_dir' (looked in service/ and bin/); pass --build-dir DIR"
pmuctl_bin=$(find_binary pmuctl tools) || pmuctl_bin=
sim_bin=$(find_binary pmu-sim tools) || sim_bin=
mavlink_bin=$(find_binary pmu-mavlink tools/pmu-mavlink) || mavlink_bin=

for f in qos.xml pmu-service.yaml systemd/pmu-service.service systemd/80-can0.network README.md \
         security/make_pki.sh security/README.md systemd/pmu-discovery-server.service discovery-server.env discovery-server.xml \
         systemd/pmuctl-agent@.service systemd/pmu-mavlink.service pmu-mavlink.yaml; do
  [ -f "$script_dir/$f" ] || die "missing deploy/$f in $script_dir"
done

if [ "$dry_run" -eq 0 ] && [ -z "$destdir" ] && [ "$(id -u)" -ne 0 ]; then
  die "installing into / needs root (or use --destdir DIR / DESTDIR=DIR, or --dry-run)"
fi

# ---- helpers -------------------------------------------------------------------------------
changed=0       # something was (or, with --dry-run, would be) installed
last_changed=0  # the last put* call changed its file
say() { echo "$*"; }
run() {  # prints the command; runs it unless --dry-run
  if [ "$dry_run" -eq 1 ]; then say "would run: $*"; else "$@"; fi
}

# put MODE SRC DEST: install SRC as DEST unless DEST already has that content.
put() {  # optional 4th argument: how to name SRC in messages
  local mode=$1 src=$2 dest=$3 label=${4:-$2}
  last_changed=0
  if [ -f "$dest" ] && cmp -s "$src" "$dest"; then
    say "unchanged  $dest"
    return 0
  fi
  if [ "$dry_run" -eq 1 ]; then
    say "would install  $label -> $dest (mode $mode)"
  else
    install -D -m "$mode" "$src" "$dest"
    say "installed  $dest"
  fi
  changed=1
  last_changed=1
}

# put_keep MODE SRC DEST: like put, but an existing DEST is never replaced.
put_keep() {
  local mode=$1 src=$2 dest=$3
  last_changed=0
  if [ -e "$dest" ]; then
    if cmp -s "$src" "$dest"; then say "unchanged  $dest"; else say "kept       $dest (exists; not overwritten)"; fi
    return 0
  fi
  put "$mode" "$src" "$dest"
}

# put_backup MODE SRC DEST: like put, but a different existing DEST is saved as DEST.old.
put_backup() {
  local mode=$1 src=$2 dest=$3
  if [ -f "$dest" ] && ! cmp -s "$src" "$dest"; then
    if [ "$dry_run" -eq 1 ]; then
      say "would save  $dest -> $dest.old (it differs from the shipped file)"
    else
      cp -p "$dest" "$dest.old"
      say "saved      $dest.old (the previous $dest differed from the shipped file)"
    fi
  fi
  put "$mode" "$src" "$dest"
}

tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

root="$destdir"
bindir="$root$prefix/bin"
[ "$prefix" = / ] && bindir="$root/bin"
unitdir="$root${prefix%/}/lib/systemd/system"
userunitdir="$root${prefix%/}/lib/systemd/user"
docdir="$root${prefix%/}/share/doc/pmu-dds"
datadir="$root${prefix%/}/share/pmu-dds"
confdir="$root/etc/pmu-dds"
networkdir="$root/etc/systemd/network"

say "pmu-dds install: build dir $build_dir, prefix $prefix${destdir:+, DESTDIR $destdir}$([ "$dry_run" -eq 1 ] && echo ', dry run')"

# ---- binaries ------------------------------------------------------------------------------
put 0755 "$service_bin" "$bindir/pmu-service"
if [ -n "$pmuctl_bin" ]; then put 0755 "$pmuctl_bin" "$bindir/pmuctl"; else say "skipped    pmuctl (not built in $build_dir)"; fi
if [ -n "$sim_bin" ]; then put 0755 "$sim_bin" "$bindir/pmu-sim"; else say "skipped    pmu-sim (not built in $build_dir)"; fi
if [ -n "$mavlink_bin" ]; then put 0755 "$mavlink_bin" "$bindir/pmu-mavlink"; else say "skipped    pmu-mavlink (not built in $build_dir)"; fi

# ---- configuration -------------------------------------------------------------------------
put_backup 0644 "$script_dir/qos.xml" "$confdir/qos.xml"
put_keep 0644 "$script_dir/pmu-service.yaml" "$confdir/pmu-service.yaml"
put 0644 "$script_dir/pmu-service.yaml" "$confdir/pmu-service.yaml.example"

# ---- systemd -------------------------------------------------------------------------------
# The units name /usr/bin/pmu-service or /usr/bin/pmuctl and /usr/share/doc/pmu-dds; follow
# --prefix. (/usr/bin/fast-discovery-server is Debian's, and stays.)
bin_path="${prefix%/}/bin"
for_prefix() {  # UNIT: deploy/systemd/UNIT with this prefix's paths, into $tmp
  sed -e "s#/usr/bin/pmu#$bin_path/pmu#g" -e "s#/usr/share/doc/pmu-dds#${prefix%/}/share/doc/pmu-dds#g" \
    "$script_dir/systemd/$1" > "$tmp/$1"
}
for_prefix pmu-service.service
put 0644 "$tmp/pmu-service.service" "$unitdir/pmu-service.service" "$script_dir/systemd/pmu-service.service (ExecStart= under $bin_path)"
unit_changed=$last_changed
for_prefix pmu-discovery-server.service
put 0644 "$tmp/pmu-discovery-server.service" "$unitdir/pmu-discovery-server.service" "$script_dir/systemd/pmu-discovery-server.service"
if [ "$last_changed" -eq 1 ]; then unit_changed=1; fi
# The user unit runs pmuctl: installed with it. Users enable it themselves (systemctl --user).
if [ -n "$pmuctl_bin" ]; then
  for_prefix pmuctl-agent@.service
  put 0644 "$tmp/pmuctl-agent@.service" "$userunitdir/pmuctl-agent@.service" "$script_dir/systemd/pmuctl-agent@.service (ExecStart= under $bin_path)"
fi
# pmu-mavlink's unit and config: installed with it; the site enables it (systemctl enable).
if [ -n "$mavlink_bin" ]; then
  for_prefix pmu-mavlink.service
  put 0644 "$tmp/pmu-mavlink.service" "$unitdir/pmu-mavlink.service" "$script_dir/systemd/pmu-mavlink.service (ExecStart= under $bin_path)"
  if [ "$last_changed" -eq 1 ]; then unit_changed=1; fi
  put_keep 0644 "$script_dir/pmu-mavlink.yaml" "$confdir/pmu-mavlink.yaml"
  put 0644 "$script_dir/pmu-mavlink.yaml" "$confdir/pmu-mavlink.yaml.example"
fi
put_keep 0644 "$script_dir/discovery-server.env" "$confdir/discovery-server.env"
put 0644 "$script_dir/discovery-server.env" "$confdir/discovery-server.env.example"
put_keep 0644 "$script_dir/discovery-server.xml" "$confdir/discovery-server.xml"
put 0644 "$script_dir/discovery-server.xml" "$confdir/discovery-server.xml.example"
put_keep 0644 "$script_dir/systemd/80-can0.network" "$networkdir/80-can0.network"
put 0644 "$script_dir/README.md" "$docdir/README.md"

# ---- security tooling ----------------------------------------------------------------------
# Only the script and its guide: no key or certificate is ever installed by this script.
put 0755 "$script_dir/security/make_pki.sh" "$datadir/make_pki.sh"
put 0644 "$script_dir/security/README.md" "$docdir/security.md"

# ---- reload --------------------------------------------------------------------------------
if [ -n "$destdir" ]; then
  say "skipped    systemctl daemon-reload (installing into DESTDIR $destdir)"
elif [ ! -d /run/systemd/system ]; then
  say "skipped    systemctl daemon-reload (systemd is not running on this machine)"
elif [ "$unit_changed" -eq 0 ]; then
  say "skipped    systemctl daemon-reload (the units are unchanged)"
else
  run systemctl daemon-reload
fi

if [ "$dry_run" -eq 1 ]; then
  say "dry run: nothing was changed"
elif [ "$changed" -eq 0 ]; then
  say "nothing to do: everything was already installed"
fi

if [ -z "$destdir" ]; then
  cat <<EOF

Next steps (see $prefix/share/doc/pmu-dds/README.md):
  edit /etc/pmu-dds/pmu-service.yaml, then: pmu-service --config /etc/pmu-dds/pmu-service.yaml --check-config
  CAN link via systemd-networkd:  systemctl enable --now systemd-networkd && networkctl reload
  start the service:              systemctl enable --now pmu-service
  check it:                       systemctl status pmu-service; journalctl -u pmu-service; pmuctl list
  Discovery Server (only for discovery mode server; needs Debian's fastdds-tools):
                                  edit /etc/pmu-dds/discovery-server.env, then
                                  systemctl enable --now pmu-discovery-server
EOF
fi
