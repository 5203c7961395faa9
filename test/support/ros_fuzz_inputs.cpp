#include "support/ros_fuzz_inputs.h"

#include <gtest/gtest.h>
#include <std_srvs/Trigger.h>

#include <cstdio>
#include <string>
#include <vector>

#include "serial_robot_driver/ServoDamping.h"
#include "serial_robot_driver/ServoHold.h"
#include "serial_robot_driver/ServoInfo.h"
#include "serial_robot_driver/ServoMove.h"
#include "serial_robot_driver/ServoPing.h"
#include "serial_robot_driver/ServoRead.h"
#include "serial_robot_driver/ServoReadAll.h"
#include "serial_robot_driver/ServoReadAngle.h"
#include "serial_robot_driver/ServoRelax.h"
#include "serial_robot_driver/ServoResetUserData.h"
#include "serial_robot_driver/ServoRotate.h"
#include "serial_robot_driver/ServoScan.h"
#include "serial_robot_driver/ServoSpin.h"
#include "serial_robot_driver/ServoWrite.h"
#include "support/ros_test_support.h"
#include "support/test_helpers.h"

namespace ros_fuzz {
namespace {

constexpr double kAnswerSeconds = 10.0;  // an upper bound for a busy machine
const std::vector<std::string> kJointNames = {"joint_1", "joint_2", "pan", "servo_1", "servo_2"};

/// A valid trajectory of a random subset of the joints, then 1..3 fields at their extremes.
trajectory_msgs::JointTrajectory fuzzTrajectory(Extremes& x) {
  trajectory_msgs::JointTrajectory msg;
  msg.header.stamp = x.chance(0.5) ? ros::Time() : x.stamp();
  msg.joint_names = x.chance(0.5) ? std::vector<std::string>{"joint_1", "joint_2"}
                                  : std::vector<std::string>{"pan", "joint_1"};
  const std::size_t points = x.chance(0.1) ? x.size() : 1 + x.pick(3);
  for (std::size_t p = 0; p < points; ++p) {
    trajectory_msgs::JointTrajectoryPoint point;
    point.positions = {0.1 * static_cast<double>(p % 5), -0.1};
    point.time_from_start = ros::Duration(0.2 * static_cast<double>(p + 1));
    msg.points.push_back(point);
  }
  const std::size_t mutations = 1 + x.pick(3);
  for (std::size_t m = 0; m < mutations; ++m) {
    trajectory_msgs::JointTrajectoryPoint* point =
        msg.points.empty() ? nullptr : &msg.points[x.pick(msg.points.size())];
    switch (x.pick(8)) {
      case 0:
        msg.header.stamp = x.stamp();
        break;
      case 1:
        msg.joint_names = x.names(x.chance(0.8) ? x.pick(4) : x.size(), kJointNames);
        break;
      case 2:
        if (point) point->time_from_start = x.duration();
        break;
      case 3:
        if (point) point->positions = x.reals(x.chance(0.7) ? 2 : x.size());
        break;
      case 4:
        if (point) point->velocities = x.reals(x.chance(0.7) ? 2 : x.size());
        break;
      case 5:
        if (point) point->accelerations = x.reals(x.chance(0.7) ? 2 : x.size());
        break;
      case 6:
        msg.points.clear();
        break;
      default:
        if (point && !point->positions.empty()) point->positions[0] = x.real();
        break;
    }
  }
  return msg;
}

sensor_msgs::JointState fuzzJointState(Extremes& x, const std::vector<std::string>& valid) {
  sensor_msgs::JointState msg;
  msg.header.stamp = x.stamp();
  msg.name = valid;
  msg.position = x.reals(valid.size());
  switch (x.pick(5)) {
    case 0:
      msg.name = x.names(x.chance(0.8) ? x.pick(5) : x.size(), kJointNames);
      break;
    case 1:
      msg.position = x.reals(x.chance(0.7) ? x.pick(5) : x.size());
      break;
    case 2:
      msg.velocity = x.reals(x.chance(0.7) ? valid.size() : x.size());
      break;
    case 3:
      msg.effort = x.reals(x.size());
      break;
    default:
      if (!msg.position.empty()) msg.position[0] = x.real();
      break;
  }
  return msg;
}

template <typename Service>
void call(const std::string& name, Service& service) {
  // The answer's content is the node's business; that it answers at all is what counts here (a
  // call roscpp lost on the way is tried again, see callService).
  EXPECT_TRUE(test_support::waitFor([&] { return test_support::callService(name, service); },
                                    kAnswerSeconds))
      << name << " gave no answer";
}

/// A servo id: mostly one that answers (0..3), else any, 255 (broadcast) included.
uint8_t servoId(Extremes& x) {
  return x.chance(0.5) ? static_cast<uint8_t>(x.pick(4)) : x.integer<uint8_t>();
}

std::vector<uint8_t> servoIds(Extremes& x) {
  std::vector<uint8_t> out(x.chance(0.8) ? x.pick(4) : x.size());
  for (uint8_t& each : out) each = servoId(x);
  return out;
}

/// A parameter name: known, dangerous, numeric, negative, enormous, empty or long.
std::string servoParam(Extremes& x) {
  const std::string params[] = {
      "",          "angle_limit_low", "servo_id",        "51",
      "-1",        "99999999999",     "response_switch", std::string(kLongString, 'p'),
      "mid_offset"};
  return params[x.pick(sizeof(params) / sizeof(params[0]))];
}

/// The servo services that read or write settings.
void fuzzSettingsService(Extremes& x) {
  switch (x.pick(8)) {
    case 0: {
      srd::ServoPing s;
      s.request.id = servoId(x);
      call("servo/ping", s);
      break;
    }
    case 1: {
      srd::ServoScan s;
      s.request.first_id = x.integer<uint8_t>();
      s.request.last_id = x.integer<uint8_t>();
      call("servo/scan", s);
      break;
    }
    case 2: {
      srd::ServoRead s;
      s.request.id = servoId(x);
      s.request.param = servoParam(x);
      call("servo/read", s);
      break;
    }
    case 3: {
      srd::ServoWrite s;
      s.request.id = servoId(x);
      s.request.param = servoParam(x);
      s.request.value = x.integer<int64_t>();
      call("servo/write", s);
      break;
    }
    case 4: {
      srd::ServoReadAll s;
      s.request.id = servoId(x);
      call("servo/read_all", s);
      break;
    }
    case 5: {
      srd::ServoResetUserData s;
      s.request.id = servoId(x);
      call("servo/reset_user_data", s);
      break;
    }
    case 6: {
      srd::ServoReadAngle s;
      s.request.id = servoId(x);
      s.request.multi_turn = x.chance(0.5);
      call("servo/read_angle", s);
      break;
    }
    default: {
      srd::ServoInfo s;
      s.request.id = servoId(x);
      call("servo/info", s);
      break;
    }
  }
}

void fuzzMove(Extremes& x) {
  srd::ServoMove s;
  s.request.id = servoId(x);
  s.request.angle_deg = x.real();
  s.request.multi_turn = x.chance(0.5);
  s.request.interval_ms = x.integer<uint32_t>();
  s.request.velocity_dps = x.real();
  s.request.accel_ms = x.integer<uint16_t>();
  s.request.decel_ms = x.integer<uint16_t>();
  s.request.power_mw = x.integer<uint16_t>();
  call("servo/move", s);
}

/// The servo services that move or hold (`wait` false, see the top of the file).
void fuzzMotionService(Extremes& x) {
  switch (x.pick(6)) {
    case 0: {
      srd::ServoRotate s;
      s.request.id = servoId(x);
      s.request.angle_deg = x.real();
      s.request.interval_ms = x.integer<uint16_t>();
      s.request.power_mw = x.integer<uint16_t>();
      call("servo/rotate", s);
      break;
    }
    case 1:
      fuzzMove(x);
      break;
    case 2: {
      srd::ServoSpin s;
      s.request.id = servoId(x);
      s.request.clockwise = x.chance(0.5);
      s.request.mode = x.integer<uint8_t>();
      s.request.speed_dps = x.integer<uint16_t>();
      s.request.value = x.integer<uint16_t>();
      call("servo/spin", s);
      break;
    }
    case 3: {
      srd::ServoDamping s;
      s.request.id = servoId(x);
      s.request.power_mw = x.integer<uint16_t>();
      call("servo/damping", s);
      break;
    }
    case 4: {
      srd::ServoRelax s;
      s.request.ids = servoIds(x);
      call("servo/relax", s);
      break;
    }
    default: {
      srd::ServoHold s;
      s.request.ids = servoIds(x);
      call("servo/hold", s);
      break;
    }
  }
}

/// One service request with its fields at extremes (the Trigger services have none).
void fuzzService(Extremes& x) {
  const char* triggers[] = {"imu/calibrate", "base/reset", "base/reset_odometry",
                            "base/clear_encoders"};
  switch (x.pick(4)) {
    case 0:
      fuzzSettingsService(x);
      break;
    case 1:
      fuzzMotionService(x);
      break;
    case 2:
      fuzzMotionService(x);
      break;
    default: {
      std_srvs::Trigger s;
      call(triggers[x.pick(4)], s);
      break;
    }
  }
}

}  // namespace

void fuzzOne(Extremes& x, Topics& topics) {
  switch (x.pick(8)) {
    case 0: {
      geometry_msgs::Twist twist;
      twist.linear.x = x.real();
      twist.angular.z = x.real();
      twist.linear.y = x.real();
      topics.cmd_vel.publish(twist);
      break;
    }
    case 1:
      topics.joint_commands.publish(fuzzJointState(x, {"joint_1", "joint_2"}));
      break;
    case 2:
      topics.servo_commands.publish(fuzzJointState(x, {"servo_1", "servo_3"}));
      break;
    case 3:
      topics.joint_trajectory.publish(fuzzTrajectory(x));
      break;
    case 4: {
      srd::FollowJointTrajectoryActionGoal goal;
      goal.header.stamp = x.stamp();
      goal.goal_id.stamp = x.stamp();
      goal.goal_id.id =
          x.chance(0.2) ? std::string(kLongString, 'g') : "fuzz_" + std::to_string(x.pick(5));
      goal.goal.trajectory = fuzzTrajectory(x);
      goal.goal.goal_time_tolerance = x.duration();
      srd::JointTolerance tolerance;
      tolerance.name = x.name(kJointNames, true);
      tolerance.position = x.real();
      tolerance.velocity = x.real();
      goal.goal.path_tolerance.assign(x.chance(0.8) ? x.pick(3) : x.size(), tolerance);
      goal.goal.goal_tolerance.assign(x.pick(3), tolerance);
      topics.goal.publish(goal);
      break;
    }
    case 5: {
      actionlib_msgs::GoalID cancel;
      cancel.id = x.chance(0.5) ? "" : "fuzz_" + std::to_string(x.pick(5));
      cancel.stamp = x.stamp();
      topics.cancel.publish(cancel);
      break;
    }
    default:
      fuzzService(x);
      break;
  }
}

}  // namespace ros_fuzz
