// floor_node: the least any roscpp driver of this robot must do, as the yardstick of driver_bench.
// Benchmark only, never installed. It reads the same parameters as driver_node for what it does:
// ~port, ~loop_rate, ~base/enabled, ~body/enabled, ~body/servo_ids, ~body/joint_names,
// ~body/zero_ticks, ~body/directions, ~body/ticks_per_revolution, ~realtime_priority (1..99, or
// true for 50: SCHED_FIFO on the reader and loop threads, memory locked, as driver_node does).
//
// Threading: one reader thread blocks on the port, frames telemetry and publishes one JointState
// per frame; the cmd_vel callback (ros::spin thread) writes its speed frame at once; the main
// thread writes the speed frame every loop period on absolute clock_nanosleep deadlines. Writes
// from the two writers are serialised by one mutex. No validation, diagnostics or services.
#include <fcntl.h>
#include <geometry_msgs/Twist.h>
#include <pthread.h>
#include <ros/ros.h>
#include <sched.h>
#include <sensor_msgs/JointState.h>
#include <sys/mman.h>
#include <termios.h>
#include <time.h>
#include <unistd.h>

#include <atomic>
#include <cstdint>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "serial_robot_driver/devices/base/base_codec.h"
#include "serial_robot_driver/devices/body/body_codec.h"
#include "serial_robot_driver/devices/body/body_controller.h"
#include "serial_robot_driver/kinematics/diff_drive.h"
#include "serial_robot_driver/protocol/stream_framer.h"
#include "support/framer_configs.h"

namespace srd = serial_robot_driver;

