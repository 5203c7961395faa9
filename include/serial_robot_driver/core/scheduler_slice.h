// ~scheduler_slice_us: the turn the node's threads ask of Linux's fair scheduler.
//
// Since Linux 6.12 (EEVDF) a SCHED_OTHER thread may ask, without privilege, for a shorter slice
// than the kernel's default (0.75 ms × (1 + log2 CPUs)) through sched_setattr's sched_runtime. A
// woken thread with the shorter slice has the earlier virtual deadline, so it preempts a CPU hog
// at once instead of waiting for the hog's turn to end; its share of the CPU (its weight) does not
// change. On the 2-core VM with a nice-0 hog per core, a thread woken every 10 ms for 0.1 ms of
// work started late by 3.2–3.8 ms at p99 with the default slice and by 0.2–0.3 ms with 100 µs.
// 100 µs, the kernel's least, was also the best for work of 0.1–0.3 ms a wake-up, the size of
// the reader's and the loop's (docs/performance.md).
//
// Threading model: a slice belongs to a thread, and a thread starts with its parent's.
// driver_node asks for it on its main thread before roscpp starts its threads, so every thread of
// the process has it; each frame thread (the port readers, the base loop) asks again where it
// starts, since in a nodelet manager the threads are not the node's. A thread at a real-time
// policy (~realtime_priority) is left alone: slices do not apply to it. A kernel before 6.12
// accepts the call and keeps its own slices; the one log line says so.
#pragma once

#include <cstdint>
#include <string>

namespace serial_robot_driver::core {

/// The kernel's bounds for a requested slice (it clamps to them); 0 asks for nothing.
constexpr int kMinSchedulerSliceUs = 100;
constexpr int kMaxSchedulerSliceUs = 100000;

/// What a thread got when it asked for a slice.
struct SliceOutcome {
  int error = 0;         ///< errno of sched_getattr / sched_setattr; 0: the call went through
  bool fair = true;      ///< false: the thread runs a real-time policy; nothing was asked
  uint64_t kept_ns = 0;  ///< the slice the kernel reports afterwards (0 before Linux 6.12)
};

/// The calling thread asks for a `slice_us` slice, keeping its policy, nice value and flags.
/// `slice_us` 0 does nothing.
SliceOutcome requestSchedulerSlice(int slice_us);

/// Pure: the one log line for `slice_us` from what a thread got; empty for 0.
std::string describeSchedulerSlice(int slice_us, const SliceOutcome& outcome);

/// Once per process: asks on a short-lived probe thread (the caller keeps its own slice) and
/// returns describeSchedulerSlice's line.
std::string probeSchedulerSlice(int slice_us);

}  // namespace serial_robot_driver::core
