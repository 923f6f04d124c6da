#!/usr/bin/env python3
"""Where a thread was switched out: reads `perf script -F tid,ip,sym` of a
`perf record -e sched:sched_switch --call-graph dwarf` and prints, per thread with many
switches, the first user-space frames of each distinct call site and its share.
Used by bench/profile.sh."""
import collections
import sys

# Kernel and libc frames between the switch and the code that asked for it.
KERNEL = ("__schedule", "schedule", "futex", "__x64", "do_syscall", "entry_SYSCALL", "do_futex", "__futex",
          "exit_to", "syscall", "do_epoll", "ep_", "__do_sys", "unix_", "sock_", "__sys", "hrtimer", "do_nanosleep",
          "restart", "irqentry", "asm_", "sysvec", "__irq", "irq", "pvm", "__raw", "_raw", "preempt",
          "common_nsleep", "schedule_hrtimeout", "__cond_resched")


def main(path, depth=4, top=8):
    sites = collections.Counter()
    per_thread = collections.Counter()
    for block in open(path, errors="replace").read().split("\n\n"):
        lines = [l.strip() for l in block.strip().split("\n") if l.strip()]
        if not lines:
            continue
        tid = lines[0].split()[0]
        frames = [" ".join(l.split()[1:]) for l in lines[1:]]
        user = [f for f in frames if not f.startswith(KERNEL)]
        sites[(tid, " <- ".join(f[:60] for f in user[:depth]))] += 1
        per_thread[tid] += 1
    for tid, total in per_thread.most_common():
        if total < 0.05 * sum(per_thread.values()):
            continue
        print(f"  thread {tid}: {total} switches")
        shown = [(site, n) for (t, site), n in sites.most_common() if t == tid][:top]
        for site, n in shown:
            print(f"    {100 * n / total:5.1f} %  {site}")


if __name__ == "__main__":
    main(sys.argv[1])
