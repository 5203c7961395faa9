// ~realtime_priority (core/realtime.h): the one log line for each way the system answers, the
// refusal of a process that may not (a thread without the capabilities, as an unprivileged user),
// and, where this process may use SCHED_FIFO (root in a container), the policy the reader thread
// really runs at. Nothing here locks the test process's memory.
#include <gtest/gtest.h>
#include <sys/resource.h>

#include <string>

#include "serial_robot_driver/core/realtime.h"
#include "serial_robot_driver/core/serial_link.h"
#include "support/reader_policy.h"
#include "support/realtime_support.h"

namespace serial_robot_driver::core {
namespace {

using test_support::currentThreadPolicy;
using test_support::fifoAllowed;
using test_support::mentions;
using test_support::ThreadPolicy;

RealtimeFacts allowed(int priority) {
  RealtimeFacts facts;
  facts.priority = priority;
  facts.rtprio_limit = 0;
  facts.memlock_limit = std::nullopt;
  facts.cap_sys_nice = true;
  facts.cap_ipc_lock = true;
  return facts;
}

TEST(Realtime, OffSaysNothingAndTriesNothing) {
  const RealtimeStatus status = prepareRealtime(0);
  EXPECT_EQ(status.priority, 0);
  EXPECT_FALSE(status.memory_locked);
  EXPECT_FALSE(status.refused);
  EXPECT_TRUE(status.message.empty());
}

TEST(Realtime, GrantedSaysWhatApplies) {
  const RealtimeStatus status = judgeRealtime(allowed(50));
  EXPECT_EQ(status.priority, 50);
  EXPECT_TRUE(status.memory_locked);
  EXPECT_FALSE(status.refused);
  EXPECT_TRUE(mentions(status.message,
                       "SCHED_FIFO priority 50 for the port readers and the base "
                       "loop, 49 for driver_node's other threads"));
  EXPECT_TRUE(mentions(status.message, "memory locked"));
}

TEST(Realtime, TheRestOfTheProcessRunsOneBelowTheFrameThreads) {
  EXPECT_EQ(supportPriority(50), 49);
  EXPECT_EQ(supportPriority(2), 1);
  EXPECT_EQ(supportPriority(1), 1);  // nothing below 1: all at the same level
  EXPECT_EQ(supportPriority(0), 0);  // off
  EXPECT_TRUE(mentions(judgeRealtime(allowed(1)).message,
                       "SCHED_FIFO priority 1 for the port readers and the base loop, the same "
                       "for driver_node's other threads"));
}

TEST(Realtime, RefusedByTheRtprioLimitNamesItAndHowToAllowIt) {
  RealtimeFacts facts = allowed(50);
  facts.cap_sys_nice = false;
  facts.sched_error = EPERM;
  const RealtimeStatus status = judgeRealtime(facts);
  EXPECT_EQ(status.priority, 0);
  EXPECT_TRUE(status.refused);
  EXPECT_TRUE(mentions(status.message, "RLIMIT_RTPRIO is 0"));
  EXPECT_TRUE(mentions(status.message, "CAP_SYS_NICE"));
  EXPECT_TRUE(mentions(status.message, "rtprio 90"));
  EXPECT_TRUE(mentions(status.message, "/etc/security/limits.conf"));
  EXPECT_TRUE(mentions(status.message, "runs on"));
  EXPECT_EQ(status.message.find('\n'), std::string::npos) << "one line";
}

TEST(Realtime, RefusedDespiteTheLimitBlamesTheMissingRealtimeBudget) {
  RealtimeFacts facts = allowed(50);
  facts.cap_sys_nice = false;
  facts.rtprio_limit = 99;
  facts.sched_error = EPERM;
  const RealtimeStatus status = judgeRealtime(facts);
  EXPECT_TRUE(status.refused);
  EXPECT_TRUE(mentions(status.message, "RLIMIT_RTPRIO is 99"));
  EXPECT_TRUE(mentions(status.message, "real-time budget"));
}

TEST(Realtime, ALimitedMemoryLockIsNotTakenAndSaysHowToAllowIt) {
  RealtimeFacts facts = allowed(50);
  facts.cap_ipc_lock = false;
  facts.memlock_limit = 8192 * 1024;
  facts.memory_skipped = true;
  const RealtimeStatus status = judgeRealtime(facts);
  EXPECT_EQ(status.priority, 50) << "the scheduling still applies";
  EXPECT_FALSE(status.memory_locked);
  EXPECT_TRUE(status.refused);
  EXPECT_TRUE(mentions(status.message, "RLIMIT_MEMLOCK is 8192 KiB"));
  EXPECT_TRUE(mentions(status.message, "memlock unlimited"));
}

TEST(Realtime, AnUnprivilegedProcessIsRefusedAndItsThreadKeepsItsPolicy) {
  rlimit rtprio{};
  rlimit memlock{};
  ASSERT_EQ(getrlimit(RLIMIT_RTPRIO, &rtprio), 0);
  ASSERT_EQ(getrlimit(RLIMIT_MEMLOCK, &memlock), 0);
  if (rtprio.rlim_cur == RLIM_INFINITY || rtprio.rlim_cur >= 20 ||
      memlock.rlim_cur == RLIM_INFINITY) {
    GTEST_SKIP() << "this user's limits allow SCHED_FIFO 20 or an unlimited memory lock";
  }
  RealtimeStatus status;
  ThreadPolicy before;
  ThreadPolicy after;
  test_support::runWithoutRealtimeCapabilities([&] {
    before = currentThreadPolicy();
    status = prepareRealtime(20);
    after = currentThreadPolicy();
  });
  EXPECT_EQ(status.priority, 0);
  EXPECT_FALSE(status.memory_locked);
  EXPECT_TRUE(status.refused);
  EXPECT_TRUE(mentions(status.message, "RLIMIT_RTPRIO is " + std::to_string(rtprio.rlim_cur)));
  EXPECT_TRUE(mentions(status.message, "RLIMIT_MEMLOCK"));
  EXPECT_EQ(after.policy, before.policy);
  EXPECT_EQ(after.priority, before.priority);
}

TEST(Realtime, EnterRealtimeGivesTheThreadFifoWhereAllowed) {
  if (!fifoAllowed(10)) GTEST_SKIP() << "this process may not use SCHED_FIFO";
  ThreadPolicy policy;
  std::thread worker([&] {
    EXPECT_EQ(enterRealtime(10), 0);
    policy = currentThreadPolicy();
  });
  worker.join();
  EXPECT_EQ(policy.policy, SCHED_FIFO);
  EXPECT_EQ(policy.priority, 10);
}

TEST(Realtime, TheReaderThreadRunsAtTheLinksPriority) {
  if (!fifoAllowed(12)) GTEST_SKIP() << "this process may not use SCHED_FIFO";
  const ThreadPolicy policy =
      test_support::readerThreadPolicy([](SerialLinkOptions& o) { o.realtime_priority = 12; });
  EXPECT_EQ(policy.policy, SCHED_FIFO);
  EXPECT_EQ(policy.priority, 12);
}

}  // namespace
}  // namespace serial_robot_driver::core
