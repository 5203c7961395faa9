#!/usr/bin/env python3
"""The report of scripts/profile_node.sh: per thread of driver_node, its role, CPU and top items.

usage: scripts/profile_report.py perf|callgrind OUT_DIR SECONDS [TOP] [PROGRAM]

OUT_DIR holds what profile_node.sh left there: cpu_ns_start / cpu_ns_end (per-thread CPU time),
switches_start / switches_end (per-thread context switches), perf.data and syscalls.csv (perf
stat --per-thread) or callgrind.out.*, and the rostopic hz logs (hz_*.log). Prints Markdown.
"""
import glob
import re
import subprocess
import sys

# The function each thread of the node runs (the first of its inclusive symbols, highest share
# first, that names one), its role, and the event its CPU is divided by.
ROLES = [
    ("SerialLink::readerLoop", "port reader (frames in, readings published)", "telemetry frame"),
    # (callgrind counts from inside the loop: readerLoop itself may not be seen)
    ("SerialLink::readOnce", "port reader (frames in, readings published)", "telemetry frame"),
    ("BaseController::run", "base loop (speed frame, odom, /tf, wheel_states)", "loop tick"),
    ("ServoBus::workerLoop", "servo bus worker", None),
    ("WireCapture::publishLoop", "wire capture", None),
    ("QueueSpinner", "callbacks (cmd_vel, timers: diagnostics, trajectories, action status)",
     "cmd_vel"),
    ("PollManager::threadFunc", "roscpp poll (writes messages to subscribers)", "message sent"),
    ("XMLRPCManager::serverThreadFunc", "roscpp xmlrpc", None),
    ("ROSOutAppender::logThread", "roscpp rosout", None),
    ("internalCallbackQueueThreadFunc", "roscpp internal queue", None),
    ("TimerManager", "roscpp timers", None),
    # floor_node (--floor): its reader, its loop (on the main thread) and its spinner.
    ("publishTelemetry", "reader (frames in, readings published)", "telemetry frame"),
    ("AsyncSpinnerImpl::threadFunc", "callbacks (cmd_vel, diagnostics timer)", "cmd_vel"),
    ("writeSpeedFrame", "loop on the main thread (speed frame, odom, /tf, wheel_states)",
     "loop tick"),
    ("main", "main", None),
]
# callgrind: the function called once per event, in the node and in floor_node, whose calls in a
# thread count that thread's events.
EVENT_CALLS = {
    "telemetry frame": ("BodyDevice::onTelemetry", "publishTelemetry("),
    "loop tick": ("BaseController::tick(", "writeSpeedFrame"),
    "cmd_vel": ("BaseDevice::commandTwist", "subscribeCmdVel"),
}
TELEMETRY_HZ = 100.0
LOOP_HZ = 50.0
DIAGNOSTICS_HZ = 1.0
# Messages per event to this profile's subscribers: joint_states + imu/data per telemetry frame;
# odom + /tf + wheel_states per loop tick; /diagnostics per diagnostics period.
MESSAGES_PER = {"telemetry frame": 2, "loop tick": 3, "diagnostics period": 1}
DIAGNOSTICS_SYMBOL = "diagnostic_updater::Updater::force_update"
OWN_PREFIXES = ("serial_robot_driver::", "diagnostic_updater::")


def read_cpu_ns(path):
    cpu_ns = {}
    with open(path) as stream:
        for line in stream:
            tid, value = line.split()
            cpu_ns[int(tid)] = int(value)
    return cpu_ns


def thread_cpu(out, seconds):
    """CPU s/s per tid over the window, from /proc/<pid>/task/<tid>/schedstat."""
    start, end = read_cpu_ns(f"{out}/cpu_ns_start"), read_cpu_ns(f"{out}/cpu_ns_end")
    return {tid: (end[tid] - start.get(tid, 0)) / 1e9 / seconds for tid in end}


def read_switches(path):
    """Per tid: (voluntary, involuntary) context switches so far."""
    switches = {}
    with open(path) as stream:
        for line in stream:
            fields = line.split()
            if len(fields) == 3:
                switches[int(fields[0])] = (int(fields[1]), int(fields[2]))
    return switches


