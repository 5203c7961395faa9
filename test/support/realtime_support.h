// What the tests of ~realtime_priority and ~scheduler_slice_us need: the calling thread's
// scheduling policy and slice, whether this process may use SCHED_FIFO at all (root in a container
// may; a CI user usually may not) and whether the kernel keeps a thread's own slice, and a thread
// that has given up the capabilities that would allow SCHED_FIFO.
#pragma once

#include <gtest/gtest.h>
#include <linux/capability.h>
#include <pthread.h>
#include <sched.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <cstdint>
#include <fstream>
#include <functional>
#include <string>
#include <thread>

#include "serial_robot_driver/core/realtime.h"

namespace test_support {

/// Passes when `message` (a log line, a refusal) contains `part`, and shows the message when not.
inline ::testing::AssertionResult mentions(const std::string& message, const std::string& part) {
  if (message.find(part) != std::string::npos) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "'" << part << "' is not in: " << message;
}

struct ThreadPolicy {
  int policy = -1;
  int priority = -1;
  uint64_t slice_ns = 0;  ///< the fair scheduler's slice (0 where the kernel reports none)
};

/// The kernel's struct sched_attr (SCHED_ATTR_SIZE_VER1), for the tests' own system calls.
struct KernelSchedAttr {
  uint32_t size = sizeof(KernelSchedAttr);
  uint32_t policy = 0;
  uint64_t flags = 0;
  int32_t nice = 0;
  uint32_t priority = 0;
  uint64_t runtime = 0, deadline = 0, period = 0;
  uint32_t util_min = 0, util_max = 0;
};

/// The calling thread's fair-scheduler slice in ns, as sched_getattr reports it: its own slice or
/// the default from Linux 6.12 on, 0 before.
inline uint64_t currentThreadSliceNs() {
  KernelSchedAttr attr;
  if (syscall(SYS_sched_getattr, 0, &attr, sizeof(attr), 0) != 0) return 0;
  return attr.runtime;
}

/// The `se.slice` line (ns) of a thread's /proc/<pid>/task/<tid>/sched file; 0 when there is none.
inline uint64_t sliceFromSchedFile(const std::string& path) {
  std::ifstream sched(path);
  std::string line;
  while (std::getline(sched, line)) {
    if (line.rfind("se.slice", 0) != 0) continue;
    const auto colon = line.find(':');
    if (colon != std::string::npos) return std::stoull(line.substr(colon + 1));
  }
  return 0;
}

/// The calling thread's policy, priority and slice, as the kernel holds them.
inline ThreadPolicy currentThreadPolicy() {
  ThreadPolicy current;
  sched_param param{};
  if (pthread_getschedparam(pthread_self(), &current.policy, &param) == 0) {
    current.priority = param.sched_priority;
  }
  current.slice_ns = currentThreadSliceNs();
  return current;
}

/// Why a test of ~scheduler_slice_us is skipped where ownSlicesKept() is false.
inline constexpr const char* kNoOwnSlices =
    "this kernel keeps no slice of a thread's own (Linux before 6.12)";

/// Whether this kernel keeps a thread's own slice (Linux 6.12 and later): asked on a thread that
/// ends at once, by system calls of its own, not by the code under test.
inline bool ownSlicesKept() {
  uint64_t kept = 0;
  std::thread probe([&] {
    KernelSchedAttr attr;
    if (syscall(SYS_sched_getattr, 0, &attr, sizeof(attr), 0) != 0) return;
    attr.size = sizeof(attr);  // the same policy and nice value, another slice
    attr.flags = 0;
    attr.runtime = 250000;
    if (syscall(SYS_sched_setattr, 0, &attr, 0) == 0) kept = currentThreadSliceNs();
  });
  probe.join();
  return kept == 250000;
}

/// Whether a thread of this process may take SCHED_FIFO at `priority` (tried on a thread that
/// ends at once).
inline bool fifoAllowed(int priority) {
  int error = -1;
  std::thread probe([&] { error = serial_robot_driver::core::enterRealtime(priority); });
  probe.join();
  return error == 0;
}

/// Runs `body` on a thread without CAP_SYS_NICE and CAP_IPC_LOCK in its effective set
/// (capabilities are per thread; threads it starts inherit that), as an unprivileged user runs.
inline void runWithoutRealtimeCapabilities(const std::function<void()>& body) {
  std::thread unprivileged([&] {
    __user_cap_header_struct header{_LINUX_CAPABILITY_VERSION_3, 0};
    __user_cap_data_struct data[2] = {};
    if (syscall(SYS_capget, &header, data) == 0) {
      data[CAP_TO_INDEX(CAP_SYS_NICE)].effective &= ~CAP_TO_MASK(CAP_SYS_NICE);
      data[CAP_TO_INDEX(CAP_IPC_LOCK)].effective &= ~CAP_TO_MASK(CAP_IPC_LOCK);
      syscall(SYS_capset, &header, data);
    }
    body();
  });
  unprivileged.join();
}

}  // namespace test_support
