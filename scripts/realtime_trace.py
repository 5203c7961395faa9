#!/usr/bin/env python3
"""Reads a scheduler trace of scripts/trace_realtime.sh: where the base loop's speed frames and the
reader's wake-ups wait.

usage: realtime_trace.py TRACE THREADS
  TRACE    tracefs text with sched_waking, sched_wakeup, sched_switch events
  THREADS  the traced process's threads, one "tid name ..." per line

The loop is the thread named srd_base_loop (else the one most often woken from a timer interrupt:
the floor's main thread), the reader srd_reader (else the one most often woken by a kworker).
"""
import collections
import re
import statistics
import sys

EVENT = re.compile(r'^\s*(.+?)-(\d+)\s+\[(\d+)\]\s+(\S+)\s+([\d.]+):\s+(\w+):\s+(.*)$')
FIELD = re.compile(r'(\w+)=(\S+)')


def read_events(path):
    events = []
    with open(path) as trace:
        for line in trace:
            match = EVENT.match(line)
            if match:
                comm, pid, cpu, flags, stamp, name, rest = match.groups()
                events.append((float(stamp), int(cpu), int(pid), comm, flags, name,
                               dict(FIELD.findall(rest))))
    return events


def read_threads(path):
    threads = {}
    with open(path) as listing:
        for line in listing:
            parts = line.split()
            if len(parts) >= 2 and parts[0].isdigit():
                threads[int(parts[0])] = parts[1]
    return threads


def pick(threads, events, name, woken_by):
    """The thread called `name`, else the one woken most often as `woken_by` says."""
    for tid, comm in threads.items():
        if comm == name:
            return tid
    counts = collections.Counter(
        int(f['pid']) for _, _, _, comm, flags, event, f in events
        if event == 'sched_waking' and int(f['pid']) in threads and woken_by(comm, flags))
    return counts.most_common(1)[0][0]


def quantiles(values):
    ordered = sorted(values)
    count = len(ordered)
    return ordered[count // 2] * 1e3, ordered[int(0.99 * count)] * 1e3, ordered[-1] * 1e3


def loop_path(events, loop):
    """Per tick: timer interrupt, loop runs, its write() wakes a kworker, that kworker runs, the
    kworker wakes the benchmark (driver_bench) that reads the frame."""
    ticks, tick = [], None
    for stamp, _, pid, comm, flags, name, f in events:
        if name == 'sched_waking' and int(f['pid']) == loop and 'h' in flags:
            tick = {'timer': stamp}
            ticks.append(tick)
        elif tick is None:
            continue
        elif name == 'sched_switch' and int(f['next_pid']) == loop and 'run' not in tick:
            tick['run'] = stamp
        elif (name == 'sched_waking' and pid == loop and f['comm'].startswith('kworker')
              and 'write' not in tick):
            tick['write'], tick['kworker'] = stamp, int(f['pid'])
        elif (name == 'sched_switch' and 'write' in tick and 'ran' not in tick
              and int(f['next_pid']) == tick['kworker']):
            tick['ran'] = stamp
        elif (name == 'sched_waking' and 'ran' in tick and 'bench' not in tick
              and pid == tick['kworker'] and f['comm'] == 'driver_bench'):
            tick['bench'] = stamp
    complete = [t for t in ticks if all(k in t for k in ('run', 'write', 'ran', 'bench'))]
    print('%d ticks traced, %d followed to the benchmark' % (len(ticks), len(complete)))
    for label, start, end in (('timer -> loop runs', 'timer', 'run'),
                              ('loop runs -> write()', 'run', 'write'),
                              ('write() -> pty kworker runs', 'write', 'ran'),
                              ('kworker -> benchmark woken', 'ran', 'bench')):
        print('  %-28s p50 %.3f  p99 %.3f  max %.3f ms' %
              ((label,) + quantiles([t[end] - t[start] for t in complete])))
    for label, key in (('at the timer', 'timer'), ('at the benchmark', 'bench')):
        periods = [b[key] - a[key] for a, b in zip(complete, complete[1:])
                   if b['timer'] - a['timer'] < 0.03]
        print('  period std %-17s %.3f ms, longest %.3f ms' %
              (label, statistics.pstdev(periods) * 1e3, max(periods) * 1e3))


def own_waits(events, threads, tid, label):
    """Wake (or preemption) -> running of `tid`, and those waits that began while another thread
    of the same process held every other core: at an equal or higher priority (which FIFO does not
    preempt: the waits a priority above the rest removes) or at a lower one (the kernel, which is
    not preemptible under PREEMPT_NONE, finishing that thread's system call first)."""
    running, pending, delays = {}, None, []
    behind = {'equal': [], 'lower': []}
    for stamp, cpu, pid, _, _, name, f in events:
        runs = (pid == tid and name != 'sched_wakeup') or (
            name == 'sched_switch' and int(f['next_pid']) == tid)
        if pending is not None and runs:
            delays.append(stamp - pending[0])
            if pending[1]:
                behind[pending[1]].append(stamp - pending[0])
            pending = None
        if name == 'sched_switch':
            running[cpu] = (int(f['next_pid']), int(f['next_prio']))
            if int(f['prev_pid']) == tid:
                own_prio = int(f['prev_prio'])
                if f['prev_state'].startswith('R'):
                    pending = (stamp, holder(running, threads, tid, own_prio))
        elif name == 'sched_wakeup' and int(f['pid']) == tid and pending is None:
            pending = (stamp, holder(running, threads, tid, int(f['prio'])))
    print('%s (%d): %d wakes, wake -> running p50 %.3f p99 %.3f max %.3f ms' %
          ((label, tid, len(delays)) + quantiles(delays)))
    for kind, waits in behind.items():
        long_waits = [d for d in waits if d > 50e-6]
        print('  behind a thread of the process at %-5s priority: %d waits > 0.05 ms, %.2f ms in all,'
              ' longest %.3f ms' % (kind, len(long_waits), sum(long_waits) * 1e3,
                                    max(waits + [0]) * 1e3))


def holder(running, threads, tid, prio):
    """'equal' when another thread of the process at `prio` or above holds a core, 'lower' when
    only lower ones of it do, None when none does (kernel priorities: lower number, higher)."""
    others = [p for pid, p in running.values() if pid in threads and pid != tid]
    if any(p <= prio for p in others):
        return 'equal'
    return 'lower' if others else None


def main():
    events = read_events(sys.argv[1])
    threads = read_threads(sys.argv[2])
    loop = pick(threads, events, 'srd_base_loop', lambda comm, flags: 'h' in flags)
    reader = pick(threads, events, 'srd_reader', lambda comm, flags: comm.startswith('kworker'))
    print('over %.1f s of trace' % (events[-1][0] - events[0][0]))
    loop_path(events, loop)
    own_waits(events, threads, loop, 'loop')
    own_waits(events, threads, reader, 'reader')


if __name__ == '__main__':
    main()
