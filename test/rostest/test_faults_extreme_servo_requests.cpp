// /extreme/driver_node (faults.test) gets servo requests with id 255, unknown names, huge and
// negative values and an empty parameter: every servo service answers success = false with a
// reason, puts no byte on the wire, and the node keeps working.
#include <gtest/gtest.h>

#include "support/faults_support.h"

namespace {

using namespace faults_test;  // NOLINT: the shared fixture

struct Rejection {
  std::string request;
  bool call_ok = false;
  bool success = true;
  std::string message;
};

TEST_F(ExtremeInputs, ServoRequestsOutOfRangeFailCleanlyWithoutBytes) {
  sim::RobotSim& robot = extremeRobot();
  // Called again if roscpp lost the call on its way (callService).
  const auto call = [&](const std::string& service, auto& srv) {
    return test_support::callService(nh_.resolveName("servo/" + service), srv);
  };
  ASSERT_TRUE(
      ros::service::waitForService(nh_.resolveName("servo/reset_user_data"), ros::Duration(20)));

  // The bus works, so a rejection below is the request's fault, not the wire's.
  srd::ServoPing alive;
  alive.request.id = 1;
  ASSERT_TRUE(waitFor([&] { return call("ping", alive) && alive.response.online; }, 20))
      << alive.response.message;

  const auto requests_on_wire = [&] {
    const sim::SimStats s = robot.stats();
    return s.framer.framesOf(srd::devices::servo_bus::kRequestFrames);
  };
  const uint64_t wire_before = requests_on_wire();
  const uint64_t sim_requests_before =
      srd::devices::servo_bus::sim::servoBusStats(robot.stats()).requests;

  std::vector<Rejection> results;
  const auto record = [&](std::string what, bool call_ok, bool success, std::string message) {
    results.push_back({std::move(what), call_ok, success, std::move(message)});
  };
  {
    srd::ServoPing s;
    s.request.id = 255;
    const bool ok = call("ping", s);
    record("ping id 255", ok, s.response.online, s.response.message);
  }
  const auto doRead = [&](uint8_t id, const std::string& param) {
    srd::ServoRead s;
    s.request.id = id;
    s.request.param = param;
    const bool ok = call("read", s);
    record("read id " + std::to_string(id) + " '" + param + "'", ok, s.response.success,
           s.response.message);
  };
  doRead(255, "voltage");
  doRead(1, "");
  doRead(1, "no_such_param");
  doRead(1, "999");
  doRead(1, "-1");
  doRead(1, "51x");
  doRead(1, std::string(10000, 'x'));
  const auto doWrite = [&](uint8_t id, const std::string& param, int64_t value) {
    srd::ServoWrite s;
    s.request.id = id;
    s.request.param = param;
    s.request.value = value;
    const bool ok = call("write", s);
    record("write id " + std::to_string(id) + " '" + param.substr(0, 20) +
               "' = " + std::to_string(value),
           ok, s.response.success, s.response.message);
  };
  doWrite(1, "", 1);
  doWrite(1, "no_such_param", 1);
  doWrite(1, "angle_limit_low", std::numeric_limits<int64_t>::max());
  doWrite(1, "angle_limit_low", std::numeric_limits<int64_t>::min());
  doWrite(1, "angle_limit_high", 32768);
  doWrite(1, "soft_start_time", -1);  // unsigned 16-bit
  doWrite(1, "stall_power_limit", 65536);
  doWrite(1, "response_switch", 2);     // 0 or 1
  doWrite(1, "accel_switch", -128);     // unsigned 8-bit
  doWrite(1, "voltage", 5000);          // read-only
  doWrite(1, "servo_id", 3);            // dangerous, not armed
  doWrite(1, "baudrate", 3);            // dangerous, not armed
  doWrite(255, "soft_start_time", 10);  // broadcast: no read-back possible
  {
    srd::ServoReadAngle s;
    s.request.id = 255;
    const bool ok = call("read_angle", s);
    record("read_angle id 255", ok, s.response.success, s.response.message);
  }
  {
    srd::ServoReadAll s;
    s.request.id = 255;
    const bool ok = call("read_all", s);
    record("read_all id 255", ok, s.response.success, s.response.message);
  }
  const auto doRotate = [&](uint8_t id, double angle, bool wait, const std::string& what) {
    srd::ServoRotate s;
    s.request.id = id;
    s.request.angle_deg = angle;
    s.request.interval_ms = 100;
    s.request.wait = wait;
    const bool ok = call("rotate", s);
    record("rotate " + what, ok, s.response.success, s.response.message);
  };
  doRotate(1, kNaN, false, "NaN");
  doRotate(1, kInf, false, "+Inf");
  doRotate(1, -kInf, false, "-Inf");
  doRotate(1, 1e9, false, "1e9 deg");
  doRotate(1, -3276.9, false, "-3276.9 deg");
  doRotate(255, 10.0, true, "id 255 with wait");
  const auto doSpin = [&](uint8_t id, uint8_t mode, uint16_t speed, uint16_t value, bool wait,
                          const std::string& what) {
    srd::ServoSpin s;
    s.request.id = id;
    s.request.mode = mode;
    s.request.speed_dps = speed;
    s.request.value = value;
    s.request.wait = wait;
    const bool ok = call("spin", s);
    record("spin " + what, ok, s.response.success, s.response.message);
  };
  doSpin(1, 4, 100, 0, false, "mode 4");
  doSpin(1, 255, 100, 0, false, "mode 255");
  doSpin(255, 1, 100, 0, true, "id 255 with wait");
  doSpin(1, 2, 1, 65535, true, "65535 turns at 1 deg/s with wait");
  {
    srd::ServoDamping s;
    s.request.id = 255;
    s.request.power_mw = 65535;
    s.request.wait = true;
    const bool ok = call("damping", s);
    record("damping id 255 with wait", ok, s.response.success, s.response.message);
  }
  for (uint8_t id : {uint8_t{1}, uint8_t{255}}) {
    srd::ServoResetUserData s;
    s.request.id = id;
    const bool ok = call("reset_user_data", s);
    record("reset_user_data id " + std::to_string(id), ok, s.response.success, s.response.message);
  }

  for (const Rejection& r : results) {
    // (a 10000-character parameter name comes back in full: shortened here for the log)
    std::printf("%-45s -> %s\n", r.request.substr(0, 45).c_str(), r.message.substr(0, 160).c_str());
    EXPECT_TRUE(r.call_ok) << r.request << ": the call itself failed";
    EXPECT_FALSE(r.success) << r.request << " was accepted: " << r.message;
    EXPECT_GE(r.message.size(), 10u) << r.request << ": no reason given";
  }
  // Not one of them put a byte on the bus.
  EXPECT_EQ(requests_on_wire(), wire_before);
  EXPECT_EQ(srd::devices::servo_bus::sim::servoBusStats(robot.stats()).requests,
            sim_requests_before);

  // And the bus still works.
  srd::ServoRead voltage;
  voltage.request.id = 1;
  voltage.request.param = "voltage";
  ASSERT_TRUE(call("read", voltage));
  EXPECT_TRUE(voltage.response.success) << voltage.response.message;
  EXPECT_EQ(voltage.response.unit, "mV");
  srd::ServoPing absent;
  absent.request.id = 200;  // not on the bus: a timeout, after a real request
  ASSERT_TRUE(call("ping", absent));
  EXPECT_FALSE(absent.response.online);
  EXPECT_FALSE(absent.response.message.empty());
  std::printf("%-45s -> %s\n", "ping id 200 (absent)", absent.response.message.c_str());
  EXPECT_TRUE(call("ping", alive) && alive.response.online) << alive.response.message;
}

}  // namespace
