// What the servo stress test (test_servo_stress.cpp) runs beside its robot: the load and its
// bounds, the simulator's counters, the motion publisher and the service-calling threads with
// their call records.
#pragma once

#include <geometry_msgs/Twist.h>
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <sensor_msgs/JointState.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "serial_robot_driver/ServoPing.h"
#include "serial_robot_driver/ServoRead.h"
#include "serial_robot_driver/ServoReadAll.h"
#include "serial_robot_driver/ServoReadAngle.h"
#include "serial_robot_driver/ServoWrite.h"
#include "serial_robot_driver/devices/base/sim/base_sim.h"
#include "serial_robot_driver/devices/body/sim/body_sim.h"
#include "serial_robot_driver/devices/servo_bus/sim/servo_bus_sim.h"
#include "serial_robot_driver/sim/robot_sim.h"
#include "support/ros_test_support.h"

namespace servo_stress_test {

namespace sim = serial_robot_driver::sim;
namespace srd = serial_robot_driver;
using test_support::Clock;
using test_support::DiagnosticsWatch;
using test_support::TopicCounter;
using test_support::waitFor;

inline const std::vector<uint8_t> kOnlineIds = {0, 1, 2};
constexpr uint8_t kSilentId = 5;  // on the bus, never answers
constexpr uint8_t kAbsentId = 9;  // not on the bus at all
constexpr int kOnlineCallsPerThread = 125;
constexpr int kOfflineCalls = 60;
constexpr double kTelemetryRateHz = 100.0;
constexpr double kBaseLoopRateHz = 50.0;  // the node's default loop_rate
// Added to timeout * (retries + 1) for an offline call: the call may queue behind an online
// transaction, and a loaded machine delays the service round trip. Generous on purpose: the
// bound catches calls that wait far longer than the bus timeout (a hang, a global queue), not
// milliseconds.
constexpr double kOfflineMargin = 1.0;
// Every call thread must have finished by then (~7 s expected); after it a call counts as hung.
constexpr double kCallDeadline = 30.0;
// Telemetry frames the node may still have had in flight (read but not yet received here) at the
// snapshot opening the window: 200 ms at 100 Hz, far more than a local round trip takes.
constexpr int64_t kOpeningInFlight = 20;
constexpr std::size_t kTelemetryFrameBytes = 32;  // 24 + 4 * 2 servos, no foot block

inline uint64_t telemetryIntact(const sim::SimStats& s) {
  return s.sentOf(serial_robot_driver::devices::body::sim::kTelemetryOutput).intact;
}
inline uint64_t speedFramesReceived(const sim::SimStats& s) {
  return serial_robot_driver::devices::base::sim::baseStats(s).speed_frames_applied +
         serial_robot_driver::devices::base::sim::baseStats(s).speed_frames_ignored;
}

/// Publishes cmd_vel at 20 Hz and joint_commands at 10 Hz (absolute deadlines) until stopped.
class Motion {
 public:
  explicit Motion(ros::NodeHandle& nh)
      : cmd_vel_(nh.advertise<geometry_msgs::Twist>("cmd_vel", 10)),
        joint_commands_(nh.advertise<sensor_msgs::JointState>("joint_commands", 10)) {}
  ~Motion() { stop(); }

  bool waitConnected() {
    return waitFor([&] { return cmd_vel_.getNumSubscribers() > 0; }, 20) &&
           waitFor([&] { return joint_commands_.getNumSubscribers() > 0; }, 20);
  }
  void start() {
    thread_ = std::thread([this] {
      const Clock::time_point start = Clock::now();
      Clock::time_point next = start;
      for (uint64_t tick = 0; !stop_; ++tick) {
        const double t = test_support::secondsSince(start);
        geometry_msgs::Twist twist;
        twist.linear.x = 0.3 * std::sin(t);
        twist.angular.z = 0.6 * std::cos(0.7 * t);
        cmd_vel_.publish(twist);
        ++cmd_vel_sent_;
        if (tick % 2 == 0) {
          sensor_msgs::JointState command;
          command.name = {"joint_1", "joint_2"};
          command.position = {0.5 * std::sin(0.5 * t), -0.5 * std::sin(0.5 * t)};
          joint_commands_.publish(command);
          ++joint_commands_sent_;
        }
        next += std::chrono::milliseconds(50);
        std::this_thread::sleep_until(next);
      }
    });
  }
  void stop() {
    stop_ = true;
    if (thread_.joinable()) thread_.join();
  }
  uint64_t cmdVelSent() const { return cmd_vel_sent_; }
  uint64_t jointCommandsSent() const { return joint_commands_sent_; }

