#!/usr/bin/env python3
"""The report of scripts/profile_node.sh: per thread of driver_node, its role, CPU and top items.

usage: scripts/profile_report.py perf|callgrind OUT_DIR SECONDS [TOP]

OUT_DIR holds what profile_node.sh left there: cpu_ns_start / cpu_ns_end (per-thread CPU time),
perf.data or callgrind.out.*, and the rostopic hz logs (hz_*.log). Prints Markdown.
"""
import glob
import re
import subprocess
import sys

# The function each thread of the node runs, first match wins (inclusive symbols), and the event
# its CPU is divided by.
ROLES = [
    ("SerialLink::readerLoop", "port reader (frames in, readings published)", "telemetry frame"),
    ("BaseController::run", "base loop (speed frame, odom, /tf, wheel_states)", "loop tick"),
    ("ServoBus::workerLoop", "servo bus worker", None),
    ("WireCapture::publishLoop", "wire capture", None),
    ("QueueSpinner", "callbacks (cmd_vel, timers: diagnostics, trajectories, action status)",
     None),
    ("PollManager::threadFunc", "roscpp poll (writes messages to subscribers)", "message sent"),
    ("XMLRPCManager::serverThreadFunc", "roscpp xmlrpc", None),
    ("ROSOutAppender::logThread", "roscpp rosout", None),
    ("internalCallbackQueueThreadFunc", "roscpp internal queue", None),
    ("TimerManager", "roscpp timers", None),
    ("main", "main", None),
]
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
    for pattern, role, event in ROLES:
        if any(pattern in symbol for symbol in symbols):
            return role, event
    return "other", None


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


def perf_report(out, cpu, messages, top):
    self_rows, child_rows = perf_rows(out, False), perf_rows(out, True)
    threads, diagnostics_us = {}, 0.0
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
        print_thread(tid, cpu[tid], role, event if rate else None, scale, relative, own, top)
    print("\n#### Per event (perf's shares of each thread, times its CPU from /proc)")
    print_per_event(threads, diagnostics_us / DIAGNOSTICS_HZ)


def callgrind_rows(path, inclusive):
    text = subprocess.run(
        ["callgrind_annotate", f"--inclusive={'yes' if inclusive else 'no'}", "--threshold=99.9",
         path], capture_output=True, text=True, check=True).stdout
    rows = []
    for line in text.splitlines():
        match = re.match(r"\s*([0-9,]+) \([ 0-9.]+%\)\s+(?:\S+:)?(.*?)(?: \[.*\])?$", line)
        if match:
            rows.append((int(match.group(1).replace(",", "")), match.group(2).strip()))
    return rows


def callgrind_report(out, cpu, messages, top):
    # --separate-threads numbers threads in creation order: the tids in ascending order.
    files = sorted(glob.glob(f"{out}/callgrind.out.*-*"), key=lambda p: int(p.rsplit("-", 1)[1]))
    tids = sorted(cpu)
    for index, path in enumerate(files):
        tid = tids[index] if index < len(tids) else -1
        exclusive, inclusive = callgrind_rows(path, False), callgrind_rows(path, True)
        total = sum(count for count, _ in exclusive)
        if total <= 0:
            continue
        role, event = role_of([symbol for _, symbol in inclusive])
        rate = events_per_second(event, messages)
        scale = 1e6 / rate if rate else 1e6
        relative = [(100 * count / total, symbol) for count, symbol in exclusive]
        own = [(100 * count / total, symbol) for count, symbol in inclusive
               if symbol.startswith(OWN_PREFIXES) and 100 * count / total < 99.5]
        print(f"\n(callgrind: {total:,} instructions in this thread; us scale from /proc, "
              "which counts valgrind's slowdown)")
        print_thread(tid, cpu.get(tid, 0.0), role, event if rate else None, scale, relative, own,
                     top)


def main():
    tool, out, seconds = sys.argv[1], sys.argv[2], float(sys.argv[3])
    top = int(sys.argv[4]) if len(sys.argv) > 4 else 8
    cpu = thread_cpu(out, seconds)
    messages = messages_per_second(out)
    print(f"### driver_node profile ({tool}, {seconds:.0f} s; 20 body servos at 100 Hz, loop "
          f"50 Hz, defaults; subscribed: joint_states, wheel_states, imu/data, odom, /tf, "
          f"/diagnostics)\n")
    print(f"node CPU {sum(cpu.values()):.4f} s/s over the window (/proc, all threads); "
          f"{len(cpu)} threads; messages sent to the subscribers {messages:.0f}/s")
    print("\n| tid | CPU s/s |\n|---|---|")
    for tid in sorted(cpu, key=lambda t: -cpu[t]):
        print(f"| {tid} | {cpu[tid]:.4f} |")
    (perf_report if tool == "perf" else callgrind_report)(out, cpu, messages, top)


if __name__ == "__main__":
    main()
