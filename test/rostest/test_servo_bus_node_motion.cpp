// driver_node's servo/* motion services (servo_bus_node.test): rotate, spin, damping, move,
// multi-turn angles and scan put their exact frames on the wire.
#include <gtest/gtest.h>

#include "support/servo_bus_node_support.h"

namespace {

using namespace servo_bus_node_test;  // NOLINT: the shared fixture

TEST(ServoBusNode, RotateSendsTheExactFrameWithoutWaiting) {
  const std::size_t mark = g_safe->mark();
  srd::ServoRotate srv;
  srv.request.id = 2;
  srv.request.angle_deg = 90.0;
  srv.request.interval_ms = 500;
  srv.request.power_mw = 0;
  srv = call(safeService("rotate"), srv);
  EXPECT_TRUE(srv.response.success) << srv.response.message;
  EXPECT_EQ(bytesBeforeNextPing(*g_safe, safeService("ping"), mark), kRotate2To90In500);
}

TEST(ServoBusNode, SpinAndDampingSendTheirFrames) {
  const std::size_t mark = g_safe->mark();
  srd::ServoSpin spin;
  spin.request.id = 0;
  spin.request.clockwise = true;
  spin.request.mode = 3;
  spin.request.speed_dps = 100;
  spin.request.value = 1000;
  spin = call(safeService("spin"), spin);
  EXPECT_TRUE(spin.response.success) << spin.response.message;
  srd::ServoDamping damping;
  damping.request.id = 0;
  damping.request.power_mw = 500;
  damping = call(safeService("damping"), damping);
  EXPECT_TRUE(damping.response.success) << damping.response.message;
  EXPECT_EQ(bytesBeforeNextPing(*g_safe, safeService("ping"), mark),
            concat({kSpin0Cw1000Ms, kDamping0At500}));
}

TEST(ServoBusNode, MotionWaitWithoutAnAnswerTimesOut) {
  srd::ServoDamping srv;
  srv.request.id = 0;
  srv.request.power_mw = 500;
  srv.request.wait = true;
  srv = call(safeService("damping"), srv);
  EXPECT_FALSE(srv.response.success);
  EXPECT_NE(srv.response.message.find("response_switch"), std::string::npos)
      << srv.response.message;
}

TEST(ServoBusNode, MoveSendsTheCommandTheRequestChooses) {
  const std::size_t mark = g_safe->mark();
  const srd::ServoMove requests[] = {
      moveRequest(2, 90.0, false, 500, 0.0, 0, 0),        // plain: ROTATE (CMD 8)
      moveRequest(1, 90.0, false, 1000, 0.0, 100, 100),   // ramps: CMD 11
      moveRequest(1, -90.0, false, 0, 360.0, 100, 100),   // velocity: CMD 12
      moveRequest(1, 720.0, true, 2000, 0.0, 0, 0),       // multi-turn plain: CMD 13
      moveRequest(1, -360.0, true, 1000, 0.0, 200, 200),  // multi-turn ramps: CMD 14
      moveRequest(1, 3600.0, true, 0, 360.0, 100, 100),   // multi-turn velocity: CMD 15
  };
  for (const srd::ServoMove& request : requests) {
    const srd::ServoMove srv = call(safeService("move"), request);
    EXPECT_TRUE(srv.response.success) << srv.response.message;
  }
  EXPECT_EQ(bytesBeforeNextPing(*g_safe, safeService("ping"), mark),
            concat({kRotate2To90In500, kMoveByInterval1To90, kMoveByVelocity1ToMinus90,
                    kMultiTurnMove1To720, kMultiTurnMoveByInterval1ToMinus360,
                    kMultiTurnMoveByVelocity1To3600}));
}

TEST(ServoBusNode, ReadAngleMultiTurnAnswersTheTurns) {
  const std::size_t mark = g_safe->mark();
  srd::ServoReadAngle srv;
  srv.request.id = 1;
  srv.request.multi_turn = true;
  srv = call(safeService("read_angle"), srv);
  EXPECT_TRUE(srv.response.success) << srv.response.message;
  EXPECT_DOUBLE_EQ(srv.response.angle_deg, 720.0);
  EXPECT_EQ(srv.response.turns, 2);
  EXPECT_EQ(g_safe->bytesSince(mark), kReadMultiTurn1);
}

TEST(ServoBusNode, ScanPingsEachIdOnceAndListsTheOnesThatAnswer) {
  const std::size_t mark = g_safe->mark();
  srd::ServoScan srv;
  srv.request.first_id = 2;
  srv.request.last_id = 4;
  srv = call(safeService("scan"), srv);
  EXPECT_EQ(srv.response.ids, std::vector<uint8_t>{3}) << srv.response.message;
  // One PING per id, none re-sent although 2 and 4 stay silent.
  EXPECT_EQ(bytesBeforeNextPing(*g_safe, safeService("ping"), mark),
            concat({kPing2, kPing3, kPing4}));
}

}  // namespace
