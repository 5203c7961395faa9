// device::ServoMotionClaims: while the e-stop holds, every servo motion service and servo_commands
// is refused (and counted under its source); without the e-stop engaged, nothing is.
#include <gtest/gtest.h>

#include <vector>

#include "serial_robot_driver/device/e_stop.h"
#include "serial_robot_driver/devices/servo_bus/servo_motion_claims.h"
#include "support/servo_bus_rig.h"

namespace serial_robot_driver::device {
namespace {

class ServoMotionClaimsTest : public ServoBusTest {
 protected:
  void SetUp() override { makeBus({1, 2}); }
  const std::vector<trajectory::BusJoint> joints_;
};

TEST_F(ServoMotionClaimsTest, NothingIsRefusedWithoutAnEngagedEStop) {
  ServoMotionClaims claims(*bus_, joints_);
  EXPECT_TRUE(claims.refuseWhileEStopped("servo/move").ok()) << "no e-stop attached";
  EStop e_stop;
  claims.attachEStop(e_stop);
  EXPECT_TRUE(claims.refuseWhileEStopped("servo/move").ok());
  EXPECT_TRUE(claims.claimServos({1}, "servo/rotate").ok());
  EXPECT_TRUE(e_stop.stats().refused.empty());
}

TEST_F(ServoMotionClaimsTest, AnEngagedEStopRefusesAndCountsEachSource) {
  ServoMotionClaims claims(*bus_, joints_);
  EStop e_stop;
  claims.attachEStop(e_stop);
  e_stop.set(true);
  const ServoStatus move = claims.refuseWhileEStopped("servo_commands");
  EXPECT_EQ(move.error, ServoError::kMotionRefused);
  EXPECT_NE(move.message.find("e_stop is engaged"), std::string::npos) << move.message;
  EXPECT_EQ(claims.claimServos({}, "servo/hold").error, ServoError::kMotionRefused);
  EXPECT_EQ(claims.claimServos({2}, "servo/hold").error, ServoError::kMotionRefused);
  const EStopStats stats = e_stop.stats();
  EXPECT_EQ(stats.refused.at("servo_commands"), 1u);
  EXPECT_EQ(stats.refused.at("servo/hold"), 2u);

  e_stop.set(false);
  EXPECT_TRUE(claims.claimServos({2}, "servo/hold").ok()) << "released: obeyed again";
}

}  // namespace
}  // namespace serial_robot_driver::device
