// What the tests of ~realtime_priority need: the calling thread's scheduling policy, whether this
// process may use SCHED_FIFO at all (root in a container may; a CI user usually may not), and a
// thread that has given up the capabilities that would allow it.
#pragma once

#include <linux/capability.h>
#include <pthread.h>
#include <sched.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <functional>
#include <thread>

#include "serial_robot_driver/core/realtime.h"

namespace test_support {

struct ThreadPolicy {
  int policy = -1;
  int priority = -1;
};

/// The calling thread's policy and priority, as the kernel holds them.
inline ThreadPolicy currentThreadPolicy() {
  ThreadPolicy current;
  sched_param param{};
  if (pthread_getschedparam(pthread_self(), &current.policy, &param) == 0) {
    current.priority = param.sched_priority;
  }
  return current;
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
