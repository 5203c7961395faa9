#include "serial_robot_driver/core/realtime.h"

#include <linux/capability.h>
#include <pthread.h>
#include <sched.h>
#include <sys/mman.h>
#include <sys/resource.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <sstream>
#include <thread>

namespace serial_robot_driver::core {

namespace {

std::optional<uint64_t> softLimit(int resource) {
  rlimit limit{};
  if (getrlimit(resource, &limit) != 0 || limit.rlim_cur == RLIM_INFINITY) return std::nullopt;
  return static_cast<uint64_t>(limit.rlim_cur);
}

/// The calling thread's effective capabilities (capabilities are per thread on Linux).
uint64_t effectiveCapabilities() {
  std::ifstream status("/proc/thread-self/status");
  std::string line;
  while (std::getline(status, line)) {
    if (line.rfind("CapEff:", 0) == 0) return std::stoull(line.substr(7), nullptr, 16);
  }
  return 0;
}

bool hasCapability(uint64_t capabilities, int capability) {
  return (capabilities >> capability) & 1U;
}

std::string limitText(const std::optional<uint64_t>& limit) {
  return limit ? std::to_string(*limit) : std::string("unlimited");
}

std::string schedulingText(const RealtimeFacts& facts) {
  const std::string fifo = "SCHED_FIFO priority " + std::to_string(facts.priority);
  if (facts.sched_error == 0) {
    const int rest = supportPriority(facts.priority);
    return fifo + " for the port readers and the base loop, " +
           (rest < facts.priority ? std::to_string(rest) : std::string("the same")) +
           " for driver_node's other threads (roscpp's, the command callbacks, the services)";
  }
  if (facts.sched_error != EPERM)
    return fifo + " refused (" + std::strerror(facts.sched_error) + ")";
  const bool limit_allows =
      !facts.rtprio_limit || *facts.rtprio_limit >= static_cast<uint64_t>(facts.priority);
  if (!limit_allows && !facts.cap_sys_nice) {
    return fifo + " refused: RLIMIT_RTPRIO is " + limitText(facts.rtprio_limit) +
           " (ulimit -r) and the process has no CAP_SYS_NICE; allow it with '@robot - rtprio 90' "
           "in /etc/security/limits.conf for the user's group (then log in again), or 'sudo "
           "setcap cap_sys_nice,cap_ipc_lock+ep' on driver_node";
  }
  return fifo + " refused although " +
         (facts.cap_sys_nice ? std::string("CAP_SYS_NICE is held")
                             : "RLIMIT_RTPRIO is " + limitText(facts.rtprio_limit)) +
         ": this cgroup has no real-time budget (kernel.sched_rt_runtime_us, cpu.rt_runtime_us; "
         "a container needs --cap-add=SYS_NICE --ulimit rtprio=99 --cpu-rt-runtime=950000)";
}

std::string memoryText(const RealtimeFacts& facts) {
  const std::string limit = facts.memlock_limit
                                ? std::to_string(*facts.memlock_limit / 1024) + " KiB"
                                : std::string("unlimited");
  const std::string allow =
      "; allow it with '@robot - memlock unlimited' in /etc/security/limits.conf or 'setcap "
      "cap_ipc_lock+ep' on driver_node";
  if (facts.memory_skipped) {
    return "memory not locked: RLIMIT_MEMLOCK is " + limit +
           " (ulimit -l) and the process has no CAP_IPC_LOCK, so a lock would make every "
           "allocation beyond it fail" +
           allow;
  }
  if (facts.memory_error != 0) {
    return std::string("memory not locked (mlockall: ") + std::strerror(facts.memory_error) +
           ", RLIMIT_MEMLOCK " + limit + ")" + allow;
  }
  return "memory locked";
}

}  // namespace

int supportPriority(int priority) { return priority > 1 ? priority - 1 : priority; }

RealtimeStatus judgeRealtime(const RealtimeFacts& facts) {
  RealtimeStatus status;
  if (facts.priority <= 0) return status;
  status.priority = facts.sched_error == 0 ? facts.priority : 0;
  status.memory_locked = !facts.memory_skipped && facts.memory_error == 0;
  status.refused = status.priority == 0 || !status.memory_locked;
  status.message = "~realtime_priority " + std::to_string(facts.priority) + ": " +
                   schedulingText(facts) + "; " + memoryText(facts);
  if (status.refused) status.message += "; the node runs on without it";
  return status;
}

int enterRealtime(int priority) {
  if (priority <= 0) return 0;
  sched_param param{};
  param.sched_priority = priority;
  return pthread_setschedparam(pthread_self(), SCHED_FIFO, &param);
}

RealtimeStatus prepareRealtime(int priority) {
  RealtimeFacts facts;
  facts.priority = priority;
  if (priority <= 0) return judgeRealtime(facts);
  facts.rtprio_limit = softLimit(RLIMIT_RTPRIO);
  facts.memlock_limit = softLimit(RLIMIT_MEMLOCK);
  const uint64_t capabilities = effectiveCapabilities();
  facts.cap_sys_nice = hasCapability(capabilities, CAP_SYS_NICE);
  facts.cap_ipc_lock = hasCapability(capabilities, CAP_IPC_LOCK);
  // A probe thread: the caller keeps its own policy. It inherits the caller's capabilities.
  std::thread probe([&facts] { facts.sched_error = enterRealtime(facts.priority); });
  probe.join();
  facts.memory_skipped = facts.memlock_limit && !facts.cap_ipc_lock;
  if (!facts.memory_skipped && mlockall(MCL_CURRENT | MCL_FUTURE) != 0) facts.memory_error = errno;
  return judgeRealtime(facts);
}

}  // namespace serial_robot_driver::core
