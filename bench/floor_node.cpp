// floor_node: the least any roscpp driver of this robot must do, as the yardstick of driver_bench.
// Benchmark only, never installed. It reads the same parameters as driver_node for what it does:
// ~port (a tty, or tcp://HOST:PORT: a TCP connection with TCP_NODELAY, raw bytes, as to ser2net;
// a lost connection ends the floor), ~loop_rate, ~base/enabled, ~body/enabled, ~body/servo_ids,
// ~body/joint_names, ~body/zero_ticks, ~body/directions, ~body/ticks_per_revolution,
// ~realtime_priority (1..99, or true for 50: SCHED_FIFO on the main thread before roscpp starts its
// threads, so every thread inherits it, as driver_node does; memory locked), ~scheduler_slice_us
// (default 0: the kernel's slice, as a minimal driver has it; else asked for on the main thread
// before roscpp starts its threads, as driver_node does: core/scheduler_slice.h).
// ~same_job (default false: the minimal floor) makes it do the job a user's driver_node does, as
// minimally as possible: besides joint_states, imu/data per telemetry frame, odom + /tf +
// wheel_states per loop tick (the commanded motion integrated), and /diagnostics at 1 Hz with
// ~same_job_statuses statuses carrying ~same_job_values key/values in all.
// ~same_interface (default false) adds the rest of driver_node's interface, each piece doing
// nothing but exist (floor_interface.h: its other publications, subscriptions, dynamic_reconfigure
// servers and action server), and the base's battery poll (~base/battery_poll_rate, 1 Hz: a request
// written on the loop, the reply framed): the least a node offering driver_node's interface
// spends on it whoever listens.
//
// Threading: one reader thread ("floor_reader") blocks on the port, frames telemetry and
// publishes one JointState (and one Imu) per frame; the cmd_vel callback (the AsyncSpinner's
// thread) writes its speed frame at once; the main thread writes the speed frame (and publishes
// odom, /tf, wheel_states) every loop period on absolute clock_nanosleep deadlines; the diagnostics
// timer runs on the spinner's thread. Writes from the two writers are serialised by one mutex. No
// validation or services.
#include <diagnostic_msgs/DiagnosticArray.h>
#include <fcntl.h>
#include <geometry_msgs/Twist.h>
#include <nav_msgs/Odometry.h>
#include <netdb.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <pthread.h>
#include <ros/ros.h>
#include <sched.h>
#include <sensor_msgs/Imu.h>
#include <sensor_msgs/JointState.h>
#include <signal.h>
#include <sys/mman.h>
#include <sys/socket.h>
#include <termios.h>
#include <tf2_msgs/TFMessage.h>
#include <time.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <algorithm>
#include <cstdio>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "floor_interface.h"
#include "serial_robot_driver/core/scheduler_slice.h"
#include "serial_robot_driver/devices/base/base_codec.h"
#include "serial_robot_driver/devices/body/body_codec.h"
#include "serial_robot_driver/devices/body/body_controller.h"
#include "serial_robot_driver/devices/body/body_readings.h"
#include "serial_robot_driver/kinematics/diff_drive.h"
#include "serial_robot_driver/protocol/stream_framer.h"
#include "support/framer_configs.h"

namespace srd = serial_robot_driver;

