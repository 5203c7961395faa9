// ~scheduler_slice_us (core/scheduler_slice.h): the one log line for each way the kernel answers;
// and, where the kernel keeps a thread's own slice (Linux 6.12 and later), that a thread really
// gets it, keeps its policy and nice value, hands it to the threads it starts, and that the port
// reader takes the link's slice. A thread at SCHED_FIFO is left alone.
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <string>
#include <thread>

#include "serial_robot_driver/core/scheduler_slice.h"
#include "serial_robot_driver/core/serial_link.h"
#include "support/reader_policy.h"
#include "support/realtime_support.h"

namespace serial_robot_driver::core {
namespace {

using test_support::currentThreadPolicy;
using test_support::mentions;
using test_support::ownSlicesKept;
using test_support::ThreadPolicy;

TEST(SchedulerSlice, OffSaysNothingAndAsksNothing) {
  EXPECT_EQ(describeSchedulerSlice(0, SliceOutcome{}), "");
  SliceOutcome outcome;
  std::thread worker([&] { outcome = requestSchedulerSlice(0); });
  worker.join();
  EXPECT_EQ(outcome.error, 0);
  EXPECT_EQ(outcome.kept_ns, 0U);
}

TEST(SchedulerSlice, EachAnswerHasItsLine) {
  SliceOutcome kept;
  kept.kept_ns = 100000;
  EXPECT_TRUE(mentions(describeSchedulerSlice(100, kept), "~scheduler_slice_us 100: "));
  EXPECT_TRUE(mentions(describeSchedulerSlice(100, kept), "turns of 100 us"));

  SliceOutcome old_kernel;  // the call went through and nothing is reported back
  EXPECT_TRUE(mentions(describeSchedulerSlice(100, old_kernel), "Linux 6.12"));
  EXPECT_TRUE(mentions(describeSchedulerSlice(100, old_kernel), "nothing changes"));

  SliceOutcome refused;
  refused.error = EPERM;
  EXPECT_TRUE(mentions(describeSchedulerSlice(100, refused), "refused"));
  EXPECT_TRUE(mentions(describeSchedulerSlice(100, refused), std::strerror(EPERM)));

  SliceOutcome fifo;
  fifo.fair = false;
  EXPECT_TRUE(mentions(describeSchedulerSlice(100, fifo), "SCHED_FIFO"));
}

TEST(SchedulerSlice, TheThreadGetsItsSliceAndKeepsItsNiceValueAndPolicy) {
  if (!ownSlicesKept()) GTEST_SKIP() << test_support::kNoOwnSlices;
  int nice_after = 0;
  ThreadPolicy after;
  SliceOutcome outcome;
  std::thread worker([&] {
    sched_param param{};
    ASSERT_EQ(pthread_setschedparam(pthread_self(), SCHED_BATCH, &param), 0);
    ASSERT_EQ(setpriority(PRIO_PROCESS, static_cast<id_t>(::syscall(SYS_gettid)), 7), 0);
    outcome = requestSchedulerSlice(300);
    errno = 0;
    nice_after = getpriority(PRIO_PROCESS, static_cast<id_t>(::syscall(SYS_gettid)));
    after = currentThreadPolicy();
  });
  worker.join();
  EXPECT_EQ(outcome.error, 0);
  EXPECT_EQ(outcome.kept_ns, 300000U);
  EXPECT_EQ(after.slice_ns, 300000U);
  EXPECT_EQ(after.policy, SCHED_BATCH);
  EXPECT_EQ(nice_after, 7) << "the slice must not reset the thread's nice value";
}

TEST(SchedulerSlice, ThreadsStartedAfterwardsInheritIt) {
  if (!ownSlicesKept()) GTEST_SKIP() << test_support::kNoOwnSlices;
  ThreadPolicy child;
  std::thread main_like([&] {  // as driver_node's main thread before roscpp starts its threads
    requestSchedulerSlice(400);
    std::thread started([&] { child = currentThreadPolicy(); });
    started.join();
  });
  main_like.join();
  EXPECT_EQ(child.slice_ns, 400000U);
}

TEST(SchedulerSlice, TheKernelsBoundsAreThoseOfThisHeader) {
  if (!ownSlicesKept()) GTEST_SKIP() << test_support::kNoOwnSlices;
  SliceOutcome least;
  SliceOutcome most;
  std::thread worker([&] {
    least = requestSchedulerSlice(kMinSchedulerSliceUs);
    most = requestSchedulerSlice(kMaxSchedulerSliceUs);
  });
  worker.join();
  EXPECT_EQ(least.kept_ns, kMinSchedulerSliceUs * 1000U);
  EXPECT_EQ(most.kept_ns, kMaxSchedulerSliceUs * 1000U);
}

TEST(SchedulerSlice, AThreadAtSchedFifoIsLeftAlone) {
  if (!test_support::fifoAllowed(5)) GTEST_SKIP() << "this process may not use SCHED_FIFO";
  SliceOutcome outcome;
  ThreadPolicy after;
  std::thread worker([&] {
    enterRealtime(5);
    outcome = requestSchedulerSlice(100);
    after = currentThreadPolicy();
  });
  worker.join();
  EXPECT_FALSE(outcome.fair);
  EXPECT_EQ(outcome.error, 0);
  EXPECT_EQ(after.policy, SCHED_FIFO);
  EXPECT_EQ(after.priority, 5);
  EXPECT_TRUE(mentions(describeSchedulerSlice(100, outcome), "SCHED_FIFO"));
}

TEST(SchedulerSlice, TheReaderThreadTakesTheLinksSlice) {
  if (!ownSlicesKept()) GTEST_SKIP() << test_support::kNoOwnSlices;
  const ThreadPolicy policy =
      test_support::readerThreadPolicy([](SerialLinkOptions& o) { o.scheduler_slice_us = 350; });
  EXPECT_EQ(policy.slice_ns, 350000U);
  EXPECT_EQ(policy.policy, SCHED_OTHER);
}

TEST(SchedulerSlice, TheProbeLeavesTheCallerAlone) {
  const uint64_t before = test_support::currentThreadSliceNs();
  const std::string line = probeSchedulerSlice(kMaxSchedulerSliceUs);
  EXPECT_TRUE(mentions(line, "~scheduler_slice_us 100000: "));
  EXPECT_EQ(test_support::currentThreadSliceNs(), before);
}

}  // namespace
}  // namespace serial_robot_driver::core