namespace {

std::atomic<bool> g_running{true};
int g_fd = -1;
std::mutex g_write_mutex;
std::atomic<int16_t> g_left{0}, g_right{0};
uint8_t g_seq = 0;  // guarded by g_write_mutex

void writeSpeedFrame() {
  std::lock_guard<std::mutex> lock(g_write_mutex);
  const auto frame = srd::devices::base::encodeWheelSpeed(g_seq++, g_left, g_right);
  if (::write(g_fd, frame.data(), frame.size()) < 0) { /* the floor does not handle errors */
  }
}

/// ~realtime_priority: an integer priority, or true for 50; 0 (or absent, or false) is off.
int realtimePriority(ros::NodeHandle& pnh) {
  int priority = 0;
  if (pnh.getParam("realtime_priority", priority)) return priority;
  bool on = false;
  return pnh.getParam("realtime_priority", on) && on ? 50 : 0;
}

/// SCHED_FIFO at `priority` for the calling thread (0: nothing); says so when not allowed.
void runRealtime(int priority, const char* thread) {
  if (priority <= 0) return;
  sched_param param{};
  param.sched_priority = priority;
  const int error = ::pthread_setschedparam(::pthread_self(), SCHED_FIFO, &param);
  if (error != 0) ROS_WARN("floor: %s thread: SCHED_FIFO %d not allowed", thread, priority);
}

/// The body's joints as ~body/* gives them.
struct BodyJoints {
  std::vector<int> ids;
  std::vector<std::string> names;
  std::vector<srd::devices::body::JointCalibration> calibrations;
};

BodyJoints readBodyJoints(ros::NodeHandle& pnh) {
  BodyJoints joints;
  std::vector<int> zeros, directions;
  pnh.getParam("body/servo_ids", joints.ids);
  pnh.getParam("body/joint_names", joints.names);
  pnh.getParam("body/zero_ticks", zeros);
  pnh.getParam("body/directions", directions);
  joints.calibrations.resize(joints.ids.size());
  for (std::size_t i = 0; i < joints.ids.size(); ++i) {
    if (i < zeros.size()) joints.calibrations[i].zero_ticks = zeros[i];
    if (i < directions.size()) joints.calibrations[i].direction = directions[i];
    joints.calibrations[i].ticks_per_revolution = pnh.param("body/ticks_per_revolution", 4096);
  }
  joints.names.resize(joints.ids.size());
  return joints;
}

/// Opens the port raw, blocking reads of at least one byte; false when it cannot be opened.
bool openRawPort(const std::string& port) {
  g_fd = ::open(port.c_str(), O_RDWR | O_NOCTTY);
  if (g_fd < 0) return false;
  termios tio{};
  ::tcgetattr(g_fd, &tio);
  ::cfmakeraw(&tio);
  tio.c_cc[VMIN] = 1;
  tio.c_cc[VTIME] = 0;
  ::tcsetattr(g_fd, TCSANOW, &tio);
  return true;
}

/// cmd_vel: the wheel speeds, written at once.
ros::Subscriber subscribeCmdVel(ros::NodeHandle& nh,
                                const srd::kinematics::DiffDriveGeometry& geometry) {
  return nh.subscribe<geometry_msgs::Twist>(
      "cmd_vel", 10, [&geometry](const geometry_msgs::Twist::ConstPtr& twist) {
        const auto speeds =
            srd::kinematics::wheelSpeedsFromTwist(geometry, twist->linear.x, twist->angular.z);
        g_left = static_cast<int16_t>(speeds[0] * geometry.ticksPerPeriodPerMps());
        g_right = static_cast<int16_t>(speeds[1] * geometry.ticksPerPeriodPerMps());
        writeSpeedFrame();
      });
}

/// The reader thread: one JointState per telemetry frame, until g_running ends.
void publishTelemetry(const BodyJoints& joints, ros::Publisher& joint_states) {
  const std::size_t count = joints.ids.size();
  const auto config = test_support::driverFramer({"body"}, count);
  srd::protocol::StreamFramer framer(config, [&](auto family, const uint8_t* data,
                                                 std::size_t size) {
    if (family != srd::devices::body::kTelemetryFrames) return;
    const auto telemetry = srd::devices::body::decodeTelemetry(data, size, count);
    if (!telemetry) return;
    sensor_msgs::JointState msg;
    msg.header.stamp = ros::Time::now();
    msg.name = joints.names;
    for (std::size_t i = 0; i < count; ++i) {
      msg.position.push_back(joints.calibrations[i].toRadians(telemetry->servos[i].position));
      msg.velocity.push_back(joints.calibrations[i].toRadiansPerSecond(telemetry->servos[i].speed));
    }
    joint_states.publish(msg);
  });
  uint8_t buffer[1024];
  while (g_running) {
    const ssize_t got = ::read(g_fd, buffer, sizeof(buffer));
    if (got > 0) framer.feed(buffer, static_cast<std::size_t>(got));
  }
}

/// The speed frame every loop period on absolute deadlines, until ROS shuts down.
void runBaseLoop(double loop_rate) {
  const long period_ns = static_cast<long>(1e9 / loop_rate);
  timespec deadline{};
  ::clock_gettime(CLOCK_MONOTONIC, &deadline);
  while (ros::ok()) {
    deadline.tv_nsec += period_ns;
    while (deadline.tv_nsec >= 1000000000L) {
      deadline.tv_nsec -= 1000000000L;
      ++deadline.tv_sec;
    }
    ::clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &deadline, nullptr);
    writeSpeedFrame();
  }
}

}  // namespace

int main(int argc, char** argv) {
  ros::init(argc, argv, "floor");
  ros::NodeHandle nh, pnh("~");
  const std::string port = pnh.param<std::string>("port", "/dev/ttyUSB0");
  const double loop_rate = pnh.param("loop_rate", 50.0);
  const bool base = pnh.param("base/enabled", true);
  const bool body = pnh.param("body/enabled", true);
  const BodyJoints joints = readBodyJoints(pnh);
  const int priority = realtimePriority(pnh);
  if (priority > 0 && ::mlockall(MCL_CURRENT | MCL_FUTURE) != 0) ROS_WARN("floor: mlockall failed");
  if (!openRawPort(port)) {
    ROS_FATAL("floor: cannot open %s", port.c_str());
    return 1;
  }

  ros::Publisher joint_states = nh.advertise<sensor_msgs::JointState>("joint_states", 10);
  const srd::kinematics::DiffDriveGeometry geometry;
  ros::Subscriber cmd_vel;
  if (base) cmd_vel = subscribeCmdVel(nh, geometry);
  std::thread reader;
  if (body) {
    reader = std::thread([&] {
      runRealtime(priority, "reader");
      publishTelemetry(joints, joint_states);
    });
  }

  ros::AsyncSpinner spinner(1);
  spinner.start();
  if (base) {
    runRealtime(priority, "loop");
    runBaseLoop(loop_rate);
  } else {
    ros::waitForShutdown();
  }
  // The reader blocks in read(); the process exits without joining it.
  g_running = false;
  reader.detach();
  return 0;
}