namespace {

std::atomic<bool> g_running{true};
int g_fd = -1;
std::mutex g_write_mutex;
std::atomic<int16_t> g_left{0}, g_right{0};
std::atomic<double> g_linear{0.0}, g_angular{0.0};  // the twist commanded last (same job)
uint8_t g_seq = 0;  // guarded by g_write_mutex
int g_battery_every = 0;  // ~same_interface: a battery request every this many loop ticks; 0: none

/// ~same_job's publishers (advertised only with it on).
struct SameJob {
  bool on = false;
  int statuses = 5;
  int values = 0;  ///< key/values in all, spread over the statuses
  unsigned long values_sent = 0;
  ros::Publisher imu, odom, tf, wheel_states, diagnostics;
  ros::SteadyTimer diagnostics_timer;
};

void writeFrame(const std::vector<uint8_t>& frame) {
  if (::write(g_fd, frame.data(), frame.size()) < 0) { /* the floor does not handle errors */
  }
}

void writeSpeedFrame() {
  std::lock_guard<std::mutex> lock(g_write_mutex);
  writeFrame(srd::devices::base::encodeWheelSpeed(g_seq++, g_left, g_right));
}

/// ~same_interface: the battery request, every g_battery_every loop ticks.
void pollBattery(long tick) {
  if (g_battery_every <= 0 || tick % g_battery_every != 0) return;
  std::lock_guard<std::mutex> lock(g_write_mutex);
  writeFrame(srd::devices::base::encodeBatteryRequest(g_seq++));
}

/// ~realtime_priority: an integer priority, or true for 50; 0 (or absent, or false) is off. Read
/// before any NodeHandle exists (ros::param needs none), so no roscpp thread runs yet.
int realtimePriority() {
  int priority = 0;
  if (ros::param::get("~realtime_priority", priority)) return priority;
  bool on = false;
  return ros::param::get("~realtime_priority", on) && on ? 50 : 0;
}

/// SCHED_FIFO at `priority` for the calling thread (0: nothing); says so when not allowed. On the
/// main thread before roscpp starts its threads: the reader, the loop, the spinner and roscpp's
/// own (poll, timers, XML-RPC) inherit it, as driver_node's do.
void runRealtime(int priority) {
  if (priority <= 0) return;
  if (::mlockall(MCL_CURRENT | MCL_FUTURE) != 0) std::fprintf(stderr, "floor: mlockall failed\n");
  sched_param param{};
  param.sched_priority = priority;
  const int error = ::pthread_setschedparam(::pthread_self(), SCHED_FIFO, &param);
  if (error != 0) std::fprintf(stderr, "floor: SCHED_FIFO %d not allowed\n", priority);
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

/// Connects to tcp://HOST:PORT with TCP_NODELAY (each speed frame sent as written); false when
/// the URL is malformed or nobody accepts.
bool connectTcp(const std::string& url) {
  const std::string address = url.substr(6);  // after "tcp://"
  const std::size_t colon = address.rfind(':');
  if (colon == std::string::npos) return false;
  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_STREAM;
  addrinfo* found = nullptr;
  if (::getaddrinfo(address.substr(0, colon).c_str(), address.substr(colon + 1).c_str(), &hints,
                    &found) != 0) {
    return false;
  }
  for (const addrinfo* candidate = found; candidate && g_fd < 0; candidate = candidate->ai_next) {
    g_fd = ::socket(candidate->ai_family, candidate->ai_socktype, candidate->ai_protocol);
    if (g_fd >= 0 && ::connect(g_fd, candidate->ai_addr, candidate->ai_addrlen) != 0) {
      ::close(g_fd);
      g_fd = -1;
    }
  }
  ::freeaddrinfo(found);
  if (g_fd < 0) return false;
  const int on = 1;
  ::setsockopt(g_fd, IPPROTO_TCP, TCP_NODELAY, &on, sizeof(on));
  ::signal(SIGPIPE, SIG_IGN);  // a write to a closed connection fails instead
  return true;
}

/// Opens the port raw, blocking reads of at least one byte (or connects, for tcp://); false when
/// it cannot be opened.
bool openRawPort(const std::string& port) {
  if (port.rfind("tcp://", 0) == 0) return connectTcp(port);
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
        g_linear = twist->linear.x;
        g_angular = twist->angular.z;
        g_left = static_cast<int16_t>(speeds[0] * geometry.ticksPerPeriodPerMps());
        g_right = static_cast<int16_t>(speeds[1] * geometry.ticksPerPeriodPerMps());
        writeSpeedFrame();
      });
}

/// Same job: one frame's IMU values as imu/data (the core's scaling, no bias, no covariances).
void publishImu(const srd::devices::body::Telemetry& telemetry, const ros::Time& stamp,
                ros::Publisher& imu) {
  const srd::devices::body::ImuReading reading =
      srd::devices::body::imuReading(telemetry, srd::devices::body::ImuParams{});
  sensor_msgs::Imu msg;
  msg.header.stamp = stamp;
  msg.header.frame_id = "imu_link";
  msg.orientation.w = reading.orientation.w;
  msg.orientation.x = reading.orientation.x;
  msg.orientation.y = reading.orientation.y;
  msg.orientation.z = reading.orientation.z;
  msg.angular_velocity.x = reading.angular_velocity.x();
  msg.angular_velocity.y = reading.angular_velocity.y();
  msg.angular_velocity.z = reading.angular_velocity.z();
  msg.linear_acceleration.x = reading.linear_acceleration.x();
  msg.linear_acceleration.y = reading.linear_acceleration.y();
  msg.linear_acceleration.z = reading.linear_acceleration.z();
  imu.publish(msg);
}

