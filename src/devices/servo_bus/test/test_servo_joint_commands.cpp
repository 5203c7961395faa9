// Bus servos as joints: their canonical names, and a servo_commands message's targets as moves
// (or the one reason the whole message is refused).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "serial_robot_driver/devices/servo_bus/servo_joint_commands.h"

namespace {

using namespace serial_robot_driver::devices::servo_bus;
using namespace serial_robot_driver::core;

TEST(ServoJointNames, RoundTripOnlyForCanonicalNamesOfBusIds) {
  EXPECT_EQ(servoJointName(12), "servo_12");
  EXPECT_EQ(servoIdFromJointName("servo_0"), 0);
  EXPECT_EQ(servoIdFromJointName("servo_12"), 12);
  EXPECT_EQ(servoIdFromJointName("servo_254"), 254);
  EXPECT_EQ(servoIdFromJointName("servo_255"), -1) << "the broadcast id is no joint";
  EXPECT_EQ(servoIdFromJointName("servo_007"), -1) << "not servo 7's canonical name";
  EXPECT_EQ(servoIdFromJointName("servo_"), -1);
  EXPECT_EQ(servoIdFromJointName("servo_1000"), -1);
  EXPECT_EQ(servoIdFromJointName("servo_1a"), -1);
  EXPECT_EQ(servoIdFromJointName("head_pan"), -1);
}

TEST(ServoJointNames, IdListsReadAsTheMessagesWriteThem) {
  EXPECT_EQ(servoIdList({}), "");
  EXPECT_EQ(servoIdList({3}), "3");
  EXPECT_EQ(servoIdList({1, 3, 200}), "1, 3, 200");
}

TEST(ServoCommandBatch, PositionsAndVelocitiesBecomeMovesInDegrees) {
  const ServoCommandBatch batch =
      toServoMoves({"servo_1", "servo_2"}, {M_PI / 2, -M_PI / 4}, {0.0, -M_PI}, 300);
  ASSERT_TRUE(batch.error.empty()) << batch.error;
  ASSERT_EQ(batch.moves.size(), 2u);
  EXPECT_EQ(batch.moves[0].id, 1);
  EXPECT_NEAR(batch.moves[0].angle_deg, 90.0, 1e-9);
  EXPECT_EQ(batch.moves[0].velocity_dps, 0.0) << "no velocity: ROTATE over the interval";
  EXPECT_EQ(batch.moves[0].interval_ms, 300u);
  EXPECT_NEAR(batch.moves[1].angle_deg, -45.0, 1e-9);
  EXPECT_NEAR(batch.moves[1].velocity_dps, 180.0, 1e-9) << "a velocity is a speed, unsigned";

  const ServoCommandBatch no_velocities = toServoMoves({"servo_3"}, {0.0}, {}, 100);
  ASSERT_EQ(no_velocities.moves.size(), 1u);
  EXPECT_EQ(no_velocities.moves[0].velocity_dps, 0.0);
}

TEST(ServoCommandBatch, AnyBadEntryRefusesTheWholeMessage) {
  EXPECT_EQ(toServoMoves({"servo_1", "servo_2"}, {0.0}, {}, 100).error,
            "has 2 names but 1 positions");
  EXPECT_EQ(toServoMoves({"servo_1"}, {0.0}, {1.0, 2.0}, 100).error,
            "has 1 names but 2 velocities (give none or one per name)");
  const ServoCommandBatch unknown = toServoMoves({"servo_1", "wheel"}, {0.0, 0.0}, {}, 100);
  EXPECT_EQ(unknown.error,
            "names 'wheel', which is not a bus servo (expected servo_<id>, id 0..254)");
  EXPECT_TRUE(unknown.moves.empty()) << "servo_1's move is not sent either";
  const std::string long_name(100, 'x');
  EXPECT_EQ(toServoMoves({long_name}, {0.0}, {}, 100).error,
            "names '" + long_name.substr(0, 40) +
                "', which is not a bus servo (expected servo_<id>, id 0..254)");
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(toServoMoves({"servo_1"}, {nan}, {}, 100).error,
            "has a non-finite position or velocity for servo_1");
  EXPECT_EQ(toServoMoves({"servo_1"}, {0.0}, {INFINITY}, 100).error,
            "has a non-finite position or velocity for servo_1");
}

}  // namespace