 private:
  ros::Publisher cmd_vel_;
  ros::Publisher joint_commands_;
  std::atomic<bool> stop_{false};
  std::atomic<uint64_t> cmd_vel_sent_{0};
  std::atomic<uint64_t> joint_commands_sent_{0};
  std::thread thread_;
};

/// One service call as the caller saw it.
struct CallRecord {
  std::string what;  ///< "ping 5", "read_all 1", ...
  bool offline = false;
  bool returned = false;  ///< ServiceClient::call returned true
  bool success = false;   ///< online / success in the response
  bool as_expected = false;
  std::string message;
  double seconds = 0.0;
};

/// A thread of service calls with clients of its own. Owned through a shared_ptr held by the
/// thread too, so that a hung call can be abandoned (detached) without a dangling object.
class Caller {
 public:
  enum class Role { kOnlineLow, kOnlineHigh, kOffline };

  Caller(const std::string& ns, Role role) : nh_(ns), role_(role) {
    // Persistent: one connection per service and thread, so the master is not asked 300 times.
    ping_ = nh_.serviceClient<srd::ServoPing>("servo/ping", true);
    read_ = nh_.serviceClient<srd::ServoRead>("servo/read", true);
    write_ = nh_.serviceClient<srd::ServoWrite>("servo/write", true);
    read_angle_ = nh_.serviceClient<srd::ServoReadAngle>("servo/read_angle", true);
    read_all_ = nh_.serviceClient<srd::ServoReadAll>("servo/read_all", true);
  }

  static void start(const std::shared_ptr<Caller>& self) {
    self->thread_ = std::thread([self] { self->run(); });
  }
  bool done() const { return done_; }
  /// Joins when done, else abandons the thread (the test has failed then).
  void finish() {
    if (!thread_.joinable()) return;
    if (done_) {
      thread_.join();
    } else {
      thread_.detach();
    }
  }
  /// The calls completed so far (all of them once done()).
  std::vector<CallRecord> records() const {
    std::lock_guard<std::mutex> lock(records_mutex_);
    return records_;
  }
  std::size_t callsStarted() const { return started_; }

 private:
  void run() {
    const int calls = role_ == Role::kOffline ? kOfflineCalls : kOnlineCallsPerThread;
    for (int i = 0; i < calls; ++i) {
      ++started_;
      CallRecord record = role_ == Role::kOffline ? offlineCall(i) : onlineCall(i);
      std::lock_guard<std::mutex> lock(records_mutex_);
      records_.push_back(std::move(record));
    }
    done_ = true;
  }

  template <typename Srv>
  bool timedCall(ros::ServiceClient& client, Srv& srv, CallRecord* record) {
    const Clock::time_point start = Clock::now();
    record->returned = client.call(srv);
    record->seconds = test_support::secondsSince(start);
    return record->returned;
  }

