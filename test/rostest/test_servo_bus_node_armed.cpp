// The armed driver_node's dangerous servo/* services (servo id change, user data reset), the
// servo_bus diagnostics (servo_bus_node.test); and the main() of the test_servo_bus_node target,
// which plays both buses.
#include <gtest/gtest.h>

#include "support/servo_bus_node_support.h"

namespace {

using namespace servo_bus_node_test;  // NOLINT: the shared fixture

TEST(ServoBusNodeArmed, ServoIdChangePingsTheNewIdWritesAndReadsBack) {
  const std::size_t mark = g_armed->mark();
  const auto [success, message] = writeParam(armedService(""), 3, "servo_id", 5);
  EXPECT_TRUE(success) << message;
  // PING 5 twice (nobody answers), the write, the read-back at the new id.
  EXPECT_EQ(g_armed->bytesSince(mark), concat({kPing5, kPing5, kWriteServoId3To5, kReadServoId5}));
}

TEST(ServoBusNodeArmed, ServoIdChangeRefusedWhenTheNewIdAnswers) {
  const std::size_t mark = g_armed->mark();
  const auto [success, message] = writeParam(armedService(""), 3, "servo_id", 4);
  EXPECT_FALSE(success);
  EXPECT_NE(message.find("already answers at id 4"), std::string::npos) << message;
  EXPECT_EQ(bytesBeforeNextPing(*g_armed, armedService("ping"), mark), kPing4);
}

TEST(ServoBusNodeArmed, ResetUserData) {
  const std::size_t mark = g_armed->mark();
  srd::ServoResetUserData srv;
  srv.request.id = 3;
  srv = call(armedService("reset_user_data"), srv);
  EXPECT_TRUE(srv.response.success) << srv.response.message;
  EXPECT_EQ(g_armed->bytesSince(mark), kResetUserData3);
}

TEST(ServoBusNodeArmed, SilentResetSucceedsWhenTheServoAnswersAtIdZero) {
  const std::size_t mark = g_armed->mark();
  srd::ServoResetUserData srv;
  srv.request.id = 6;
  srv = call(armedService("reset_user_data"), srv);
  EXPECT_TRUE(srv.response.success) << srv.response.message;
  EXPECT_NE(srv.response.message.find("id 0"), std::string::npos) << srv.response.message;
  // The reset once (never re-sent to an id the servo may have left), then PING 0.
  EXPECT_EQ(g_armed->bytesSince(mark), concat({kResetUserData6, kPing0}));
}

TEST(ServoBusNode, DiagnosticsReportTransactionsTimeoutsAndSkippedEchoes) {
  // An offline PING makes sure there is a timeout to report; the safe bus echoes every request.
  EXPECT_FALSE(ping(safeService("ping"), 7).response.online);
  ros::NodeHandle nh;
  const test_support::DiagnosticsWatch diagnostics(nh, "driver_node");
  const auto servo_bus = [&] { return diagnostics.latest("servo_bus"); };
  const bool seen = test_support::waitFor(
      [&] {
        const test_support::DiagnosticsWatch::Status status = servo_bus();
        return status.number("timeouts") > 0 && status.number("echoes skipped") > 0 &&
               status.number("transactions") > 0;
      },
      15.0);
  EXPECT_TRUE(seen) << "no servo_bus diagnostics with transactions, timeouts and echoes";
  EXPECT_GT(servo_bus().values.count("max latency (ms)"), 0u);
}

void scriptServos(ServoBusPlayer& safe, ServoBusPlayer& armed) {
  safe.answer(kPing3, {kPing3Reply});
  safe.answer(kReadVoltage3, {kReadVoltage3Reply});
  safe.answer(kReadLimitLow3, {kReadLimitLow3Reply});
  safe.answer(kWriteSoftStart3, {kWriteSoftStart3Ok});
  safe.answer(kReadSoftStart3, {kReadSoftStart3Reply300});
  safe.answer(kWriteOverTemp3, {kWriteOverTemp3Failed});
  safe.answer(kReadAngle0, {kReadAngle0Reply902});
  safe.answer(kReadBatch3, {kReadBatch3Reply});
  safe.answer(kReadMultiTurn1, {kReadMultiTurn1Reply720});

  armed.answer(kPing3, {kPing3Reply});
  armed.answer(kPing4, {kPing4Reply});
  armed.answer(kWriteServoId3To5, {kWriteServoId3To5Ok});
  armed.answer(kReadServoId5, {kReadServoId5Reply});
  armed.answer(kResetUserData3, {kResetUserData3Ok});
  armed.answer(kPing0, {kPing0Reply});
}

/// Waits until the node behind `ping_service` has opened its pty and servo 3 answers.
bool waitUntilOnline(const std::string& ping_service) {
  if (!ros::service::waitForService(ping_service, ros::Duration(30.0))) return false;
  return test_support::waitFor(
      [&] {
        srd::ServoPing srv;
        srv.request.id = 3;
        return test_support::callService(ping_service, srv) && srv.response.online;
      },
      30.0);
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  test_support::RosTestNode node(argc, argv, "test_servo_bus_node", /*spinner_threads=*/1);

  std::string safe_port;
  std::string armed_port;
  if (!ros::param::get("/driver_node/port", safe_port) ||
      !ros::param::get("/armed/driver_node/port", armed_port)) {
    std::fprintf(stderr, "the .test file must set /driver_node/port and /armed/driver_node/port\n");
    return 1;
  }
  int result = 1;
  {
    const std::unique_ptr<ServoBusPlayer> safe_bus = servoBus(safe_port, /*echo=*/true);
    const std::unique_ptr<ServoBusPlayer> armed_bus = servoBus(armed_port, /*echo=*/false);
    ServoBusPlayer& safe = *safe_bus;
    ServoBusPlayer& armed = *armed_bus;
    scriptServos(safe, armed);
    g_safe = &safe;
    g_armed = &armed;
    if (!waitUntilOnline("servo/ping") || !waitUntilOnline("armed/servo/ping")) {
      std::fprintf(stderr, "driver_node did not come up on its pty\n");
    } else {
      result = RUN_ALL_TESTS();
    }
    g_safe = nullptr;
    g_armed = nullptr;
  }
  return result;
}
