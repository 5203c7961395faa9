// driver_node's servo/* services (servo_bus_node.test, docs/node_api.md): ping, parameter reads
// and writes, angles and the user block, against the bus servos this test plays on a pty.
#include <gtest/gtest.h>

#include "support/servo_bus_node_support.h"

namespace {

using namespace servo_bus_node_test;  // NOLINT: the shared fixture

// --- tests --------------------------------------------------------------------------------------

TEST(ServoBusNode, PingOnline) {
  const std::size_t mark = g_safe->mark();
  const srd::ServoPing srv = ping(safeService("ping"), 3);
  EXPECT_TRUE(srv.response.online) << srv.response.message;
  EXPECT_EQ(g_safe->bytesSince(mark), kPing3);
}

TEST(ServoBusNode, PingOfflineReturnsAfterAllAttempts) {
  const std::size_t mark = g_safe->mark();
  const Clock::time_point start = Clock::now();
  const srd::ServoPing srv = ping(safeService("ping"), 7);
  // timeout 0.25 s x (retries 1 + 1), plus a generous margin for a busy machine.
  EXPECT_LT(secondsSince(start), 0.5 + 3.0);
  EXPECT_FALSE(srv.response.online);
  EXPECT_EQ(srv.response.message, "servo 7 did not answer PING within 250 ms (2 attempts)");
  EXPECT_EQ(bytesBeforeNextPing(*g_safe, safeService("ping"), mark), concat({kPing7, kPing7}));
}

TEST(ServoBusNode, ReadUnsignedParameter) {
  srd::ServoRead srv;
  srv.request.id = 3;
  srv.request.param = "voltage";
  srv = call(safeService("read"), srv);
  EXPECT_TRUE(srv.response.success) << srv.response.message;
  EXPECT_EQ(srv.response.value, 7400);
  EXPECT_EQ(srv.response.unit, "mV");
}

TEST(ServoBusNode, ReadSignedParameterByDataId) {
  srd::ServoRead srv;
  srv.request.id = 3;
  srv.request.param = "52";
  srv = call(safeService("read"), srv);
  EXPECT_TRUE(srv.response.success) << srv.response.message;
  EXPECT_EQ(srv.response.value, -900);
  EXPECT_EQ(srv.response.unit, "0.1deg");
}

TEST(ServoBusNode, WriteIsReadBack) {
  const std::size_t mark = g_safe->mark();
  srd::ServoWrite srv;
  srv.request.id = 3;
  srv.request.param = "soft_start_time";
  srv.request.value = 300;
  srv = call(safeService("write"), srv);
  EXPECT_TRUE(srv.response.success) << srv.response.message;
  EXPECT_EQ(g_safe->bytesSince(mark), concat({kWriteSoftStart3, kReadSoftStart3}));
}

TEST(ServoBusNode, WriteResultZeroIsAFailure) {
  srd::ServoWrite srv;
  srv.request.id = 3;
  srv.request.param = "over_temperature";
  srv.request.value = 80;
  srv = call(safeService("write"), srv);
  EXPECT_FALSE(srv.response.success);
  EXPECT_NE(srv.response.message.find("result 0"), std::string::npos) << srv.response.message;
}

TEST(ServoBusNode, ReadAngle) {
  srd::ServoReadAngle srv;
  srv.request.id = 0;
  srv = call(safeService("read_angle"), srv);
  EXPECT_TRUE(srv.response.success) << srv.response.message;
  EXPECT_DOUBLE_EQ(srv.response.angle_deg, 90.2);
}

TEST(ServoBusNode, ReadAllReturnsTheTwentyTwoUserParameters) {
  srd::ServoReadAll srv;
  srv.request.id = 3;
  srv = call(safeService("read_all"), srv);
  ASSERT_TRUE(srv.response.success) << srv.response.message;
  const std::vector<std::string> names = {
      "reserved_32",        "response_switch",    "servo_id",          "reserved_35",
      "baudrate",           "stall_protect_mode", "stall_power_limit", "over_volt_low",
      "over_volt_high",     "over_temperature",   "over_power",        "over_current",
      "accel_switch",       "reserved_45",        "po_lock_switch",    "wb_lock_switch",
      "angle_limit_switch", "soft_start_switch",  "soft_start_time",   "angle_limit_high",
      "angle_limit_low",    "angle_mid_offset"};
  const std::vector<int64_t> values = {0,    0, 3, 0, 5, 1, 4000, 4500, 14000, 80,    12000,
                                       3000, 1, 0, 0, 1, 1, 0,    300,  1800,  -1800, -5};
  EXPECT_EQ(srv.response.names, names);
  EXPECT_EQ(srv.response.values, values);
}

}  // namespace
