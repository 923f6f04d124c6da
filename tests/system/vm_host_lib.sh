# vm_host_lib.sh: what the host-side VM test runners share, sourced by
# tests/system/run_vm_tests.sh (initramfs VM) and tests/systemd/run_systemd_vm.sh (systemd
# VM). The caller defines note(). The VM side of the same RESULT protocol is
# scenario_lib.sh.

# The linux-image-X-amd64 that linux-image-amd64 depends on: both VMs boot that kernel.
kernel_package() {
  local dep
  dep=$(apt-cache depends linux-image-amd64 2>/dev/null | sed -n 's/^ *Depends: \(linux-image-[0-9][^ ]*\)$/\1/p' | head -n1 || true)
  [ -n "$dep" ] || dep=$(apt-cache show linux-image-amd64 2>/dev/null |
    sed -n 's/^Depends: .*\(linux-image-[0-9][^ ,]*-amd64\).*/\1/p' | head -n1 || true)
  echo "$dep"
}

# Says why qemu ended when it did not end cleanly.
qemu_outcome() {  # STATUS TIMEOUT-SECONDS CONSOLE-LOG
  if [ "$1" = 124 ] || [ "$1" = 137 ]; then
    note "the VM did not finish within ${2}s (killed)"
  elif [ "$1" != 0 ]; then
    note "qemu exited with status $1; last console lines:"
    tail -n 20 "$3" >&2
  fi
}

# One table row per scenario from the last `RESULT NAME PASS|FAIL|SKIP SECS DETAIL` line
# on the console: no line is a FAIL (the VM crashed, hung or timed out), and a SKIP fails
# unless the scenario is in SKIP-ALLOWED (" a b "). Returns 1 when any scenario failed.
print_verdict() {  # CONSOLE-LOG SKIP-ALLOWED SCENARIO...
  local log=$1 skip_allowed=$2 failed=0 s line status rest secs detail
  shift 2
  printf '%-22s %-5s %8s  %s\n' scenario result time detail
  for s in "$@"; do
    line=$(grep -E "^RESULT $s (PASS|FAIL|SKIP)( |$)" "$log" | tail -n1 || true)
    if [ -z "$line" ]; then
      status=FAIL; secs="-"; detail="no RESULT line (VM crashed, hung or timed out; see $log)"
    else
      status=$(awk '{print $3}' <<<"$line")
      rest=$(cut -d' ' -f4- <<<"$line")
      secs=$(awk '{print $1}' <<<"$rest")
      detail=$(cut -s -d' ' -f2- <<<"$rest")
    fi
    case "$status" in
      PASS) ;;
      SKIP) case "$skip_allowed" in *" $s "*) ;; *) failed=1; detail="SKIP not allowed here: $detail" ;; esac ;;
      *) failed=1 ;;
    esac
    printf '%-22s %-5s %8s  %s\n' "$s" "$status" "${secs:--}" "$detail"
  done
  return $failed
}
