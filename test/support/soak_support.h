// What the soak (test_soak.cpp) runs beside its robot: the soak's length and bounds, the
// simulator's counters it reconciles, a boundary of both sides at rest, and the threads that
// publish cmd_vel and joint_commands and call the servo and base services meanwhile.
#pragma once

#include <geometry_msgs/Twist.h>
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <sensor_msgs/Imu.h>
#include <sensor_msgs/JointState.h>
#include <std_srvs/Trigger.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "serial_robot_driver/ServoPing.h"
#include "serial_robot_driver/ServoRead.h"
#include "serial_robot_driver/ServoReadAll.h"
#include "serial_robot_driver/ServoReadAngle.h"
#include "serial_robot_driver/ServoRotate.h"
#include "serial_robot_driver/Telemetry.h"
#include "serial_robot_driver/WheelCommand.h"
#include "serial_robot_driver/devices/base/sim/base_sim.h"
#include "serial_robot_driver/devices/body/sim/body_sim.h"
#include "serial_robot_driver/devices/servo_bus/sim/servo_bus_sim.h"
#include "serial_robot_driver/protocol/stream_framer.h"
#include "serial_robot_driver/sim/robot_sim.h"
#include "support/framer_configs.h"
#include "support/ros_test_support.h"

namespace soak_test {

namespace protocol = serial_robot_driver::protocol;
namespace sim = serial_robot_driver::sim;
namespace srd = serial_robot_driver;
using test_support::DiagnosticsWatch;
using test_support::TopicCounter;
using test_support::waitFor;

constexpr std::size_t kShortestTelemetryFrame = 32;  // 24 + 4 * 2 servos, no foot block
constexpr double kUnplugEvery = 5.0;
// Longer than the 1 s diagnostics period, so the port is seen down at rest. A multiple of the
// node's 0.1 s reconnect interval: the driver's retries, which started at the unplug, then fall a
// few ms after each replug, so most episodes lose nothing to the flush on open and must reconcile
// exactly, while the first episode (the simulator starts at a random phase) and the occasional
// late reopen exercise the bound.
constexpr double kUnplugDuration = 1.5;
constexpr uint64_t kMaxHostFramesLostPerUnplug = 3;
constexpr long kRssSlackKb = 1024;

inline double soakSeconds() {
  const char* text = std::getenv("SRD_SOAK_SECONDS");
  const double seconds = text ? std::atof(text) : 0.0;
  return seconds > 0 ? seconds : 60.0;
}

inline uint64_t telemetryIntact(const sim::SimStats& s) {
  return s.sentOf(serial_robot_driver::devices::body::sim::kTelemetryOutput).intact;
}
inline uint64_t hostFramesReceived(const sim::SimStats& s) {
  using protocol::FrameFamily;
  return s.framer.framesOf(serial_robot_driver::devices::base::kFrames) +
         s.framer.framesOf(serial_robot_driver::devices::servo_bus::kRequestFrames) +
         s.framer.framesOf(serial_robot_driver::devices::body::kSyncWriteFrames);
}

/// Both sides at rest while the pty is unplugged.
struct Boundary {
  uint64_t unplugs = 0;
  sim::SimStats sim;
  DiagnosticsWatch::Status port;  ///< the driver's port status, reporting it down
  uint64_t joint_states = 0;
  uint64_t imu = 0;
  uint64_t telemetry = 0;
  test_support::ProcessSample process;
};

/// Publishes cmd_vel (20 Hz) and joint_commands (10 Hz) until stopped.
class Motion {
 public:
  explicit Motion(ros::NodeHandle& nh) {
    cmd_vel_ = nh.advertise<geometry_msgs::Twist>("cmd_vel", 10);
    joint_commands_ = nh.advertise<sensor_msgs::JointState>("joint_commands", 10);
  }
  bool waitConnected() {
    return waitFor([&] { return cmd_vel_.getNumSubscribers() > 0; }, 20) &&
           waitFor([&] { return joint_commands_.getNumSubscribers() > 0; }, 20);
  }
  void start() {
    thread_ = std::thread([this] {
      const auto start = test_support::Clock::now();
      for (uint64_t tick = 0; !stop_; ++tick) {
        const double t = test_support::secondsSince(start);
        geometry_msgs::Twist twist;
        twist.linear.x = 0.4 * std::sin(t);
        twist.angular.z = 0.8 * std::cos(0.7 * t);
        cmd_vel_.publish(twist);
        if (tick % 2 == 0) {
          sensor_msgs::JointState command;
          command.name = {"joint_1", "joint_2"};
          command.position = {0.5 * std::sin(0.5 * t), -0.5 * std::sin(0.5 * t)};
          joint_commands_.publish(command);
          ++joint_commands_sent_;
        }
        test_support::sleepSeconds(0.05);
      }
    });
  }
  void stop() {
    stop_ = true;
    if (thread_.joinable()) thread_.join();
  }
  uint64_t jointCommandsSent() const { return joint_commands_sent_; }