def syscall_counts(path):
    """Per tid, per system call, what `perf stat --per-thread -x,` counted (comm-tid,count,,event)."""
    counts = {}
    try:
        with open(path) as stream:
            lines = stream.readlines()
    except OSError:
        return counts
    prefix = "syscalls:sys_enter_"
    for line in lines:
        fields = line.strip().split(",")
        if len(fields) < 4 or not fields[3].startswith(prefix) or "-" not in fields[0]:
            continue
        tid = int(fields[0].rsplit("-", 1)[1])
        count = int(fields[1]) if fields[1].isdigit() else 0
        counts.setdefault(tid, {})[fields[3][len(prefix):]] = count
    return counts


def print_wakes_and_calls(out, seconds, roles):
    """Per thread and second: how often it blocked (so woke up again), was preempted, and each
    system call it made; the wake-ups and calls are what the kernel charges a thread beyond its
    instructions."""
    start, end = read_switches(f"{out}/switches_start"), read_switches(f"{out}/switches_end")
    calls = syscall_counts(f"{out}/syscalls.csv")
    names = sorted({name for per_thread in calls.values() for name, count in per_thread.items()
                    if count > 0})
    print("\n#### Wake-ups and system calls per thread (per second: the switches over the CPU "
          "window, the calls over perf's)\n")
    print("| thread | blocked (woke) | preempted | " + " | ".join(f"`{n}`" for n in names) + " |")
    print("|---|---|---|" + "---|" * len(names))
    totals = [0.0] * (2 + len(names))
    for tid in sorted(end, key=lambda tid: -(end[tid][0] - start.get(tid, (0, 0))[0])):
        woke = (end[tid][0] - start.get(tid, (0, 0))[0]) / seconds
        preempted = (end[tid][1] - start.get(tid, (0, 0))[1]) / seconds
        row = [woke, preempted] + [calls.get(tid, {}).get(n, 0) / seconds for n in names]
        if sum(row) < 1:
            continue
        totals = [a + b for a, b in zip(totals, row)]
        cells = " | ".join(f"{value:.0f}" for value in row)
        print(f"| {roles.get(tid, 'tid')} ({tid}) | {cells} |")
    print("| **all threads** | " + " | ".join(f"**{value:.0f}**" for value in totals) + " |")


def messages_per_second(out):
    """Messages the node sent per second to this profile's subscribers (rostopic hz)."""
    total = 0.0
    for log in glob.glob(f"{out}/hz_*.log"):
        rates = re.findall(r"average rate: ([0-9.]+)", open(log, errors="replace").read())
        if rates:
            total += float(rates[-1])
    return total


def events_per_second(event, messages):
    return {"telemetry frame": TELEMETRY_HZ, "loop tick": LOOP_HZ,
            "diagnostics period": DIAGNOSTICS_HZ, "message sent": messages}.get(event)


def print_per_event(threads, diagnostics_us):
    """threads: role -> (cpu s/s, us per event). The node's CPU per event, its own thread plus
    roscpp's poll thread for the messages the event sends."""
    by_event = {event: (role, cpu, us) for role, (cpu, us, event) in threads.items() if event}
    send_us = by_event.get("message sent", (None, 0, 0.0))[2]
    print("\n| event | its thread | that thread per event | + sending its messages | total |"
          "\n|---|---|---|---|---|")
    for event in ("telemetry frame", "loop tick", "diagnostics period"):
        role, _, own_us = by_event.get(event, ("-", 0, None))
        if event == "diagnostics period":
            role, own_us = f"(`{DIAGNOSTICS_SYMBOL}`, inclusive, any thread)", diagnostics_us
        if own_us is None:
            continue
        send = send_us * MESSAGES_PER[event]
        print(f"| {event} | {role} | {own_us:.1f} us | {send:.1f} us "
              f"({MESSAGES_PER[event]} x {send_us:.1f}) | {own_us + send:.1f} us |")


def perf_rows(out, children):
    """(tid, percent of all samples, symbol) from perf report --sort pid,sym (pid: the thread)."""
    mode = "--children" if children else "--no-children"
    text = subprocess.run(
        ["perf", "report", "-i", f"{out}/perf.data", mode, "--sort", "pid,sym", "--stdio",
         "-g", "none", "--percent-limit", "0.05"],
        capture_output=True, text=True, check=True).stdout
    rows = []
    for line in text.splitlines():
        match = re.match(r"\s*([0-9.]+)%\s+(?:([0-9.]+)%\s+)?(\d+):\S+\s+\[.\]\s+(.*)$", line)
        if match:
            rows.append((int(match.group(3)), float(match.group(1)), match.group(4).strip()))
    return rows


