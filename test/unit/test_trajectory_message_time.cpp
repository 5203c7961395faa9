// trajectory/message_time.h: stamps as messages carry them (any seconds, nanoseconds not
// normalised) give finite times without throwing; the stamps an action server can compute with;
// a message's duration; how a goal whose handling failed is answered.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>

#include "serial_robot_driver/trajectory/message_time.h"

namespace serial_robot_driver::trajectory {
namespace {

constexpr int64_t kUint32Max = std::numeric_limits<uint32_t>::max();

TEST(MessageTime, AStampBecomesASteadyStartByItsDistanceFromNow) {
  EXPECT_EQ(steadyStart({}, 500.0, {1000000000, 0}), 500.0) << "zero: now";
  EXPECT_NEAR(steadyStart({1000, 0}, 500.0, {998, 0}), 502.0, 1e-9);
  EXPECT_NEAR(steadyStart({1000, 0}, 500.0, {1001, 500000000}), 498.5, 1e-9);
  EXPECT_EQ(steadyStart({0, 1}, 500.0, {0, 0}), 500.0 + 1e-9) << "1 ns is not zero";
}

TEST(MessageTime, AnyStampGivesAFiniteTime) {
  EXPECT_NEAR(steadyStart({4000000000, 0}, 500.0, {1700000000, 0}), 500.0 + 2.3e9, 1.0);
  EXPECT_NEAR(steadyStart({1700000000, 4000000000}, 500.0, {1700000000, 0}), 504.0, 1e-6)
      << "unnormalised nanoseconds count as seconds";
  const MessageStamp largest{kUint32Max, kUint32Max};
  EXPECT_TRUE(std::isfinite(steadyStart(largest, 0.0, {1, 0})));
  EXPECT_NEAR(secondsBetween({1, 0}, largest), 1.0 - 4294967295.0 - 4.294967295, 1e-3);
  EXPECT_NEAR(secondsBetween(largest, {0, 0}), 4294967295.0 + 4.294967295, 1e-3);
}

TEST(MessageTime, TheActionServerTakesNormalisedStampsADayBeforeTheEndOfItsSeconds) {
  EXPECT_TRUE(actionTimersCanTake({0, 0}));
  EXPECT_TRUE(actionTimersCanTake({1700000000, 999999999}));
  EXPECT_TRUE(actionTimersCanTake({kUint32Max - 86400, 0}));
  EXPECT_FALSE(actionTimersCanTake({kUint32Max - 86399, 0}));
  EXPECT_FALSE(actionTimersCanTake({kUint32Max, kUint32Max}));
  EXPECT_FALSE(actionTimersCanTake({1700000000, 1000000000})) << "nsec not normalised";
  EXPECT_FALSE(actionTimersCanTake({-1, 0}));
  EXPECT_FALSE(actionTimersCanTake({0, -1}));
}

TEST(MessageTime, TheRefusalNamesTheServerAndTheStamp) {
  EXPECT_EQ(unusableStampText("follow_joint_trajectory", {4294967295, 4294967295}),
            "follow_joint_trajectory: goal or cancel refused: its goal_id.stamp (4294967295 s, "
            "4294967295 ns) is not a time the action server can compute with");
}

TEST(MessageTime, AMessagesDurationHoldsWhatA32BitSecondCountCan) {
  EXPECT_EQ(messageDuration(1.5), 1.5);
  EXPECT_EQ(messageDuration(-1.0), 0.0);
  EXPECT_EQ(messageDuration(-std::numeric_limits<double>::infinity()), 0.0);
  EXPECT_EQ(messageDuration(std::nan("")), 0.0);
  const double longest = std::numeric_limits<int32_t>::max() - 1.0;
  EXPECT_EQ(messageDuration(1e308), longest);
  EXPECT_EQ(messageDuration(std::numeric_limits<double>::infinity()), longest);
}

TEST(MessageTime, AFailedGoalIsRejectedBeforeAcceptanceAbortedAfterAndLeftOnceOver) {
  const auto pending = internalErrorOutcome(GoalPhase::kPending, "bad_alloc");
  ASSERT_TRUE(pending);
  EXPECT_EQ(pending->status, GoalStatus::kRejected);
  EXPECT_EQ(pending->error_code, result_code::kInvalidGoal);
  EXPECT_EQ(pending->error_string, "internal error: bad_alloc");
  EXPECT_EQ(pending->text, pending->error_string);
  const auto active = internalErrorOutcome(GoalPhase::kActive, "");
  ASSERT_TRUE(active);
  EXPECT_EQ(active->status, GoalStatus::kAborted);
  EXPECT_EQ(active->error_code, result_code::kInvalidGoal);
  EXPECT_EQ(active->error_string, "internal error: ");
  EXPECT_FALSE(internalErrorOutcome(GoalPhase::kOver, "late"));
}

}  // namespace
}  // namespace serial_robot_driver::trajectory
