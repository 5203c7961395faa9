// The base's control loop at ~realtime_priority: where this process may use SCHED_FIFO (root in a
// container), the loop thread really runs at it, above the thread that started it (driver_node's
// threads run one below, core/realtime.h); where it may not, the loop runs on all the same.
#include <gtest/gtest.h>

#include <atomic>
#include <mutex>
#include <thread>

#include "serial_robot_driver/core/realtime.h"
#include "serial_robot_driver/devices/base/base_controller.h"
#include "support/realtime_support.h"
#include "support/test_helpers.h"

namespace serial_robot_driver::devices::base {
namespace {

using test_support::currentThreadPolicy;
using test_support::ThreadPolicy;

/// The policy of the thread that reported the first odometry sample: the loop's.
ThreadPolicy loopPolicyWith(const BaseConfig& config) {
  std::mutex mutex;
  std::optional<ThreadPolicy> seen;
  BaseEvents events;
  events.on_odometry = [&](const OdometrySample&) {
    std::lock_guard<std::mutex> lock(mutex);
    if (!seen) seen = currentThreadPolicy();
  };
  BaseController controller(
      config, [](const std::vector<uint8_t>&) { return true; }, events);
  controller.start();
  const bool ticked = test_support::waitFor(
      [&] {
        std::lock_guard<std::mutex> lock(mutex);
        return seen.has_value();
      },
      3.0);
  controller.stop();
  EXPECT_TRUE(ticked) << "the loop ticks whatever its policy";
  return seen.value_or(ThreadPolicy{});
}

ThreadPolicy loopPolicyAt(int priority) {
  BaseConfig config;
  config.realtime_priority = priority;
  return loopPolicyWith(config);
}

TEST(BaseControllerRealtime, TheLoopRunsAtTheConfiguredPriority) {
  if (!test_support::fifoAllowed(11)) GTEST_SKIP() << "this process may not use SCHED_FIFO";
  const ThreadPolicy policy = loopPolicyAt(11);
  EXPECT_EQ(policy.policy, SCHED_FIFO);
  EXPECT_EQ(policy.priority, 11);
}

TEST(BaseControllerRealtime, TheLoopRunsAboveTheProcessThreadThatStartsIt) {
  if (!test_support::fifoAllowed(11)) GTEST_SKIP() << "this process may not use SCHED_FIFO";
  ThreadPolicy starter;
  ThreadPolicy loop;
  std::thread process_thread([&] {  // as driver_node's main thread, whose policy threads inherit
    core::enterRealtime(core::supportPriority(11));
    starter = test_support::currentThreadPolicy();
    loop = loopPolicyAt(11);
  });
  process_thread.join();
  EXPECT_EQ(starter.policy, SCHED_FIFO);
  EXPECT_EQ(loop.policy, SCHED_FIFO);
  EXPECT_GT(loop.priority, starter.priority);
}

TEST(BaseControllerRealtime, WithoutAPriorityTheLoopKeepsTheNormalPolicy) {
  EXPECT_EQ(loopPolicyAt(0).policy, SCHED_OTHER);
}

TEST(BaseControllerRealtime, TheLoopTakesTheConfiguredSchedulerSlice) {
  if (!test_support::ownSlicesKept()) GTEST_SKIP() << test_support::kNoOwnSlices;
  BaseConfig config;
  config.scheduler_slice_us = 450;
  const ThreadPolicy policy = loopPolicyWith(config);
  EXPECT_EQ(policy.policy, SCHED_OTHER);
  EXPECT_EQ(policy.slice_ns, 450000U);
}

}  // namespace
}  // namespace serial_robot_driver::devices::base