 private:
  ros::Publisher cmd_vel_;
  ros::Publisher joint_commands_;
  std::atomic<bool> stop_{false};
  std::atomic<uint64_t> joint_commands_sent_{0};
  std::thread thread_;
};

/// Calls the servo and base services in turn until stopped, counting the outcomes.
class ServiceCaller {
 public:
  explicit ServiceCaller(ros::NodeHandle& nh) : nh_(nh) {}

  bool waitConnected() {
    return ros::service::waitForService(nh_.resolveName("servo/ping"), ros::Duration(20)) &&
           ros::service::waitForService(nh_.resolveName("base/clear_encoders"), ros::Duration(20));
  }
  void start() {
    thread_ = std::thread([this] {
      for (uint64_t i = 0; !stop_; ++i) {
        callOne(i);
        test_support::sleepSeconds(0.05);
      }
    });
  }
  void stop() {
    stop_ = true;
    if (thread_.joinable()) thread_.join();
  }

  uint64_t calls = 0, call_failures = 0, successes = 0, failures = 0, silent_failures = 0;
  uint64_t answered_successes = 0;  ///< calls that succeed only with a servo's answer
  double slowest_s = 0.0;

 private:
  template <typename Srv>
  void account(const std::string& service, Srv& srv, bool needs_answer,
               bool (*success)(const typename Srv::Response&),
               const std::string& (*message)(const typename Srv::Response&)) {
    const auto start = test_support::Clock::now();
    const bool ok = test_support::callService(nh_.resolveName(service), srv);
    slowest_s = std::max(slowest_s, test_support::secondsSince(start));
    ++calls;
    if (!ok) {
      ++call_failures;
      return;
    }
    if (success(srv.response)) {
      ++successes;
      if (needs_answer) ++answered_successes;
    } else {
      ++failures;
      if (message(srv.response).empty()) ++silent_failures;
    }
  }

  void callOne(uint64_t i) {
    switch (i % 6) {
      case 0: {
        srd::ServoPing srv;
        srv.request.id = 1;
        account<srd::ServoPing>(
            "servo/ping", srv, true, [](const auto& r) { return bool(r.online); },
            [](const auto& r) -> const std::string& { return r.message; });
        break;
      }
      case 1: {
        srd::ServoRead srv;
        srv.request.id = 0;
        srv.request.param = "voltage";
        account<srd::ServoRead>(
            "servo/read", srv, true, [](const auto& r) { return bool(r.success); },
            [](const auto& r) -> const std::string& { return r.message; });
        break;
      }
      case 2: {
        srd::ServoReadAngle srv;
        srv.request.id = 2;
        account<srd::ServoReadAngle>(
            "servo/read_angle", srv, true, [](const auto& r) { return bool(r.success); },
            [](const auto& r) -> const std::string& { return r.message; });
        break;
      }
      case 3: {
        srd::ServoReadAll srv;
        srv.request.id = 1;
        account<srd::ServoReadAll>(
            "servo/read_all", srv, true, [](const auto& r) { return bool(r.success); },
            [](const auto& r) -> const std::string& { return r.message; });
        break;
      }
      case 4: {
        srd::ServoRotate srv;
        srv.request.id = 0;
        srv.request.angle_deg = static_cast<double>(i % 90);
        srv.request.interval_ms = 50;
        account<srd::ServoRotate>(
            "servo/rotate", srv, false, [](const auto& r) { return bool(r.success); },  // no wait
            [](const auto& r) -> const std::string& { return r.message; });
        break;
      }
      default: {
        std_srvs::Trigger srv;
        const char* service = (i / 6) % 2 == 0 ? "base/reset" : "base/clear_encoders";
        account<std_srvs::Trigger>(
            service, srv, false, [](const auto& r) { return bool(r.success); },
            [](const auto& r) -> const std::string& { return r.message; });
        break;
      }
    }
  }

  ros::NodeHandle nh_;  // the services' namespace
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

}  // namespace soak_test
