// The action must keep control_msgs' md5 sums, or clients built against control_msgs (MoveIt,
// rqt_joint_trajectory_controller) are refused at connection time.
#include <gtest/gtest.h>
#include <ros/message_traits.h>

#include <string>

#include "serial_robot_driver/FollowJointTrajectoryAction.h"
#include "serial_robot_driver/FollowJointTrajectoryActionGoal.h"
#include "serial_robot_driver/FollowJointTrajectoryActionResult.h"
#include "serial_robot_driver/FollowJointTrajectoryGoal.h"
#include "serial_robot_driver/FollowJointTrajectoryResult.h"
#include "serial_robot_driver/JointTolerance.h"

namespace {

template <typename Message>
std::string md5() {
  return ros::message_traits::MD5Sum<Message>::value();
}

// control_msgs/FollowJointTrajectory's sums. ActionGoal is the type on the `goal` topic, the one a
// client's connection is matched on; Goal is what it wraps.
TEST(TrajectoryActionDefinition, SumsMatchControlMsgs) {
  EXPECT_EQ(md5<serial_robot_driver::FollowJointTrajectoryAction>(),
            "bc4f9b743838566551c0390c65f1a248");
  EXPECT_EQ(md5<serial_robot_driver::FollowJointTrajectoryActionGoal>(),
            "cff5c1d533bf2f82dd0138d57f4304bb");
  EXPECT_EQ(md5<serial_robot_driver::FollowJointTrajectoryGoal>(),
            "69636787b6ecbde4d61d711979bc7ecb");
  EXPECT_EQ(md5<serial_robot_driver::FollowJointTrajectoryActionResult>(),
            "c4fb3b000dc9da4fd99699380efcc5d9");
  EXPECT_EQ(md5<serial_robot_driver::JointTolerance>(), "f544fe9c16cf04547e135dd6063ff5be");
}

TEST(TrajectoryActionDefinition, ResultCodesMatchControlMsgs) {
  using Result = serial_robot_driver::FollowJointTrajectoryResult;
  EXPECT_EQ(Result::SUCCESSFUL, 0);
  EXPECT_EQ(Result::INVALID_GOAL, -1);
  EXPECT_EQ(Result::INVALID_JOINTS, -2);
  EXPECT_EQ(Result::OLD_HEADER_TIMESTAMP, -3);
  EXPECT_EQ(Result::PATH_TOLERANCE_VIOLATED, -4);
  EXPECT_EQ(Result::GOAL_TOLERANCE_VIOLATED, -5);
}

}  // namespace
