// calibrate_base's ROS wiring (calibrate_base_main.cpp): finding the driver, and the
// topics converted into the inputs of the core's TurnCalibrationRun.
#pragma once

#include <ros/ros.h>

#include <atomic>
#include <optional>
#include <string>

#include "serial_robot_driver/devices/base/turn_calibration_run.h"

namespace serial_robot_driver::devices::base::ros {

/// The driver's resolved name: `named` when given, else the one node publishing wheel_command,
/// waited for up to 5 s (a signal in `stop_signal` or ROS shutting down ends the wait). Unset with
/// `why` set when there is none, or several.
std::optional<std::string> findCalibrationDriver(const std::string& named,
                                                 const std::atomic<int>& stop_signal,
                                                 std::string* why);

/// imu/data, wheel_command, e_stop (the driver's input topic: every engagement published) and the
/// driver's e-stop status on /diagnostics (its state and count of engagements) into the run;
/// cmd_vel out. Messages arrive in ros::spinOnce().
class CalibrationTopics {
 public:
  explicit CalibrationTopics(TurnCalibrationRun& run);
  void command(const BaseTwist& twist);
  bool commandSubscribed() const { return cmd_vel_.getNumSubscribers() > 0; }

 private:
  ::ros::NodeHandle nh_;
  ::ros::Publisher cmd_vel_;
  ::ros::Subscriber imu_, frames_, diagnostics_, e_stop_;
};

}  // namespace serial_robot_driver::devices::base::ros
