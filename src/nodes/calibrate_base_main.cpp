// calibrate_base: turns the running robot in place both ways, compares the IMU's yaw with the turn
// its wheel frames commanded and prints the effective wheel separation (docs/calibration.md).
// A client of the node's topics, never a node service: the user sees progress, Ctrl-C stops it,
// it ties up none of the node's threads, and if it is killed hard the node's own
// ~base/cmd_vel_timeout stops the base. The estimator is the core's
// (devices/base/turn_calibration); this file only wires topics to it and sequences the run.
#include <diagnostic_msgs/DiagnosticArray.h>
#include <geometry_msgs/Twist.h>
#include <ros/ros.h>
#include <sensor_msgs/Imu.h>

#include <atomic>
#include <csignal>
#include <cstdio>
#include <iostream>
#include <optional>
#include <string>

#include "serial_robot_driver/WheelCommand.h"
#include "serial_robot_driver/devices/base/turn_calibration.h"
#include "serial_robot_driver/ros/driver_params.h"

namespace {

using serial_robot_driver::device::MotionRecord;
using serial_robot_driver::device::MotionRecorder;
using serial_robot_driver::kinematics::DiffDriveGeometry;

constexpr int kExitRefused = 1;
constexpr int kExitUsage = 2;

const char* const kUsage = R"(usage: rosrun serial_robot_driver calibrate_base [options]

Turns the robot in place counter-clockwise, then clockwise, compares the IMU's yaw (imu/data)
with the turn the wheel frames commanded (wheel_command) and prints the effective
wheel_separation. Nothing is written to the node or the config: the tool prints the value, the
command to try it now and the line to keep it. Needs telemetry and the e-stop released; Ctrl-C
stops the base and exits. Run it in the driver's namespace (ROS_NAMESPACE=... for a fleet).

  --rate RAD_S      turning rate (default 1.0)
  --angle RAD       how far each turn goes, commanded (default 6.283: a full turn)
  --distance M      also drive this far straight ahead (commanded) and ask for the distance
                    really travelled: prints the effective wheel_diameter (default 0: no)
  --speed M_S       speed of the straight run (default 0.2)
  --measured M      the measured distance of the straight run, instead of asking for it
  --node NAME       the driver node (default: the node publishing wheel_command)
  --settle S        rest before and after each motion (default 0.5)
  --help            this text
)";

struct Options {
  double rate = 1.0;
  double angle = 2 * M_PI;
  double distance = 0.0;
  double speed = 0.2;
  std::optional<double> measured;
  std::string node;
  double settle = 0.5;
};

/// Parses the options after ros::init removed the ROS remappings; nullopt (after printing why)
/// on a bad one.
std::optional<Options> parseOptions(int argc, char** argv, bool* help) {
  Options options;
  auto number = [&](int& i, double low, double high, double* out) {
    const std::string name = argv[i];
    if (i + 1 >= argc) {
      std::cerr << name << " needs a value\n";
      return false;
    }
    char* end = nullptr;
    const double value = std::strtod(argv[++i], &end);
    if (*end != '\0' || !(value >= low && value <= high)) {
      std::cerr << name << " must be a number in " << low << ".." << high << ", not " << argv[i]
                << "\n";
      return false;
    }
    *out = value;
    return true;
  };
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    double measured = 0;
    bool ok = true;
    if (arg == "--help" || arg == "-h") {
      *help = true;
      return options;
    } else if (arg == "--rate") {
      ok = number(i, 0.05, 5.0, &options.rate);
    } else if (arg == "--angle") {
      ok = number(i, 0.5, 40.0, &options.angle);
    } else if (arg == "--distance") {
      ok = number(i, 0.0, 20.0, &options.distance);
    } else if (arg == "--speed") {
      ok = number(i, 0.02, 2.0, &options.speed);
    } else if (arg == "--measured") {
      ok = number(i, 0.0, 40.0, &measured);
      options.measured = measured;
    } else if (arg == "--settle") {
      ok = number(i, 0.1, 5.0, &options.settle);
    } else if (arg == "--node" && i + 1 < argc) {
      options.node = argv[++i];
    } else {
      std::cerr << "unknown option " << arg << " (--help lists them)\n";
      ok = false;
    }
    if (!ok) return std::nullopt;
  }
  return options;
}

std::atomic<int> g_signal{0};
void onSignal(int signal_number) { g_signal = signal_number; }

void say(const std::string& text) { std::cout << text << std::endl; }
std::string fixed(double value, int digits = 4) {
  char text[64];
  std::snprintf(text, sizeof text, "%.*f", digits, value);
  return text;
}

/// Why the run stopped early: printed, then the exit status.
struct Abort {
  std::string message;
  int exit_code = kExitRefused;
};

