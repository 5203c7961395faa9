// What the servo_bus_node.test tests share: frames written out by hand from docs/protocols.md,
// section 3, the bus servos this test plays on the nodes' ptys (/driver_node: dangerous writes
// refused, echoing adapter; /armed/driver_node: allowed), and service-call helpers.
//
// "Nothing was written" is checked without timing: after a rejected call the test pings servo 3
// and requires that the bytes the pty received in between are exactly that PING.
#pragma once

#include <gtest/gtest.h>
#include <ros/ros.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "serial_robot_driver/ServoDamping.h"
#include "serial_robot_driver/ServoMove.h"
#include "serial_robot_driver/ServoPing.h"
#include "serial_robot_driver/ServoRead.h"
#include "serial_robot_driver/ServoReadAll.h"
#include "serial_robot_driver/ServoReadAngle.h"
#include "serial_robot_driver/ServoResetUserData.h"
#include "serial_robot_driver/ServoRotate.h"
#include "serial_robot_driver/ServoScan.h"
#include "serial_robot_driver/ServoSpin.h"
#include "serial_robot_driver/ServoWrite.h"
#include "serial_robot_driver/devices/servo_bus/servo_bus_codec.h"
#include "serial_robot_driver/protocol/stream_framer.h"
#include "serial_robot_driver/sim/pseudo_terminal.h"
#include "support/fake_device.h"
#include "support/golden_frames.h"
#include "support/ros_test_support.h"

namespace servo_bus_node_test {

namespace srd = serial_robot_driver;
namespace protocol = serial_robot_driver::protocol;
using test_support::Bytes;
using test_support::Clock;
using test_support::concat;
using test_support::secondsSince;

using namespace golden::servo;  // NOLINT: the frames shared with the unit tests

// --- more frames written out by hand from docs/protocols.md, section 3 (SUM = byte sum mod 256) --
inline const Bytes kPing4 = {0x12, 0x4C, 0x01, 0x01, 0x04, 0x64};
// over_temperature (41 = 0x29) of servo 3 := 80, answered with result 0.
inline const Bytes kWriteOverTemp3 = {0x12, 0x4C, 0x04, 0x04, 0x03, 0x29, 0x50, 0x00, 0xE2};
inline const Bytes kWriteOverTemp3Failed = {0x05, 0x1C, 0x04, 0x03, 0x03, 0x29, 0x00, 0x54};
inline const Bytes kPing2 = {0x12, 0x4C, 0x01, 0x01, 0x02, 0x62};
// RESET_USER_DATA id 6: 5E + 02 + 01 + 06 = 67 (the armed bus leaves it unanswered).
inline const Bytes kResetUserData6 = {0x12, 0x4C, 0x02, 0x01, 0x06, 0x67};

// --- the servos on a pty ----------------------------------------------------------------------

/// The bus servos on a pty (a scripted FakeDevice that records every byte the node writes).
using ServoBusPlayer = test_support::FakeDevice;

/// Plays the bus servos at `path`: answers the requests it is scripted for; with `echo`, every
/// request is written back first, as an adapter with a looped-back transmit line does.
inline std::unique_ptr<ServoBusPlayer> servoBus(const std::string& path, bool echo) {
  protocol::FramerConfig config;
  config.accept(protocol::servo::kRequestFrames);
  auto bus = std::make_unique<ServoBusPlayer>(path, config, echo);
  bus->plug();
  return bus;
}

inline ServoBusPlayer* g_safe = nullptr;  // /driver_node: dangerous writes refused, echoing adapter
inline ServoBusPlayer* g_armed = nullptr;  // /armed/driver_node: dangerous writes allowed

inline std::string safeService(const std::string& name) { return "servo/" + name; }
inline std::string armedService(const std::string& name) { return "armed/servo/" + name; }

template <typename Srv>
Srv call(const std::string& service, Srv srv) {
  EXPECT_TRUE(ros::service::call(service, srv)) << service;
  return srv;
}

inline srd::ServoPing ping(const std::string& service, uint8_t id) {
  srd::ServoPing srv;
  srv.request.id = id;
  return call(service, srv);
}

/// Pings servo 3 (which answers) and returns what the pty received since `mark` before that PING:
/// everything the node wrote in between. The trailing PING frames are checked and cut off (more
/// than one only if a busy machine made the node re-send).
inline Bytes bytesBeforeNextPing(ServoBusPlayer& bus, const std::string& ping_service,
                                 std::size_t mark) {
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

inline srd::ServoMove moveRequest(uint8_t id, double angle_deg, bool multi_turn,
                                  uint32_t interval_ms, double velocity_dps, uint16_t accel_ms,
                                  uint16_t decel_ms) {
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

inline std::pair<bool, std::string> readParam(const std::string& prefix, uint8_t id,
                                              const char* param) {
  srd::ServoRead srv;
  srv.request.id = id;
  srv.request.param = param;
  srv = call(prefix + "read", srv);
  return {srv.response.success, srv.response.message};
}

inline std::pair<bool, std::string> writeParam(const std::string& prefix, uint8_t id,
                                               const char* param, int64_t value) {
  srd::ServoWrite srv;
  srv.request.id = id;
  srv.request.param = param;
  srv.request.value = value;
  srv = call(prefix + "write", srv);
  return {srv.response.success, srv.response.message};
}

}  // namespace servo_bus_node_test