def role_of(symbols):
    """symbols: a thread's inclusive symbols, highest share first ("main" only when nothing more
    telling matches: floor_node runs its loop on the main thread)."""
    found = None
    for symbol in symbols:
        for pattern, role, event in ROLES:
            if pattern in symbol:
                if pattern != "main":
                    return role, event
                found = found or (role, event)
    return found or ("other", None)


def short(symbol, width=110):
    symbol = symbol.replace("serial_robot_driver::", "")
    return symbol if len(symbol) <= width else symbol[: width - 3] + "..."


def print_thread(tid, cpu, role, event, per_event_scale, self_rows, own_rows, top):
    unit = f"us per {event}" if event else "us per s"
    scale = per_event_scale
    print(f"\n#### {role} (tid {tid}): {cpu:.4f} s/s"
          + (f" = {cpu * scale:.1f} {unit}" if event else ""))
    print(f"\n| % of thread | {unit} | self (top {top}) |\n|---|---|---|")
    for share, symbol in self_rows[:top]:
        print(f"| {share:.1f} | {cpu * scale * share / 100:.2f} | `{short(symbol)}` |")
    if own_rows:
        print(f"\n| % of thread | {unit} | the project's code, inclusive (top {top}) |\n|---|---|---|")
        for share, symbol in own_rows[:top]:
            print(f"| {share:.1f} | {cpu * scale * share / 100:.2f} | `{short(symbol)}` |")


def perf_report(out, cpu, messages, top, seconds):
    self_rows, child_rows = perf_rows(out, False), perf_rows(out, True)
    threads, diagnostics_us, roles = {}, 0.0, {}
    for tid in sorted(cpu, key=lambda tid: -cpu[tid]):
        mine = [(share, symbol) for t, share, symbol in self_rows if t == tid]
        total = sum(share for share, _ in mine)
        if total <= 0 or cpu[tid] <= 0:
            continue
        inclusive = [(share, symbol) for t, share, symbol in child_rows if t == tid]
        role, event = role_of([symbol for _, symbol in inclusive])
        rate = events_per_second(event, messages)
        scale = 1e6 / rate if rate else 1e6
        relative = [(100 * share / total, symbol) for share, symbol in mine]
        own = [(100 * share / total, symbol) for share, symbol in inclusive
               if symbol.startswith(OWN_PREFIXES) and 100 * share / total < 99.5]
        diagnostics_us += sum(cpu[tid] * 1e6 * share / 100 for share, symbol in own
                              if symbol.startswith(DIAGNOSTICS_SYMBOL))
        threads[f"{role} (tid {tid})"] = (cpu[tid], cpu[tid] * scale, event if rate else None)
        roles[tid] = role
        print_thread(tid, cpu[tid], role, event if rate else None, scale, relative, own, top)
    node = sum(cpu.values()) or 1.0
    print("\n#### Per thread\n\n| thread | CPU s/s | share of the node |\n|---|---|---|")
    for name, (thread_cpu_share, _, _) in threads.items():
        print(f"| {name} | {thread_cpu_share:.4f} | {100 * thread_cpu_share / node:.0f} % |")
    print("\n#### Per event (perf's shares of each thread, times its CPU from /proc)")
    print_per_event(threads, diagnostics_us / DIAGNOSTICS_HZ)
    print_wakes_and_calls(out, seconds, roles)


def callgrind_rows(path, inclusive):
    text = subprocess.run(
        ["callgrind_annotate", f"--inclusive={'yes' if inclusive else 'no'}", "--threshold=99.9",
         path], capture_output=True, text=True, check=True).stdout
    rows, total = [], 0
    for line in text.splitlines():
        match = re.match(r"\s*([0-9,]+) \([ 0-9.]+%\)\s+(.*?)(?: \[.*\])?$", line)
        if match and "PROGRAM TOTALS" in line:
            total = int(match.group(1).replace(",", ""))
        if not match or "PROGRAM TOTALS" in line:
            continue
        # "file:function": the first single colon ends the file ("???" when unknown).
        parts = re.split(r"(?<!:):(?!:)", match.group(2), maxsplit=1)
        symbol = parts[1] if len(parts) == 2 else parts[0]
        rows.append((int(match.group(1).replace(",", "")), symbol.strip()))
    return rows, total