/// The reader thread: one JointState (and with ~same_job one Imu) per telemetry frame, until
/// g_running ends or the connection is lost (then the floor ends).
void publishTelemetry(const BodyJoints& joints, ros::Publisher& joint_states, SameJob& job) {
  const std::size_t count = joints.ids.size();
  // With the battery poll its replies are framed too (and dropped: nobody listens to battery).
  const auto config =
      test_support::driverFramer(g_battery_every > 0 ? std::vector<std::string>{"base", "body"}
                                                     : std::vector<std::string>{"body"},
                                 count);
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
    if (job.on) publishImu(*telemetry, msg.header.stamp, job.imu);
  });
  uint8_t buffer[1024];
  while (g_running) {
    const ssize_t got = ::read(g_fd, buffer, sizeof(buffer));
    if (got > 0) {
      framer.feed(buffer, static_cast<std::size_t>(got));
    } else if (got == 0 || errno != EINTR) {
      ROS_ERROR("floor: the port is lost (%s); the floor ends", got == 0 ? "closed" : "read error");
      ros::requestShutdown();
      return;
    }
  }
}

/// Same job: the commanded motion integrated over one loop period, published as odom, its
/// transform on /tf and the wheels' angles on wheel_states.
class SameJobOdometry {
 public:
  SameJobOdometry(SameJob& job, const srd::kinematics::DiffDriveGeometry& geometry)
      : job_(job), geometry_(geometry) {
    wheels_.name = {"left_wheel_joint", "right_wheel_joint"};
    wheels_.position = {0.0, 0.0};
    wheels_.velocity = {0.0, 0.0};
  }

  void tick(double dt) {
    const double linear = g_linear, angular = g_angular;
    x_ += linear * std::cos(yaw_) * dt;
    y_ += linear * std::sin(yaw_) * dt;
    yaw_ += angular * dt;
    const auto speeds = srd::kinematics::wheelSpeedsFromTwist(geometry_, linear, angular);
    const ros::Time stamp = ros::Time::now();
    nav_msgs::Odometry odom;
    odom.header.stamp = stamp;
    odom.header.frame_id = "odom";
    odom.child_frame_id = "base_link";
    odom.pose.pose.position.x = x_;
    odom.pose.pose.position.y = y_;
    odom.pose.pose.orientation.z = std::sin(yaw_ / 2);
    odom.pose.pose.orientation.w = std::cos(yaw_ / 2);
    odom.twist.twist.linear.x = linear;
    odom.twist.twist.angular.z = angular;
    job_.odom.publish(odom);
    tf2_msgs::TFMessage tf;
    tf.transforms.resize(1);
    tf.transforms[0].header = odom.header;
    tf.transforms[0].child_frame_id = odom.child_frame_id;
    tf.transforms[0].transform.translation.x = x_;
    tf.transforms[0].transform.translation.y = y_;
    tf.transforms[0].transform.rotation = odom.pose.pose.orientation;
    job_.tf.publish(tf);
    wheels_.header.stamp = stamp;
    for (int i = 0; i < 2; ++i) {
      wheels_.velocity[i] = speeds[i] / (geometry_.wheel_diameter / 2);
      wheels_.position[i] += wheels_.velocity[i] * dt;
    }
    job_.wheel_states.publish(wheels_);
  }

 private:
  SameJob& job_;
  const srd::kinematics::DiffDriveGeometry& geometry_;
  double x_ = 0, y_ = 0, yaw_ = 0;
  sensor_msgs::JointState wheels_;
};

/// Same job: /diagnostics once a second, job.statuses statuses (as many as driver_node's).
void startDiagnostics(ros::NodeHandle& nh, SameJob& job) {
  job.diagnostics_timer = nh.createSteadyTimer(ros::WallDuration(1.0), [&job](const auto&) {
    diagnostic_msgs::DiagnosticArray array;
    array.header.stamp = ros::Time::now();
    array.status.resize(static_cast<std::size_t>(std::max(0, job.statuses)));
    for (std::size_t i = 0; i < array.status.size(); ++i) {
      array.status[i].name = "floor: status " + std::to_string(i);
      array.status[i].message = "OK";
      array.status[i].hardware_id = "floor";
    }
    // driver_node's values are counters and settings: a number each, under a fixed key.
    for (int v = 0; v < job.values && !array.status.empty(); ++v) {
      diagnostic_msgs::KeyValue value;
      value.key = "value " + std::to_string(v);
      value.value = std::to_string(job.values_sent++);
      array.status[v % array.status.size()].values.push_back(std::move(value));
    }
    job.diagnostics.publish(array);
  });
}

