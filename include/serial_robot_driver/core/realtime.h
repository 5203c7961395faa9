// ~realtime_priority: the threads that carry frames between the wire and the devices' decisions
// run SCHED_FIFO, and the process's memory is locked, as drivers that own a control loop do, so a
// busy machine (a CPU hog at nice 0 on every core) does not stretch their tail.
//
// Threading model: a scheduling policy belongs to a thread. prepareRealtime() runs once per
// process, before those threads start (DriverCore::start()): it locks the memory (mlockall, process
// wide) and checks that SCHED_FIFO is allowed, so the core logs ONE line saying what applies,
// or what refused it and how to allow it. Two levels, because SCHED_FIFO threads of EQUAL priority
// never preempt one another: at one level a woken loop or reader waits until whichever thread of
// the node holds a core blocks (traced on 2 cores under a CPU hog: the loop and the readers queued
// behind roscpp's poll thread, the process's busiest, while a higher-priority process held the
// other core; docs/performance.md).
//  - At `priority` (enterRealtime() first thing where each starts), the threads that carry frames:
//    every port's reader thread (core::SerialLink: reads, frames, decodes and publishes telemetry
//    and replies; the servo bus's transactions run on it) and the base's control loop
//    (devices::base::BaseController: the 50 Hz wheel frames). They preempt the rest at once.
//  - At supportPriority(priority), one below, the rest of the process: driver_node puts its main
//    thread there before roscpp starts its threads (ros_layer::runDriverNode), so every other
//    thread inherits it: roscpp's poll thread (which carries messages between the sockets and the
//    callback queues) and timers, the global queue's spinner (cmd_vel and joint_commands written
//    at once, trajectory ticks, services, diagnostics), the servo/* and calibration spinners. Still
//    ahead of every normal process, but never ahead of a frame. In a nodelet manager only the
//    frame threads take a priority.
// A thread that may not switch (EPERM) goes on at the normal policy: nothing else changes.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

namespace serial_robot_driver::core {

/// ~realtime_priority's range: 0 is off, 1..kMaxRealtimePriority SCHED_FIFO at that priority.
constexpr int kMaxRealtimePriority = 99;

/// The SCHED_FIFO priority of the process's threads that do not carry frames when those that do
/// run at `priority`: one below (1 stays 1: there is nothing below it), 0 when off.
int supportPriority(int priority);

/// What the system said when real-time scheduling was asked for (prepareRealtime()).
struct RealtimeFacts {
  int priority = 0;      ///< asked for; 0: off (nothing was tried)
  int sched_error = 0;   ///< errno of SCHED_FIFO at `priority` on a probe thread; 0: allowed
  int memory_error = 0;  ///< errno of mlockall(MCL_CURRENT | MCL_FUTURE); 0: locked (or skipped)
  /// The lock was not tried: with a finite RLIMIT_MEMLOCK and no CAP_IPC_LOCK, MCL_FUTURE would
  /// make any allocation beyond the limit fail later, in the middle of the run.
  bool memory_skipped = false;
  std::optional<uint64_t> rtprio_limit;   ///< RLIMIT_RTPRIO (soft); nullopt: unlimited
  std::optional<uint64_t> memlock_limit;  ///< RLIMIT_MEMLOCK in bytes (soft); nullopt: unlimited
  bool cap_sys_nice = false;              ///< the calling thread's effective CAP_SYS_NICE
  bool cap_ipc_lock = false;              ///< and CAP_IPC_LOCK
};

/// What applies, and the one log line that says it.
struct RealtimeStatus {
  int priority = 0;  ///< SCHED_FIFO priority the threads take; 0: normal scheduling
  bool memory_locked = false;
  /// One line: what applies, or what refused it, naming the limit and how to allow it. Empty
  /// when real-time was not asked for.
  std::string message;
  bool refused = false;  ///< something asked for could not be had (a warning, not an error)
};

/// Pure: the status and its log line from what the system said.
RealtimeStatus judgeRealtime(const RealtimeFacts& facts);

/// Once per process, before the real-time threads start: for `priority` > 0 locks the memory and
/// checks SCHED_FIFO at `priority` (on a short-lived probe thread, so the caller keeps its own
/// policy). `priority` 0: does nothing.
RealtimeStatus prepareRealtime(int priority);

/// The calling thread takes SCHED_FIFO at `priority` (1..99); 0 does nothing. Returns 0 or the
/// errno that refused it (the thread then keeps its policy).
int enterRealtime(int priority);

}  // namespace serial_robot_driver::core
