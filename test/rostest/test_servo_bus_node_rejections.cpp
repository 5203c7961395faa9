// driver_node's servo/* services refuse bad or dangerous requests (servo_bus_node.test): each
// fails with a message and writes nothing to the bus.
#include <gtest/gtest.h>

#include "support/servo_bus_node_support.h"

namespace {

using namespace servo_bus_node_test;  // NOLINT: the shared fixture

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

}  // namespace