class CalibrationRun {
 public:
  explicit CalibrationRun(const Options& options) : options_(options) {
    cmd_vel_ = nh_.advertise<geometry_msgs::Twist>("cmd_vel", 10);
    imu_sub_ = nh_.subscribe("imu/data", 100, &CalibrationRun::onImu, this);
    wheel_sub_ = nh_.subscribe("wheel_command", 100, &CalibrationRun::onWheelCommand, this);
    diagnostics_sub_ = nh_.subscribe("/diagnostics", 20, &CalibrationRun::onDiagnostics, this);
  }

  /// The whole run; the base is stopped on every way out of it.
  int run() {
    try {
      prepare();
      const MotionRecord ccw = move("turning counter-clockwise", 0.0, options_.rate);
      const MotionRecord cw = move("turning clockwise", 0.0, -options_.rate);
      report(ccw, cw);
      return 0;
    } catch (const Abort& abort) {
      std::cerr << "calibrate_base: " << abort.message << std::endl;
      if (moved_) stopBase();
      return abort.exit_code;
    } catch (const std::exception& error) {  // a ROS error mid-run: still stop the base
      std::cerr << "calibrate_base: " << error.what() << std::endl;
      if (moved_) stopBase();
      return kExitRefused;
    }
  }

 private:
  void onImu(const sensor_msgs::Imu& msg) {
    last_imu_ = ros::WallTime::now();
    if (recorder_) recorder_->addImuRate(msg.header.stamp.toSec(), msg.angular_velocity.z);
    last_imu_stamp_ = msg.header.stamp.toSec();
  }
  void onWheelCommand(const serial_robot_driver::WheelCommand& msg) {
    last_frame_ = ros::WallTime::now();
    last_frame_zero_ = msg.left_ticks == 0 && msg.right_ticks == 0;
    if (last_frame_zero_) ++zero_frames_;
    if (recorder_)
      recorder_->addWheelFrame(msg.header.stamp.toSec(), msg.left_ticks, msg.right_ticks);
  }
  void onDiagnostics(const diagnostic_msgs::DiagnosticArray& msg) {
    for (const auto& status : msg.status) {
      if (status.name != e_stop_status_name_) continue;
      for (const auto& value : status.values) {
        if (value.key == "engaged") e_stop_engaged_ = value.value == "True";
      }
    }
  }

  /// Spins for up to `seconds`, until `done` holds; false on a timeout. A signal aborts.
  template <typename Done>
  bool spinUntil(double seconds, Done done) {
    const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(seconds);
    while (ros::WallTime::now() < deadline) {
      checkSignal();
      ros::spinOnce();
      if (done()) return true;
      ros::WallDuration(0.01).sleep();
    }
    return false;
  }
  void checkSignal() const {
    if (g_signal != 0) {
      throw Abort{std::string(g_signal == SIGINT ? "interrupted (SIGINT)" : "terminated"),
                  128 + g_signal};
    }
    if (!ros::ok()) throw Abort{"ROS shut down", kExitRefused};
  }

  std::string findNode() {
    if (!options_.node.empty()) return ros::names::resolve(options_.node);
    const std::string topic = ros::names::resolve("wheel_command");
    std::string found;
    spinUntil(5.0, [&] {
      XmlRpc::XmlRpcValue args, result, payload;
      args[0] = ros::this_node::getName();
      if (!ros::master::execute("getSystemState", args, result, payload, false)) return false;
      for (int i = 0; i < payload[0].size(); ++i) {
        if (std::string(payload[0][i][0]) != topic) continue;
        if (payload[0][i][1].size() > 1) {
          throw Abort{"several nodes publish " + topic + ": name the driver with --node"};
        }
        if (payload[0][i][1].size() == 1) found = std::string(payload[0][i][1][0]);
      }
      return !found.empty();
    });
    if (found.empty()) {
      throw Abort{"no driver publishes " + topic +
                  ": start it first (roslaunch serial_robot_driver sim.launch), or run the tool in "
                  "its namespace (ROS_NAMESPACE=...)"};
    }
    return found;
  }

  /// The base's configuration in force: the node's parameters read as the node reads them (a key
  /// left out of its config has the node's default), so ticks convert exactly as they were made.
  serial_robot_driver::device::BaseConfig nodeBaseConfig() const {
    try {
      return serial_robot_driver::ros_layer::loadParams(ros::NodeHandle(node_), nullptr)
          .base.controller;
    } catch (const std::exception& error) {
      throw Abort{"cannot read the parameters of " + node_ + ": " + error.what()};
    }
  }

