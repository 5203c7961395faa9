// End-to-end tests of the servo/* services of driver_node (docs/protocols.md, section 3,
// docs/node_api.md).
//
// servo_bus_node.test launches two driver_nodes with only the servo bus enabled: /driver_node
// (dangerous writes refused) and /armed/driver_node (allowed). This test creates their ptys and
// plays the servos itself: a thread per bus reads every byte the node writes, splits the requests
// with the project's StreamFramer and answers the requests it has a script for with response
// frames written out by hand below. The safe bus also echoes every request first, like a
// half-duplex adapter, so the node has to skip its own echo.
//
// "Nothing was written" is checked without timing: after a rejected call the test pings servo 3
// and requires that the bytes the pty received in between are exactly that PING.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <ros/ros.h>

#include "serial_robot_driver/ServoDamping.h"
#include "serial_robot_driver/ServoMove.h"
#include "serial_robot_driver/ServoScan.h"
#include "serial_robot_driver/ServoPing.h"
#include "serial_robot_driver/ServoRead.h"
#include "serial_robot_driver/ServoReadAll.h"
#include "serial_robot_driver/ServoReadAngle.h"
#include "serial_robot_driver/ServoResetUserData.h"
#include "serial_robot_driver/ServoRotate.h"
#include "serial_robot_driver/ServoSpin.h"
#include "serial_robot_driver/ServoWrite.h"
#include "serial_robot_driver/protocol/stream_framer.h"
#include "serial_robot_driver/sim/pseudo_terminal.h"
#include "support/fake_device.h"
#include "support/golden_frames.h"
#include "support/ros_test_support.h"

namespace {

namespace srd = serial_robot_driver;
namespace protocol = serial_robot_driver::protocol;
using test_support::Bytes;
using test_support::Clock;
using test_support::concat;
using test_support::secondsSince;

using namespace golden::servo;  // NOLINT: the frames shared with the unit tests

// --- more frames written out by hand from docs/protocols.md, section 3 (SUM = byte sum mod 256) --
const Bytes kPing4 = {0x12, 0x4C, 0x01, 0x01, 0x04, 0x64};
// over_temperature (41 = 0x29) of servo 3 := 80, answered with result 0.
const Bytes kWriteOverTemp3 = {0x12, 0x4C, 0x04, 0x04, 0x03, 0x29, 0x50, 0x00, 0xE2};
const Bytes kWriteOverTemp3Failed = {0x05, 0x1C, 0x04, 0x03, 0x03, 0x29, 0x00, 0x54};
const Bytes kPing2 = {0x12, 0x4C, 0x01, 0x01, 0x02, 0x62};
// RESET_USER_DATA id 6: 5E + 02 + 01 + 06 = 67 (the armed bus leaves it unanswered).
const Bytes kResetUserData6 = {0x12, 0x4C, 0x02, 0x01, 0x06, 0x67};

// --- the servos on a pty ----------------------------------------------------------------------

/// The bus servos on a pty (a scripted FakeDevice that records every byte the node writes).
using ServoBusPlayer = test_support::FakeDevice;

/// Plays the bus servos at `path`: answers the requests it is scripted for; with `echo`, every
/// request is written back first, as an adapter with a looped-back transmit line does.
std::unique_ptr<ServoBusPlayer> servoBus(const std::string& path, bool echo) {
  protocol::FramerConfig config;
  config.servo_request = true;
  auto bus = std::make_unique<ServoBusPlayer>(path, config, echo);
  bus->plug();
  return bus;
}

ServoBusPlayer* g_safe = nullptr;   // /driver_node: dangerous writes refused, echoing adapter
ServoBusPlayer* g_armed = nullptr;  // /armed/driver_node: dangerous writes allowed

std::string safeService(const std::string& name) { return "servo/" + name; }
std::string armedService(const std::string& name) { return "armed/servo/" + name; }

template <typename Srv>
Srv call(const std::string& service, Srv srv) {
  EXPECT_TRUE(ros::service::call(service, srv)) << service;
  return srv;
}

srd::ServoPing ping(const std::string& service, uint8_t id) {
  srd::ServoPing srv;
  srv.request.id = id;
  return call(service, srv);
}

/// Pings servo 3 (which answers) and returns what the pty received since `mark` before that PING:
/// everything the node wrote in between. The trailing PING frames are checked and cut off (more
/// than one only if a busy machine made the node re-send).
Bytes bytesBeforeNextPing(ServoBusPlayer& bus, const std::string& ping_service, std::size_t mark) {
  const srd::ServoPing srv = ping(ping_service, 3);
  EXPECT_TRUE(srv.response.online) << srv.response.message;
  Bytes bytes = bus.bytesSince(mark);
  std::size_t pings = 0;
  while (bytes.size() >= kPing3.size() &&
         std::equal(kPing3.begin(), kPing3.end(), bytes.end() - kPing3.size())) {
    bytes.resize(bytes.size() - kPing3.size());
    ++pings;
  }
  EXPECT_GE(pings, 1u) << "the PING of servo 3 did not reach the pty last";
  return bytes;
}

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
      "reserved_32",     "response_switch",  "servo_id",           "reserved_35",
      "baudrate",        "stall_protect_mode", "stall_power_limit", "over_volt_low",
      "over_volt_high",  "over_temperature", "over_power",         "over_current",
      "accel_switch",    "reserved_45",      "po_lock_switch",     "wb_lock_switch",
      "angle_limit_switch", "soft_start_switch", "soft_start_time", "angle_limit_high",
      "angle_limit_low", "angle_mid_offset"};
  const std::vector<int64_t> values = {0, 0,    3,     0,  5, 1, 4000, 4500, 14000, 80,   12000,
                                       3000, 1, 0, 0, 1, 1, 0, 300,  1800, -1800, -5};
  EXPECT_EQ(srv.response.names, names);
  EXPECT_EQ(srv.response.values, values);
}

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