/// Advertises ~same_job's topics and starts its diagnostics (nothing without it).
void advertiseSameJob(ros::NodeHandle& nh, ros::NodeHandle& pnh, SameJob& job) {
  job.on = pnh.param("same_job", false);
  job.statuses = pnh.param("same_job_statuses", job.statuses);
  job.values = pnh.param("same_job_values", job.values);
  if (!job.on) return;
  job.imu = nh.advertise<sensor_msgs::Imu>("imu/data", 10);
  job.odom = nh.advertise<nav_msgs::Odometry>("odom", 50);
  job.tf = ros::NodeHandle().advertise<tf2_msgs::TFMessage>("/tf", 100);
  job.wheel_states = nh.advertise<sensor_msgs::JointState>("wheel_states", 50);
  job.diagnostics =
      ros::NodeHandle().advertise<diagnostic_msgs::DiagnosticArray>("/diagnostics", 1);
  startDiagnostics(nh, job);
}

/// The speed frame every loop period on absolute deadlines (with ~same_job the odometry's topics
/// after it), until ROS shuts down.
void runBaseLoop(double loop_rate, SameJobOdometry* odometry) {
  const long period_ns = static_cast<long>(1e9 / loop_rate);
  timespec deadline{};
  ::clock_gettime(CLOCK_MONOTONIC, &deadline);
  for (long tick = 1; ros::ok(); ++tick) {
    deadline.tv_nsec += period_ns;
    while (deadline.tv_nsec >= 1000000000L) {
      deadline.tv_nsec -= 1000000000L;
      ++deadline.tv_sec;
    }
    ::clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &deadline, nullptr);
    pollBattery(tick);
    writeSpeedFrame();
    if (odometry) odometry->tick(1.0 / loop_rate);
  }
}

}  // namespace

int main(int argc, char** argv) {
  ros::init(argc, argv, "floor");
  srd::core::requestSchedulerSlice(ros::param::param("~scheduler_slice_us", 0));  // before threads
  runRealtime(realtimePriority());
  ros::NodeHandle nh, pnh("~");
  const std::string port = pnh.param<std::string>("port", "/dev/ttyUSB0");
  const double loop_rate = pnh.param("loop_rate", 50.0);
  const bool base = pnh.param("base/enabled", true);
  const bool body = pnh.param("body/enabled", true);
  const BodyJoints joints = readBodyJoints(pnh);
  if (!openRawPort(port)) {
    ROS_FATAL("floor: cannot open %s", port.c_str());
    return 1;
  }

  ros::Publisher joint_states = nh.advertise<sensor_msgs::JointState>("joint_states", 10);
  SameJob job;
  advertiseSameJob(nh, pnh, job);
  std::unique_ptr<floor_bench::FloorInterface> interface;
  if (pnh.param("same_interface", false)) {
    interface = std::make_unique<floor_bench::FloorInterface>(nh, pnh);
    const double battery_rate = pnh.param("base/battery_poll_rate", 1.0);
    if (base && battery_rate > 0)
      g_battery_every = std::max(1, static_cast<int>(loop_rate / battery_rate));
  }
  const srd::kinematics::DiffDriveGeometry geometry;
  ros::Subscriber cmd_vel;
  if (base) cmd_vel = subscribeCmdVel(nh, geometry);
  std::thread reader;
  if (body) {
    reader = std::thread([&] {
      // For driver_bench's CPU by thread; the loop is the main thread (named as the process).
      ::pthread_setname_np(::pthread_self(), "floor_reader");
      publishTelemetry(joints, joint_states, job);
    });
  }

  ros::AsyncSpinner spinner(1);
  spinner.start();
  if (base) {
    SameJobOdometry odometry(job, geometry);
    runBaseLoop(loop_rate, job.on ? &odometry : nullptr);
  } else {
    ros::waitForShutdown();
  }
  // The reader blocks in read(); the process exits without joining it.
  g_running = false;
  reader.detach();
  return 0;
}