  /// The refusals before anything moves: no driver, no base, no telemetry, the e-stop.
  void prepare() {
    node_ = findNode();
    e_stop_status_name_ = node_.substr(1) + ": e_stop";  // the updater's prefix has no slash
    const serial_robot_driver::device::BaseConfig base = nodeBaseConfig();
    geometry_ = base.geometry;
    left_direction_ = base.left_wheel_direction;
    right_direction_ = base.right_wheel_direction;
    say("driver " + node_ + ": wheel_separation " + fixed(geometry_.wheel_separation) +
        " m, wheel_diameter " + fixed(geometry_.wheel_diameter) + " m");
    if (!spinUntil(3.0, [&] { return last_frame_.toSec() > 0; })) {
      throw Abort{"no wheel_command from " + node_ + " in 3 s: is the base enabled and connected?"};
    }
    if (!spinUntil(3.0, [&] { return last_imu_.toSec() > 0; })) {
      throw Abort{
          "refused: no telemetry on " + ros::names::resolve("imu/data") +
          " in 3 s; the turn is measured with the IMU (is the body enabled and streaming?)"};
    }
    // The node's diagnostics come once a second.
    if (!spinUntil(3.0, [&] { return e_stop_engaged_.has_value(); })) {
      throw Abort{"no e_stop status from " + node_ +
                  " on /diagnostics in 3 s: cannot tell "
                  "whether the e-stop is engaged"};
    }
    if (*e_stop_engaged_) {
      throw Abort{"refused: the e-stop is engaged; release it (e_stop false) and run again"};
    }
    spinUntil(2.0, [&] { return cmd_vel_.getNumSubscribers() > 0; });
    say("turning in place " + fixed(options_.angle, 2) + " rad each way at " +
        fixed(options_.rate, 2) + " rad/s; Ctrl-C stops the base");
  }

  void publish(double linear, double angular) {
    geometry_msgs::Twist twist;
    twist.linear.x = linear;
    twist.angular.z = angular;
    cmd_vel_.publish(twist);
  }

  /// Aborts a motion that can no longer be trusted or must not go on.
  void checkRunning() const {
    const ros::WallTime now = ros::WallTime::now();
    if (e_stop_engaged_.value_or(false)) throw Abort{"aborted: the e-stop engaged"};
    if ((now - last_imu_).toSec() > 0.5) {
      throw Abort{"aborted: telemetry stopped (no imu/data for 0.5 s)"};
    }
    if ((now - last_frame_).toSec() > 0.5) {
      throw Abort{"aborted: the node stopped writing wheel frames (no wheel_command for 0.5 s)"};
    }
  }

  /// Publishes zero until a zero frame is written after it (bounded); keeps publishing zero for
  /// `rest` more seconds. Throws when no stop could be confirmed.
  void holdStill(double rest) {
    const uint64_t zero_frames_before = zero_frames_;
    ros::WallTime next_publish;
    auto keepZero = [&] {
      if (ros::WallTime::now() >= next_publish) {
        publish(0, 0);
        next_publish = ros::WallTime::now() + ros::WallDuration(0.05);
      }
    };
    const bool stopped = spinUntil(
        3.0, [&] { return keepZero(), zero_frames_ > zero_frames_before && last_frame_zero_; });
    if (!stopped) {
      throw Abort{
          "no zero wheel frame written within 3 s of the stop; the node's "
          "~base/cmd_vel_timeout stops the base"};
    }
    spinUntil(rest, [&] { return keepZero(), false; });
  }

  /// One motion between two rests, recorded: a turn (angular != 0) until the wheel frames have
  /// commanded options_.angle, or a straight run until they have commanded options_.distance.
  MotionRecord move(const std::string& what, double linear, double angular) {
    moved_ = true;
    holdStill(options_.settle);
    recorder_.emplace(geometry_, left_direction_, right_direction_);
    const double goal = angular != 0 ? options_.angle : options_.distance;
    const double speed = angular != 0 ? std::abs(angular) : std::abs(linear);
    const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(goal / speed * 2 + 3);
    ros::WallTime next_progress = ros::WallTime::now();
    double done = 0;
    while (done < goal) {
      checkSignal();
      ros::spinOnce();
      checkRunning();
      if (ros::WallTime::now() > deadline) {
        throw Abort{what + ": the base did not get there in time (" + fixed(done, 2) + " of " +
                    fixed(goal, 2) + " commanded)"};
      }
      publish(linear, angular);
      const MotionRecord so_far = recorder_->finish(ros::Time::now().toSec());
      done = angular != 0 ? std::abs(so_far.commanded_yaw) : so_far.commanded_distance;
      if (ros::WallTime::now() >= next_progress) {
        say(what + ": " + fixed(done, 2) + " / " + fixed(goal, 2) + (angular != 0 ? " rad" : " m") +
            " commanded, IMU " + fixed(so_far.measured_yaw, 2) + " rad");
        next_progress += ros::WallDuration(0.5);
      }
      ros::WallDuration(0.02).sleep();
    }
    holdStill(options_.settle);
    checkRunning();
    const MotionRecord record = recorder_->finish(last_imu_stamp_);
    recorder_.reset();
    if (angular != 0) {
      say(what + ": done, commanded " + fixed(record.commanded_yaw, 3) + " rad, IMU measured " +
          fixed(record.measured_yaw, 3) + " rad (" + std::to_string(record.imu_samples) +
          " samples)");
    } else {
      say(what + ": done, commanded " + fixed(record.commanded_distance, 3) + " m");
    }
    return record;
  }