srd::ServoMove moveRequest(uint8_t id, double angle_deg, bool multi_turn, uint32_t interval_ms,
                           double velocity_dps, uint16_t accel_ms, uint16_t decel_ms) {
  srd::ServoMove srv;
  srv.request.id = id;
  srv.request.angle_deg = angle_deg;
  srv.request.multi_turn = multi_turn;
  srv.request.interval_ms = interval_ms;
  srv.request.velocity_dps = velocity_dps;
  srv.request.accel_ms = accel_ms;
  srv.request.decel_ms = decel_ms;
  return srv;
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

std::pair<bool, std::string> move(const std::string& prefix, const srd::ServoMove& request) {
  const srd::ServoMove srv = call(prefix + "move", request);
  return {srv.response.success, srv.response.message};
}

// Every rejection: success false, a message naming the problem, and not one byte on the pty.
struct Rejection {
  const char* name;
  bool armed;
  const char* message_part;
  std::function<std::pair<bool, std::string>(const std::string& prefix)> call;
};

std::pair<bool, std::string> readParam(const std::string& prefix, uint8_t id, const char* param) {
  srd::ServoRead srv;
  srv.request.id = id;
  srv.request.param = param;
  srv = call(prefix + "read", srv);
  return {srv.response.success, srv.response.message};
}

std::pair<bool, std::string> writeParam(const std::string& prefix, uint8_t id, const char* param,
                                        int64_t value) {
  srd::ServoWrite srv;
  srv.request.id = id;
  srv.request.param = param;
  srv.request.value = value;
  srv = call(prefix + "write", srv);
  return {srv.response.success, srv.response.message};
}

const Rejection kRejections[] = {
    {"UnknownParam", false, "unknown servo parameter",
     [](const std::string& p) { return readParam(p, 3, "volts"); }},
    {"ReadOnly", false, "read-only",
     [](const std::string& p) { return writeParam(p, 3, "voltage", 7000); }},
    {"OutOfRange", false, "out of range",
     [](const std::string& p) { return writeParam(p, 3, "response_switch", 2); }},
    {"ServoIdUnarmed", false, "allow_dangerous_writes",
     [](const std::string& p) { return writeParam(p, 3, "servo_id", 5); }},
    {"BaudrateUnarmed", false, "allow_dangerous_writes",
     [](const std::string& p) { return writeParam(p, 3, "baudrate", 7); }},
    {"ResetUnarmed", false, "allow_dangerous_writes",
     [](const std::string& p) {
       srd::ServoResetUserData srv;
       srv.request.id = 3;
       srv = call(p + "reset_user_data", srv);
       return std::make_pair(static_cast<bool>(srv.response.success), srv.response.message);
     }},
    {"ServoIdOutOfRangeArmed", true, "out of range",
     [](const std::string& p) { return writeParam(p, 3, "servo_id", 255); }},
    {"PingBroadcast", false, "broadcast",
     [](const std::string& p) {
       const srd::ServoPing srv = ping(p + "ping", 255);
       return std::make_pair(static_cast<bool>(srv.response.online), srv.response.message);
     }},
    {"ReadBroadcast", false, "broadcast",
     [](const std::string& p) { return readParam(p, 255, "voltage"); }},
    {"WriteBroadcastArmed", true, "broadcast",
     [](const std::string& p) { return writeParam(p, 255, "soft_start_time", 10); }},
    {"ReadAngleBroadcast", false, "broadcast",
     [](const std::string& p) {
       srd::ServoReadAngle srv;
       srv.request.id = 255;
       srv = call(p + "read_angle", srv);
       return std::make_pair(static_cast<bool>(srv.response.success), srv.response.message);
     }},
    {"ReadAllBroadcast", false, "broadcast",
     [](const std::string& p) {
       srd::ServoReadAll srv;
       srv.request.id = 255;
       srv = call(p + "read_all", srv);
       return std::make_pair(static_cast<bool>(srv.response.success), srv.response.message);
     }},
    {"ResetBroadcastArmed", true, "broadcast",
     [](const std::string& p) {
       srd::ServoResetUserData srv;
       srv.request.id = 255;
       srv = call(p + "reset_user_data", srv);
       return std::make_pair(static_cast<bool>(srv.response.success), srv.response.message);
     }},
    {"RotateBroadcastWait", false, "broadcast",
     [](const std::string& p) {
       srd::ServoRotate srv;
       srv.request.id = 255;
       srv.request.angle_deg = 10.0;
       srv.request.wait = true;
       srv = call(p + "rotate", srv);
       return std::make_pair(static_cast<bool>(srv.response.success), srv.response.message);
     }},
    {"RotateAngleOutOfRange", false, "out of range",
     [](const std::string& p) {
       srd::ServoRotate srv;
       srv.request.id = 2;
       srv.request.angle_deg = 5000.0;
       srv = call(p + "rotate", srv);
       return std::make_pair(static_cast<bool>(srv.response.success), srv.response.message);
     }},
    {"SpinModeOutOfRange", false, "spin mode 4",
     [](const std::string& p) {
       srd::ServoSpin srv;
       srv.request.id = 0;
       srv.request.mode = 4;
       srv = call(p + "spin", srv);
       return std::make_pair(static_cast<bool>(srv.response.success), srv.response.message);
     }},
    {"MoveSingleTurnBeyond180", false, "+-180",
     [](const std::string& p) { return move(p, moveRequest(1, 180.5, false, 100, 0, 0, 0)); }},
    {"MoveMultiTurnBeyondLimit", false, "+-368640",
     [](const std::string& p) { return move(p, moveRequest(1, -368641, true, 100, 0, 0, 0)); }},
    {"MoveVelocityAbove750", false, "750",
     [](const std::string& p) { return move(p, moveRequest(1, 10, false, 0, 751, 0, 0)); }},
    {"MoveRampUnder20", false, "under 20 ms",
     [](const std::string& p) { return move(p, moveRequest(1, 10, false, 500, 0, 10, 100)); }},
    {"MoveNaN", false, "finite",
     [](const std::string& p) { return move(p, moveRequest(1, std::nan(""), true, 0, 0, 0, 0)); }},
    {"MoveInfiniteVelocity", false, "finite",
     [](const std::string& p) { return move(p, moveRequest(1, 10, false, 0, INFINITY, 0, 0)); }},
    {"ScanBroadcast", false, "broadcast",
     [](const std::string& p) {
       srd::ServoScan srv;
       srv.request.first_id = 250;
       srv.request.last_id = 255;
       srv = call(p + "scan", srv);
       // servo/scan has no success flag: "no id found" stands for the failure.
       return std::make_pair(!srv.response.ids.empty(), srv.response.message);
     }},
    {"ReadMultiTurnBroadcast", false, "broadcast",
     [](const std::string& p) {
       srd::ServoReadAngle srv;
       srv.request.id = 255;
       srv.request.multi_turn = true;
       srv = call(p + "read_angle", srv);
       return std::make_pair(static_cast<bool>(srv.response.success), srv.response.message);
     }},
    {"WriteResponseSwitchUnarmed", false, "allow_dangerous_writes",
     [](const std::string& p) { return writeParam(p, 3, "response_switch", 1); }},
    {"WriteStallModeZero", false, "out of range",
     [](const std::string& p) { return writeParam(p, 3, "stall_protect_mode", 0); }},
    {"DampingBroadcastWait", false, "broadcast",
     [](const std::string& p) {
       srd::ServoDamping srv;
       srv.request.id = 255;
       srv.request.wait = true;
       srv = call(p + "damping", srv);
       return std::make_pair(static_cast<bool>(srv.response.success), srv.response.message);
     }},
};

class ServoBusNodeRejection : public ::testing::TestWithParam<Rejection> {};

TEST_P(ServoBusNodeRejection, FailsWithAMessageAndWritesNothing) {
  const Rejection& rejection = GetParam();
  ServoBusPlayer& bus = rejection.armed ? *g_armed : *g_safe;
  const std::string prefix = rejection.armed ? "armed/servo/" : "servo/";
  const std::size_t mark = bus.mark();
  const auto [success, message] = rejection.call(prefix);
  EXPECT_FALSE(success);
  EXPECT_NE(message.find(rejection.message_part), std::string::npos) << message;
  EXPECT_EQ(bytesBeforeNextPing(bus, prefix + "ping", mark), Bytes{});
}

INSTANTIATE_TEST_SUITE_P(ServoBusNode, ServoBusNodeRejection, ::testing::ValuesIn(kRejections),
                         [](const ::testing::TestParamInfo<Rejection>& info) {
                           return std::string(info.param.name);
                         });

TEST(ServoBusNodeArmed, ServoIdChangePingsTheNewIdWritesAndReadsBack) {
  const std::size_t mark = g_armed->mark();
  const auto [success, message] = writeParam(armedService(""), 3, "servo_id", 5);
  EXPECT_TRUE(success) << message;
  // PING 5 twice (nobody answers), the write, the read-back at the new id.
  EXPECT_EQ(g_armed->bytesSince(mark),
            concat({kPing5, kPing5, kWriteServoId3To5, kReadServoId5}));
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
        return ros::service::call(ping_service, srv) && srv.response.online;
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