  CallRecord offlineCall(int i) {
    CallRecord record;
    record.offline = true;
    const uint8_t id = (i / 2) % 2 == 0 ? kSilentId : kAbsentId;
    if (i % 2 == 0) {
      srd::ServoPing srv;
      srv.request.id = id;
      record.what = "ping " + std::to_string(id);
      if (timedCall(ping_, srv, &record)) {
        record.success = srv.response.online;
        record.message = srv.response.message;
      }
    } else {
      srd::ServoRead srv;
      srv.request.id = id;
      srv.request.param = "voltage";
      record.what = "read voltage " + std::to_string(id);
      if (timedCall(read_, srv, &record)) {
        record.success = srv.response.success;
        record.message = srv.response.message;
      }
    }
    record.as_expected = record.returned && !record.success &&
                         record.message.find("did not answer") != std::string::npos;
    return record;
  }

  CallRecord onlineCall(int i) {
    // The low thread owns servos 0 and 1, the high thread servo 2: each writes only its own, so
    // read_all can check the value it last wrote.
    const uint8_t id = role_ == Role::kOnlineLow ? kOnlineIds[(i / 5) % 2] : kOnlineIds[2];
    CallRecord record;
    switch (i % 5) {
      case 0: {
        srd::ServoPing srv;
        srv.request.id = kOnlineIds[i % kOnlineIds.size()];  // any online servo
        record.what = "ping " + std::to_string(srv.request.id);
        if (timedCall(ping_, srv, &record)) {
          record.success = srv.response.online;
          record.message = srv.response.message;
          record.as_expected = record.success;
        }
        break;
      }
      case 1: {
        srd::ServoRead srv;
        srv.request.id = id;
        srv.request.param = "voltage";
        record.what = "read voltage " + std::to_string(id);
        if (timedCall(read_, srv, &record)) {
          record.success = srv.response.success;
          record.message = srv.response.message;
          record.as_expected =
              record.success && srv.response.unit == "mV" && srv.response.value > 0;
        }
        break;
      }
      case 2: {
        srd::ServoWrite srv;
        srv.request.id = id;
        srv.request.param = "soft_start_time";
        srv.request.value = 100 + i + (role_ == Role::kOnlineHigh ? 1000 : 0);
        record.what = "write soft_start_time " + std::to_string(id);
        if (timedCall(write_, srv, &record)) {
          record.success = srv.response.success;
          record.message = srv.response.message;
          record.as_expected = record.success;
          if (record.success) written_[id] = srv.request.value;
        }
        break;
      }
      case 3: {
        srd::ServoReadAngle srv;
        srv.request.id = id;
        record.what = "read_angle " + std::to_string(id);
        if (timedCall(read_angle_, srv, &record)) {
          record.success = srv.response.success;
          record.message = srv.response.message;
          record.as_expected = record.success && std::isfinite(srv.response.angle_deg);
        }
        break;
      }
      default: {
        srd::ServoReadAll srv;
        srv.request.id = id;
        record.what = "read_all " + std::to_string(id);
        if (timedCall(read_all_, srv, &record)) {
          record.success = srv.response.success;
          record.message = srv.response.message;
          record.as_expected =
              record.success && srv.response.names.size() == 22 && srv.response.values.size() == 22;
          const auto it =
              std::find(srv.response.names.begin(), srv.response.names.end(), "soft_start_time");
          if (record.as_expected && written_.count(id) > 0) {
            const bool found = it != srv.response.names.end();
            const int64_t value = found ? srv.response.values[it - srv.response.names.begin()] : -1;
            if (value != written_[id]) {
              record.as_expected = false;
              record.message += " [soft_start_time " + std::to_string(value) + ", last written " +
                                std::to_string(written_[id]) + "]";
            }
          }
        }
        break;
      }
    }
    return record;
  }

  ros::NodeHandle nh_;
  const Role role_;
  ros::ServiceClient ping_, read_, write_, read_angle_, read_all_;
  std::map<uint8_t, int64_t> written_;
  mutable std::mutex records_mutex_;
  std::vector<CallRecord> records_;
  std::atomic<std::size_t> started_{0};
  std::atomic<bool> done_{false};
  std::thread thread_;
};

inline double paramOr(const std::string& name, double fallback) {
  double value = fallback;
  ros::param::get(name, value);
  return value;
}

}  // namespace servo_stress_test