  double measuredDistance() {
    if (options_.measured) return *options_.measured;
    std::cout << "measure the distance the robot travelled and type it in metres: " << std::flush;
    double measured = 0;
    if (!(std::cin >> measured)) {
      checkSignal();  // Ctrl-C at the prompt interrupts the read (no SA_RESTART)
      throw Abort{"no distance typed: no wheel_diameter"};
    }
    return measured;
  }

  void report(const MotionRecord& ccw, const MotionRecord& cw) {
    using namespace serial_robot_driver::device;
    const auto turn = calibrateTurn(ccw, cw, geometry_.wheel_separation);
    if (!turn.value) throw Abort{"refused: " + turn.error};
    say("measured/commanded turn " + fixed(turn.value->ratio, 3) + " (counter-clockwise " +
        fixed(turn.value->ratio_ccw, 3) + ", clockwise " + fixed(turn.value->ratio_cw, 3) +
        ", gyro bias " + fixed(turn.value->gyro_bias, 4) + " rad/s)");
    printSetting("wheel_separation", turn.value->effective_separation, geometry_.wheel_separation);
    if (options_.distance <= 0) return;

    const MotionRecord straight = move("driving straight", options_.speed, 0.0);
    holdStill(0.1);
    const auto diameter = calibrateDiameter(straight, measuredDistance(), geometry_.wheel_diameter);
    if (!diameter.value) throw Abort{"refused: " + diameter.error};
    say("measured/commanded distance " + fixed(diameter.value->ratio, 3));
    printSetting("wheel_diameter", diameter.value->effective_diameter, geometry_.wheel_diameter);
    const double scale = diameter.value->effective_diameter / geometry_.wheel_diameter;
    say("with that wheel_diameter, the turns give wheel_separation " +
        fixed(
            calibrateTurn(ccw, cw, geometry_.wheel_separation, scale).value->effective_separation) +
        " (set both)");
  }

  void printSetting(const std::string& key, double value, double configured) const {
    say("effective " + key + ": " + fixed(value) + " m (configured " + fixed(configured) + " m)");
    say("  try it now:  rosrun dynamic_reconfigure dynparam set " + node_ + "/base " + key + " " +
        fixed(value));
    say("  keep it:     in your config file, under base:   " + key + ": " + fixed(value));
  }

  /// Every way out once the base may have moved: zero cmd_vel until a zero frame is written.
  void stopBase() {
    g_signal = 0;  // a second Ctrl-C during the stop must not skip it
    recorder_.reset();
    if (!ros::ok()) {
      std::cerr << "calibrate_base: ROS is down; the node's ~base/cmd_vel_timeout stops the base"
                << std::endl;
      return;
    }
    try {
      holdStill(0.0);
      std::cerr << "calibrate_base: base stopped (a zero wheel frame was written)" << std::endl;
    } catch (const Abort& abort) {
      std::cerr << "calibrate_base: " << abort.message << std::endl;
    }
  }

  Options options_;
  ros::NodeHandle nh_;
  ros::Publisher cmd_vel_;
  ros::Subscriber imu_sub_, wheel_sub_, diagnostics_sub_;
  std::string node_;
  std::string e_stop_status_name_;
  DiffDriveGeometry geometry_;
  int left_direction_ = 1;
  int right_direction_ = 1;
  std::optional<MotionRecorder> recorder_;
  std::optional<bool> e_stop_engaged_;
  ros::WallTime last_imu_, last_frame_;
  double last_imu_stamp_ = 0;
  bool last_frame_zero_ = false;
  uint64_t zero_frames_ = 0;
  bool moved_ = false;
};

}  // namespace

int main(int argc, char** argv) {
  // Our own SIGINT/SIGTERM: the base is stopped before the tool exits, not after roscpp's.
  ros::init(argc, argv, "calibrate_base",
            ros::init_options::NoSigintHandler | ros::init_options::AnonymousName);
  bool help = false;
  const std::optional<Options> options = parseOptions(argc, argv, &help);
  if (help) {
    std::cout << kUsage;
    return 0;
  }
  if (!options) return kExitUsage;
  // Without SA_RESTART, so that a signal also ends a wait for typed input.
  struct sigaction action {};
  action.sa_handler = onSignal;
  sigemptyset(&action.sa_mask);
  sigaction(SIGINT, &action, nullptr);
  sigaction(SIGTERM, &action, nullptr);
  const int status = CalibrationRun(*options).run();
  ros::shutdown();
  return status;
}
