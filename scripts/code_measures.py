#!/usr/bin/env python3
"""Shape measures of the sources (docs/development.md, "Keeping the shape"): functions over 60
lines, classes whose members are defined in several .cpp files, shared files that name a device,
and the ROS layer's share of the non-test lines. Run from the repository root; prints a report.
"""
import re
import subprocess
import sys
from collections import defaultdict

MAX_FUNCTION_LINES = 60
# A file that includes one of these belongs to the ROS layer wherever it sits.
ROS_INCLUDE = re.compile(r"#include\s*<(ros|rosbag|nodelet|actionlib|tf2_ros|diagnostic_updater|"
                         r"dynamic_reconfigure|\w+_msgs)/")
DEVICE_NAMES = re.compile(
    r"\b(base|body|servo_bus|imu)\b|\b(Base|Body|ServoBus|Imu)[A-Z][A-Za-z]*"
    r"|\b(base|body|servo_bus)_[a-z]+")


def tracked(*patterns):
    out = subprocess.run(["git", "ls-files", *patterns], capture_output=True, text=True,
                         check=True).stdout
    return [p for p in out.split("\n") if p]


def is_test(path):
    return "/test/" in path or path.startswith("test/")


def is_dds(path):
    """The DDS layer and front ends (src/dds, src/dds_front, src/devices/*/dds, dds_driver)."""
    return "/dds" in path or path.rsplit("/", 1)[-1].startswith("dds_")


def code_lines(text):
    """The text with comments, string and character literals blanked (line breaks kept)."""
    out, i, n = [], 0, len(text)
    while i < n:
        c = text[i]
        if text.startswith("//", i):
            j = text.find("\n", i)
            i = n if j < 0 else j
        elif text.startswith("/*", i):
            j = text.find("*/", i + 2)
            j = n if j < 0 else j + 2
            out.append("\n" * text.count("\n", i, j))
            i = j
        elif c == 'R' and text.startswith('R"', i):
            m = re.match(r'R"([^(]*)\(', text[i:])
            end = text.find(")" + m.group(1) + '"', i) if m else -1
            j = n if end < 0 else end + len(m.group(1)) + 2
            out.append('""' + "\n" * text.count("\n", i, j))
            i = j
        elif c in "\"'":
            j = i + 1
            while j < n and text[j] != c:
                j += 2 if text[j] == "\\" else 1
            out.append(c + c)
            i = j + 1
        else:
            out.append(c)
            i += 1
    return "".join(out)


def functions(path):
    """(name, first line, line count) of each function body defined at namespace or class level."""
    text = code_lines(open(path, encoding="utf-8").read())
    found, stack, head_start = [], [], 0
    for m in re.finditer(r"[{};]", text):
        ch, pos = m.group(), m.start()
        if ch == "{":
            head = text[head_start:pos]
            outer = all(kind != "function" for kind, _, _ in stack)
            is_function = (outer and ")" in head and not re.search(
                r"\b(class|struct|namespace|enum|union)\b", head) and
                not re.search(r"=\s*$", head.strip()) and not head.strip().endswith("]"))
            name = ""
            if is_function:
                sig = re.search(r"([~\w:<>]+)\s*\(", head)
                name = sig.group(1) if sig else "?"
                start = head_start + len(head) - len(head.lstrip())
            stack.append(("function" if is_function else "block",
                          start if is_function else pos, name))
            head_start = pos + 1
        elif ch == "}":
            if stack:
                kind, start, name = stack.pop()
                if kind == "function":
                    first = text.count("\n", 0, start) + 1
                    last = text.count("\n", 0, pos) + 1
                    found.append((name, first, last - first + 1))
            head_start = pos + 1
        else:
            head_start = pos + 1
    return found


def main():
    sources = [p for p in tracked("src", "include", "bench") if p.endswith((".cpp", ".h"))]
    product = [p for p in sources if not is_test(p)]

    long_functions = []
    class_files = defaultdict(set)
    for path in product:
        for name, line, count in functions(path):
            if count > MAX_FUNCTION_LINES:
                long_functions.append((count, f"{path}:{line} {name}"))
            if path.endswith(".cpp") and "::" in name and not path.startswith("bench/"):
                cls = name.rsplit("::", 1)[0].split("::")[-1]
                class_files[cls].add(path)
    split = {c: sorted(f) for c, f in class_files.items() if len(f) > 1}

    shared = [p for p in product if not p.startswith(("src/devices/", "include/serial_robot_driver/devices/", "bench/"))]
    naming = [p for p in shared if DEVICE_NAMES.search(code_lines(open(p, encoding="utf-8").read()))]

    def lines(paths):
        return sum(open(p, encoding="utf-8").read().count("\n") for p in paths)

    core_and_ros = [p for p in product if not p.startswith("bench/")]
    ros = [p for p in core_and_ros if "/ros/" in p or p.startswith("src/nodes/") or
           ROS_INCLUDE.search(open(p, encoding="utf-8").read())]
    plumbing = [p for p in core_and_ros if not p.startswith(("src/devices/", "include/serial_robot_driver/devices/"))]
    casts = [p for p in plumbing if re.search(r"\bdynamic_cast\b|\bstd::any\b", code_lines(open(p, encoding="utf-8").read()))]

    for label, prefix_ok in (("driver", lambda w: not w.startswith("bench/")),
                             ("benchmarks", lambda w: w.startswith("bench/"))):
        listed = sorted((c, w) for c, w in long_functions if prefix_ok(w))
        print(f"non-test functions over {MAX_FUNCTION_LINES} lines ({label}): {len(listed)}")
        for count, where in reversed(listed):
            print(f"  {count:4d}  {where}")
    print(f"classes defined over several .cpp: {len(split)}")
    for cls, files in sorted(split.items()):
        print(f"  {cls}: {', '.join(files)}")
    print(f"shared non-test files whose code names a device: {len(naming)}")
    for p in naming:
        print(f"  {p}")
    print(f"dynamic_cast / std::any in shared plumbing: {len(casts)} files {casts}")
    print(f"ROS-layer share of non-test lines: {lines(ros)} / {lines(core_and_ros)} = "
          f"{100.0 * lines(ros) / lines(core_and_ros):.1f} %")
    # The same without the DDS files, so that the DDS layer's size does not hide ROS-layer growth.
    ros_only, without_dds = ([p for p in paths if not is_dds(p)] for paths in (ros, core_and_ros))
    print(f"ROS-layer share of non-test lines without the DDS files: {lines(ros_only)} / "
          f"{lines(without_dds)} = {100.0 * lines(ros_only) / lines(without_dds):.1f} %")
    return 0


if __name__ == "__main__":
    sys.exit(main())
