#include "serial_robot_driver/core/scheduler_slice.h"

#include <sched.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <thread>

namespace serial_robot_driver::core {

namespace {

/// The kernel's struct sched_attr (SCHED_ATTR_SIZE_VER1, 56 bytes), under a name of its own:
/// glibc before 2.41 has no sched_setattr, and later ones declare the struct in <sched.h>.
struct KernelSchedAttr {
  uint32_t size = sizeof(KernelSchedAttr);
  uint32_t sched_policy = 0;
  uint64_t sched_flags = 0;
  int32_t sched_nice = 0;
  uint32_t sched_priority = 0;
  uint64_t sched_runtime = 0;
  uint64_t sched_deadline = 0;
  uint64_t sched_period = 0;
  uint32_t sched_util_min = 0;
  uint32_t sched_util_max = 0;
};
static_assert(sizeof(KernelSchedAttr) == 56, "the kernel's SCHED_ATTR_SIZE_VER1");

/// The kernel's SCHED_FLAG_RESET_ON_FORK: the only flag a fair thread's attributes carry back.
constexpr uint64_t kResetOnFork = 0x01;

bool getAttr(KernelSchedAttr* attr) {
  return ::syscall(SYS_sched_getattr, 0, attr, sizeof(*attr), 0) == 0;
}

std::string microsecondsText(uint64_t ns) { return std::to_string(ns / 1000) + " us"; }

}  // namespace

SliceOutcome requestSchedulerSlice(int slice_us) {
  SliceOutcome outcome;
  if (slice_us <= 0) return outcome;
  KernelSchedAttr attr;
  if (!getAttr(&attr)) {
    outcome.error = errno;
    return outcome;
  }
  if (attr.sched_policy != SCHED_OTHER && attr.sched_policy != SCHED_BATCH &&
      attr.sched_policy != SCHED_IDLE) {
    outcome.fair = false;
    return outcome;
  }
  // The same policy, nice value and reset-on-fork flag: only the slice changes.
  KernelSchedAttr wanted;
  wanted.sched_policy = attr.sched_policy;
  wanted.sched_flags = attr.sched_flags & kResetOnFork;
  wanted.sched_nice = attr.sched_nice;
  wanted.sched_runtime = static_cast<uint64_t>(slice_us) * 1000U;
  if (::syscall(SYS_sched_setattr, 0, &wanted, 0) != 0) {
    outcome.error = errno;
    return outcome;
  }
  KernelSchedAttr after;
  if (getAttr(&after)) outcome.kept_ns = after.sched_runtime;
  return outcome;
}

std::string describeSchedulerSlice(int slice_us, const SliceOutcome& outcome) {
  if (slice_us <= 0) return std::string();
  const std::string head = "~scheduler_slice_us " + std::to_string(slice_us) + ": ";
  if (outcome.error != 0) {
    return head + "sched_setattr refused it (" + std::strerror(outcome.error) +
           "); the node's threads keep the kernel's slices";
  }
  if (!outcome.fair) {
    return head +
           "not asked: the threads run SCHED_FIFO (~realtime_priority), where slices do "
           "not apply";
  }
  if (outcome.kept_ns == 0) {
    return head +
           "this kernel keeps its own slices (a thread's own slice needs Linux 6.12 or "
           "later); nothing changes";
  }
  return head + "the node's threads run in turns of " + microsecondsText(outcome.kept_ns) +
         ", so a woken reader or loop preempts a busy core at once";
}

std::string probeSchedulerSlice(int slice_us) {
  SliceOutcome outcome;
  std::thread probe([&outcome, slice_us] { outcome = requestSchedulerSlice(slice_us); });
  probe.join();
  return describeSchedulerSlice(slice_us, outcome);
}

}  // namespace serial_robot_driver::core
