// device::ServoMotionClaims: while the e-stop holds, every servo motion service and servo_commands
// is refused (and counted under its source); without the e-stop engaged, nothing is.
#include <gtest/gtest.h>

#include <vector>

#include "serial_robot_driver/core/e_stop.h"
#include "serial_robot_driver/devices/servo_bus/servo_motion_claims.h"
#include "support/servo_bus_rig.h"

namespace serial_robot_driver::devices::servo_bus {
namespace {

class ServoMotionClaimsTest : public ServoBusTest {
 protected:
  void SetUp() override { makeBus({1, 2}); }
  const std::vector<trajectory::BusJoint> joints_;
};

TEST_F(ServoMotionClaimsTest, NothingIsRefusedWithoutAnEngagedEStop) {
  ServoMotionClaims claims(*bus_, joints_);
  EXPECT_TRUE(claims.refuseWhileEStopped("servo/move").ok()) << "no e-stop attached";
  core::EStop e_stop;
  claims.attachEStop(e_stop);
  EXPECT_TRUE(claims.refuseWhileEStopped("servo/move").ok());
  EXPECT_TRUE(claims.claimServos({1}, "servo/rotate").ok());
  EXPECT_TRUE(e_stop.stats().refused.empty());
}

TEST_F(ServoMotionClaimsTest, AnEngagedEStopRefusesAndCountsEachSource) {
  ServoMotionClaims claims(*bus_, joints_);
  core::EStop e_stop;
  claims.attachEStop(e_stop);
  e_stop.set(true);
  const ServoStatus move = claims.refuseWhileEStopped("servo_commands");
  EXPECT_EQ(move.error, ServoError::kMotionRefused);
  EXPECT_NE(move.message.find("e_stop is engaged"), std::string::npos) << move.message;
  EXPECT_EQ(claims.claimServos({}, "servo/hold").error, ServoError::kMotionRefused);
  EXPECT_EQ(claims.claimServos({2}, "servo/hold").error, ServoError::kMotionRefused);
  const core::EStopStats stats = e_stop.stats();
  EXPECT_EQ(stats.refused.at("servo_commands"), 1u);
  EXPECT_EQ(stats.refused.at("servo/hold"), 2u);

  e_stop.set(false);
  EXPECT_TRUE(claims.claimServos({2}, "servo/hold").ok()) << "released: obeyed again";
}

TEST_F(ServoMotionClaimsTest, UnderAnEngagedEStopTheMotionServicesWriteNothing) {
  ServoMotionClaims claims(*bus_, joints_);
  core::EStop e_stop;
  claims.attachEStop(e_stop);
  e_stop.set(true);
  MoveRequest move;
  move.id = 1;
  RotateRequest rotate;
  rotate.id = 1;
  SpinRequest spin;
  spin.id = 1;
  spin.mode = 1;  // continuous
  EXPECT_EQ(claims.move(move, "servo/move").error, ServoError::kMotionRefused);
  EXPECT_EQ(claims.rotate(rotate, "servo/rotate").error, ServoError::kMotionRefused);
  EXPECT_EQ(claims.hold({1}, "servo/hold").error, ServoError::kMotionRefused);
  EXPECT_EQ(claims.spin(spin, "servo/spin").error, ServoError::kMotionRefused);
  EXPECT_TRUE(written().empty());
  const core::EStopStats stats = e_stop.stats();
  for (const char* source : {"servo/move", "servo/rotate", "servo/hold", "servo/spin"}) {
    EXPECT_EQ(stats.refused.count(source), 1u) << source;
  }
}

TEST_F(ServoMotionClaimsTest, UnderAnEngagedEStopTheStopsStillReachTheBus) {
  ServoMotionClaims claims(*bus_, joints_);
  core::EStop e_stop;
  claims.attachEStop(e_stop);
  e_stop.set(true);
  SpinRequest spin_stop;
  spin_stop.id = 1;  // mode 0: a SPIN stop
  EXPECT_NE(claims.spin(spin_stop, "servo/spin").error, ServoError::kMotionRefused);
  const std::size_t after_spin = written().size();
  EXPECT_GT(after_spin, 0u);
  EXPECT_NE(claims.damping(1, 0, false, "servo/damping").error, ServoError::kMotionRefused);
  const std::size_t after_damping = written().size();
  EXPECT_GT(after_damping, after_spin);
  EXPECT_NE(claims.relax({1}, "servo/relax").error, ServoError::kMotionRefused);
  EXPECT_GT(written().size(), after_damping);
  EXPECT_TRUE(e_stop.stats().refused.empty());
}

TEST(ServoErrors, OnlyWhatARequestAsksForRefusesIt) {
  EXPECT_TRUE(refusesRequest(ServoError::kInvalidArgument));
  EXPECT_TRUE(refusesRequest(ServoError::kDangerous));
  EXPECT_FALSE(refusesRequest(ServoError::kTimeout));
  EXPECT_FALSE(refusesRequest(ServoError::kMotionRefused)) << "counted by the e-stop instead";
  EXPECT_FALSE(refusesRequest(ServoError::kOk));
}

}  // namespace
}  // namespace serial_robot_driver::devices::servo_bus