def callgrind_calls(path):
    """Calls per function name in a callgrind file (its "calls=" lines; names compressed)."""
    names, calls, callee = {}, {}, None
    for line in open(path, errors="replace"):
        match = re.match(r"c?fn=\((\d+)\)(?: (.*))?$", line.rstrip("\n"))
        if match:
            if match.group(2):
                names[match.group(1)] = match.group(2)
            if line.startswith("cfn="):
                callee = names.get(match.group(1))
            continue
        if line.startswith("calls=") and callee:
            calls[callee] = calls.get(callee, 0) + int(line[6:].split()[0])
    return calls


def events_in(calls, event):
    """How many `event`s a thread handled: the most calls of its EVENT_CALLS functions."""
    patterns = EVENT_CALLS.get(event, ())
    return max((n for name, n in calls.items() if any(p in name for p in patterns)), default=0)


def callgrind_report(out, cpu, messages, top, seconds):
    """Instruction counts per thread over the window (valgrind runs the threads one at a time, so
    /proc's CPU of a thread says little): each thread's share, its instructions per event (from the
    calls of EVENT_CALLS' functions; the poll thread's per message sent) and its top items."""
    del cpu  # the time scale of a callgrind run is valgrind's
    paths = sorted(glob.glob(f"{out}/callgrind.out.*.1-*")) or sorted(
        glob.glob(f"{out}/callgrind.out.*-*"))
    threads = []
    for path in paths:
        (exclusive, total), (inclusive, _) = callgrind_rows(path, False), callgrind_rows(path, True)
        inclusive.sort(key=lambda row: -row[0])
        threads.append((total, exclusive, inclusive, callgrind_calls(path)))
    everything = sum(thread[0] for thread in threads) or 1
    per_event = []
    for total, exclusive, inclusive, calls in sorted(threads, key=lambda thread: -thread[0]):
        if total < everything / 200:
            continue
        role, event = role_of([symbol for _, symbol in inclusive])
        count = messages * seconds if event == "message sent" else events_in(calls, event)
        events = {event: count} if count else {}
        per_event += [(event, role, total / n) for event, n in events.items()]
        print(f"\n#### {role}: {total:,} instructions, {100 * total / everything:.1f} % of the "
              "program's" + "".join(f"; {total / n:,.0f} per {event} ({n:,.0f})"
                                    for event, n in events.items()))
        print(f"\n| % of thread | self (top {top}) |\n|---|---|")
        for count, symbol in exclusive[:top]:
            print(f"| {100 * count / total:.1f} | `{short(symbol)}` |")
        own = [(count, symbol) for count, symbol in inclusive
               if symbol.startswith(OWN_PREFIXES) and count < 0.995 * total]
        if own:
            print(f"\n| % of thread | the project's code, inclusive (top {top}) |\n|---|---|")
            for count, symbol in own[:top]:
                print(f"| {100 * count / total:.1f} | `{short(symbol)}` |")
    print(f"\n#### Per event\n\n{everything / seconds:,.0f} instructions per second in all."
          "\n\n| event | thread | instructions per event, that thread |\n|---|---|---|")
    for event, role, count in per_event:
        print(f"| {event} | {role} | {count:,.0f} |")


def main():
    tool, out, seconds = sys.argv[1], sys.argv[2], float(sys.argv[3])
    top = int(sys.argv[4]) if len(sys.argv) > 4 else 8
    program = sys.argv[5] if len(sys.argv) > 5 else "driver_node"
    cpu = thread_cpu(out, seconds)
    messages = messages_per_second(out)
    print(f"### {program}{' ~same_job' if program == 'floor_node' else ''} profile ({tool}, "
          f"{seconds:.0f} s; 20 body servos at 100 Hz, loop 50 Hz, defaults; subscribed: "
          f"joint_states, wheel_states, imu/data, odom, /tf, /diagnostics)\n")
    print(f"CPU {sum(cpu.values()):.4f} s/s over the window (/proc, all threads"
          f"{', under valgrind' if tool == 'callgrind' else ''}); {len(cpu)} threads; messages "
          f"sent to the subscribers {messages:.0f}/s")
    if tool == "perf":
        perf_report(out, cpu, messages, top, seconds)
    else:
        callgrind_report(out, cpu, messages, top, seconds)


if __name__ == "__main__":
    main()
