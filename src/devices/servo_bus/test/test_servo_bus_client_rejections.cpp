// ServoBusClient's rejections (servo_bus_client_fixture.h): for every invalid call the right
// error, a message naming the problem, and not one byte written.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <vector>

#include "support/servo_bus_client_fixture.h"

namespace serial_robot_driver::devices::servo_bus {
namespace {

using protocol::FrameFamily;
using namespace golden::servo;  // NOLINT: the frames shared with the rostest

// --- every rejection: the right error, a message naming the problem, and not one byte written ---

struct Rejection {
  const char* name;
  bool armed;
  ServoError error;
  const char* message_part;
  std::function<ServoStatus(ServoBusClient&)> call;
};

RotateRequest rotateTo(uint8_t id, double angle_deg, bool wait) {
  RotateRequest request;
  request.id = id;
  request.angle_deg = angle_deg;
  request.interval_ms = 100;
  request.wait = wait;
  return request;
}

SpinRequest spinWith(uint8_t id, uint8_t mode, uint16_t speed, uint16_t value, bool wait) {
  SpinRequest request;
  request.id = id;
  request.mode = mode;
  request.speed_dps = speed;
  request.value = value;
  request.wait = wait;
  return request;
}

MoveRequest moveTo(uint8_t id, double angle_deg, bool multi_turn) {
  MoveRequest request;
  request.id = id;
  request.angle_deg = angle_deg;
  request.multi_turn = multi_turn;
  return request;
}

ServoStatus readInto(ServoBusClient& client, uint8_t id, const char* param) {
  ServoParamValue value;
  return client.readParam(id, param, &value);
}

const Rejection kRejections[] = {
    {"ReadUnknownParam", false, ServoError::kUnknownParam, "'volts'",
     [](ServoBusClient& c) { return readInto(c, 3, "volts"); }},
    {"ReadUnknownDataId", false, ServoError::kUnknownParam, "'9'",
     [](ServoBusClient& c) { return readInto(c, 3, "9"); }},
    {"WriteUnknownParam", false, ServoError::kUnknownParam, "'speed'",
     [](ServoBusClient& c) { return c.writeParam(3, "speed", 1); }},
    {"WriteReadOnly", false, ServoError::kReadOnly, "read-only",
     [](ServoBusClient& c) { return c.writeParam(3, "voltage", 7000); }},
    {"WriteOutOfRange", false, ServoError::kOutOfRange, "out of range",
     [](ServoBusClient& c) { return c.writeParam(3, "response_switch", 2); }},
    {"WriteOutOfTypeRange", false, ServoError::kOutOfRange, "out of range",
     [](ServoBusClient& c) { return c.writeParam(3, "angle_limit_low", -40000); }},
    {"WriteServoIdUnarmed", false, ServoError::kDangerous, "dangerous",
     [](ServoBusClient& c) { return c.writeParam(3, "servo_id", 5); }},
    {"WriteBaudrateUnarmed", false, ServoError::kDangerous, "dangerous",
     [](ServoBusClient& c) { return c.writeParam(3, "36", 5); }},
    {"ArmedServoIdOutOfRange", true, ServoError::kOutOfRange, "out of range",
     [](ServoBusClient& c) { return c.writeParam(3, "servo_id", 255); }},
    {"ResetUnarmed", false, ServoError::kDangerous, "dangerous",
     [](ServoBusClient& c) { return c.resetUserData(3); }},
    {"PingBroadcast", false, ServoError::kInvalidArgument, "broadcast",
     [](ServoBusClient& c) { return c.ping(255); }},
    {"ReadBroadcast", false, ServoError::kInvalidArgument, "broadcast",
     [](ServoBusClient& c) { return readInto(c, 255, "voltage"); }},
    {"WriteBroadcast", true, ServoError::kInvalidArgument, "broadcast",
     [](ServoBusClient& c) { return c.writeParam(255, "soft_start_time", 10); }},
    {"ReadAngleBroadcast", false, ServoError::kInvalidArgument, "broadcast",
     [](ServoBusClient& c) {
       double angle = 0.0;
       return c.readAngle(255, &angle);
     }},
    {"ReadAllBroadcast", false, ServoError::kInvalidArgument, "broadcast",
     [](ServoBusClient& c) {
       std::vector<ServoParamValue> values;
       return c.readAll(255, &values);
     }},
    {"ResetBroadcastArmed", true, ServoError::kInvalidArgument, "broadcast",
     [](ServoBusClient& c) { return c.resetUserData(255); }},
    {"RotateBroadcastWait", false, ServoError::kInvalidArgument, "broadcast",
     [](ServoBusClient& c) { return c.rotate(rotateTo(255, 10.0, true)); }},
    {"SpinBroadcastWait", false, ServoError::kInvalidArgument, "broadcast",
     [](ServoBusClient& c) { return c.spin(spinWith(255, 0, 0, 0, true)); }},
    {"DampingBroadcastWait", false, ServoError::kInvalidArgument, "broadcast",
     [](ServoBusClient& c) { return c.damping(255, 100, true); }},
    {"RotateAngleTooLarge", false, ServoError::kInvalidArgument, "out of range",
     [](ServoBusClient& c) { return c.rotate(rotateTo(2, 3276.8, false)); }},
    {"RotateAngleTooSmall", false, ServoError::kInvalidArgument, "out of range",
     [](ServoBusClient& c) { return c.rotate(rotateTo(2, -3276.9, false)); }},
    {"RotateAngleNaN", false, ServoError::kInvalidArgument, "finite",
     [](ServoBusClient& c) { return c.rotate(rotateTo(2, std::nan(""), false)); }},
    {"SpinModeOutOfRange", false, ServoError::kInvalidArgument, "spin mode 4",
     [](ServoBusClient& c) { return c.spin(spinWith(0, 4, 100, 0, false)); }},
    {"SpinWaitTooLong", false, ServoError::kInvalidArgument, "wait = false",
     [](ServoBusClient& c) { return c.spin(spinWith(0, 2, 1, 1000, true)); }},
    {"WriteResponseSwitchUnarmed", false, ServoError::kDangerous, "answered",
     [](ServoBusClient& c) { return c.writeParam(3, "response_switch", 1); }},
    {"WriteReservedUnarmed", false, ServoError::kDangerous, "reserved",
     [](ServoBusClient& c) { return c.writeParam(3, "reserved_45", 1); }},
    {"WriteStallModeZero", false, ServoError::kOutOfRange, "1..2",
     [](ServoBusClient& c) { return c.writeParam(3, "stall_protect_mode", 0); }},
    {"WriteSwitchTwo", false, ServoError::kOutOfRange, "0..1",
     [](ServoBusClient& c) { return c.writeParam(3, "angle_limit_switch", 2); }},
    {"MoveSingleTurnAbove180", false, ServoError::kInvalidArgument, "+-180",
     [](ServoBusClient& c) { return c.move(moveTo(1, 180.1, false)); }},
    {"MoveSingleTurnBelowMinus180", false, ServoError::kInvalidArgument, "+-180",
     [](ServoBusClient& c) { return c.move(moveTo(1, -180.5, false)); }},
    {"MoveMultiTurnTooFar", false, ServoError::kInvalidArgument, "+-368640",
     [](ServoBusClient& c) { return c.move(moveTo(1, 368640.5, true)); }},
    {"MoveAngleNaN", false, ServoError::kInvalidArgument, "finite",
     [](ServoBusClient& c) { return c.move(moveTo(1, std::nan(""), false)); }},
    {"MoveAngleInfinite", false, ServoError::kInvalidArgument, "finite",
     [](ServoBusClient& c) { return c.move(moveTo(1, INFINITY, true)); }},
    {"MoveVelocityNaN", false, ServoError::kInvalidArgument, "velocity_dps is not",
     [](ServoBusClient& c) {
       MoveRequest r = moveTo(1, 10, false);
       r.velocity_dps = std::nan("");
       return c.move(r);
     }},
    {"MoveVelocityAbove750", false, ServoError::kInvalidArgument, "750",
     [](ServoBusClient& c) {
       MoveRequest r = moveTo(1, 10, false);
       r.velocity_dps = 750.5;
       return c.move(r);
     }},
    {"MoveVelocityNegative", false, ServoError::kInvalidArgument, "negative",
     [](ServoBusClient& c) {
       MoveRequest r = moveTo(1, 10, false);
       r.velocity_dps = -10;
       return c.move(r);
     }},
    {"MoveAccelUnder20", false, ServoError::kInvalidArgument, "accel_ms 19",
     [](ServoBusClient& c) {
       MoveRequest r = moveTo(1, 10, false);
       r.interval_ms = 1000;
       r.accel_ms = 19;
       return c.move(r);
     }},
    {"MoveDecelUnder20ByVelocity", false, ServoError::kInvalidArgument, "decel_ms 1",
     [](ServoBusClient& c) {
       MoveRequest r = moveTo(1, 10, true);
       r.velocity_dps = 100;
       r.decel_ms = 1;
       return c.move(r);
     }},
    {"MoveSingleTurnIntervalAboveU16", false, ServoError::kInvalidArgument, "65535",
     [](ServoBusClient& c) {
       MoveRequest r = moveTo(1, 10, false);
       r.interval_ms = 65536;
       return c.move(r);
     }},
    {"MoveRampsLongerThanInterval", false, ServoError::kInvalidArgument, "accel + decel",
     [](ServoBusClient& c) {
       MoveRequest r = moveTo(1, 10, false);
       r.interval_ms = 100;
       r.accel_ms = 80;
       r.decel_ms = 80;
       return c.move(r);
     }},
    {"ReadMultiTurnBroadcast", false, ServoError::kInvalidArgument, "broadcast",
     [](ServoBusClient& c) {
       MultiTurnReading reading;
       return c.readMultiTurnAngle(255, &reading);
     }},
    {"ScanBroadcast", false, ServoError::kInvalidArgument, "broadcast",
     [](ServoBusClient& c) {
       std::vector<uint8_t> ids;
       return c.scan(250, 255, &ids);
     }},
    {"ScanReversedRange", false, ServoError::kInvalidArgument, "above last_id",
     [](ServoBusClient& c) {
       std::vector<uint8_t> ids;
       return c.scan(9, 3, &ids);
     }},
};

class ServoBusClientRejectionTest : public ::testing::TestWithParam<Rejection> {};

TEST_P(ServoBusClientRejectionTest, RejectsWithoutWritingAByte) {
  const Rejection& rejection = GetParam();
  FakeBus bus;
  ServoBusClient client(testOptions(rejection.armed),
                        [&bus](const Bytes& frame) { return bus.write(frame); });
  bus.client = &client;
  const ServoStatus status = rejection.call(client);
  EXPECT_EQ(status.error, rejection.error) << status.message;
  EXPECT_NE(status.message.find(rejection.message_part), std::string::npos) << status.message;
  EXPECT_TRUE(bus.written.empty());
}

INSTANTIATE_TEST_SUITE_P(ServoBusClient, ServoBusClientRejectionTest,
                         ::testing::ValuesIn(kRejections),
                         [](const ::testing::TestParamInfo<Rejection>& info) {
                           return std::string(info.param.name);
                         });

}  // namespace
}  // namespace serial_robot_driver::devices::servo_bus
