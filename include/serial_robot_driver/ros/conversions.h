// Pure conversions every device's ROS adapter shares (stamps, joint commands, status reports): no
// node, no I/O, so they are unit-tested without a roscore. A device's own message conversions live
// in its folder (src/devices/<name>/ros/).
#pragma once

#include <diagnostic_updater/DiagnosticStatusWrapper.h>
#include <ros/time.h>
#include <sensor_msgs/JointState.h>

#include <chrono>
#include <string>
#include <vector>

#include "serial_robot_driver/core/status_report.h"
#include "serial_robot_driver/ros/driver_params.h"

namespace serial_robot_driver::ros_layer {

/// The ROS time at which a steady_clock event happened: `ros_now` minus how long ago it was
/// (`steady_now` - `event`). Saturates at ros::Time(0) instead of going negative.
ros::Time toRosTime(std::chrono::steady_clock::time_point event, const ros::Time& ros_now,
                    std::chrono::steady_clock::time_point steady_now);

/// The same, against the current ros::Time::now() and steady_clock::now().
ros::Time toRosTime(std::chrono::steady_clock::time_point event);

/// Header stamps of frames from their arrival time in the core (steady clock).
/// Live: toRosTime(), with the last conversion remembered per thread, so the users of one chunk
/// (its wire capture and the frames it completes, all on the port's reader thread) give it the
/// very same stamp. Replaying (params.replay_timeline set): the recorded stamp the arrival stands
/// for on the replay's timeline, exactly, so a replay publishes the recorded stamps.
class ArrivalStamps {
 public:
  explicit ArrivalStamps(const DriverParams& params) : replay_timeline_(params.replay_timeline) {}
  ros::Time operator()(std::chrono::steady_clock::time_point arrival) const;

 private:
  std::shared_ptr<const transport::ReplayPacing> replay_timeline_;
};

/// How writeStatusReport treats the status's summary so far.
enum class SummaryWrite {
  kReplace,  ///< the report's level and message are the status's (the updater's fresh status)
  kMerge,    ///< merged into another check's verdict (DiagnosticStatusWrapper::mergeSummary)
};
/// A core status report as the updater publishes it: its summary, its hardware_id when it has
/// one, and its values appended in order. Taken by value: its strings move into the status (the
/// callers hand over a report made for this call), once a second for each of ~100 values.
void writeStatusReport(core::StatusReport report,
                       diagnostic_updater::DiagnosticStatusWrapper& status,
                       SummaryWrite summary = SummaryWrite::kReplace);

}  // namespace serial_robot_driver::ros_layer
