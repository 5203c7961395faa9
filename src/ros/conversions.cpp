#include "serial_robot_driver/ros/conversions.h"

#include <utility>

#include "serial_robot_driver/core/wall_stamps.h"

namespace serial_robot_driver::ros_layer {

ros::Time toRosTime(std::chrono::steady_clock::time_point event, const ros::Time& ros_now,
                    std::chrono::steady_clock::time_point steady_now) {
  // core::wallTimeOf() on the ROS clock (which may be simulated) instead of the wall clock.
  const std::chrono::system_clock::time_point now{std::chrono::nanoseconds(ros_now.toNSec())};
  ros::Time stamp;
  stamp.fromNSec(static_cast<uint64_t>(core::wallTimeOf(event, now, steady_now).count()));
  return stamp;
}

ros::Time toRosTime(std::chrono::steady_clock::time_point event) {
  // Read both clocks back to back so the offset between them is as exact as it can be.
  const auto steady_now = std::chrono::steady_clock::now();
  const ros::Time ros_now = ros::Time::now();
  return toRosTime(event, ros_now, steady_now);
}

ros::Time ArrivalStamps::operator()(std::chrono::steady_clock::time_point arrival) const {
  if (replay_timeline_ || !ros::Time::isSimTime()) {
    // The core's stamp of the arrival (ros::Time::now() is the wall clock too), which every front
    // end gives the same frame: the DDS one publishes the same stamp.
    ros::Time stamp;
    stamp.fromNSec(static_cast<uint64_t>(core::WallStamps(replay_timeline_)(arrival).count()));
    return stamp;
  }
  // Simulated time: the same conversion against ros::Time::now().
  thread_local std::chrono::steady_clock::time_point last_arrival{};
  thread_local ros::Time last_stamp;
  if (arrival != last_arrival || last_stamp.isZero()) {
    last_stamp = toRosTime(arrival);
    last_arrival = arrival;
  }
  return last_stamp;
}

void writeStatusReport(core::StatusReport report,
                       diagnostic_updater::DiagnosticStatusWrapper& status, SummaryWrite summary) {
  static_assert(static_cast<unsigned char>(core::StatusLevel::kWarn) ==
                        diagnostic_msgs::DiagnosticStatus::WARN &&
                    static_cast<unsigned char>(core::StatusLevel::kError) ==
                        diagnostic_msgs::DiagnosticStatus::ERROR &&
                    static_cast<unsigned char>(core::StatusLevel::kStale) ==
                        diagnostic_msgs::DiagnosticStatus::STALE,
                "StatusLevel's values are DiagnosticStatus's levels");
  const auto level = static_cast<unsigned char>(report.level);
  if (summary == SummaryWrite::kReplace) {
    status.summary(level, report.message);
  } else {
    status.mergeSummary(level, report.message);
  }
  if (!report.hardware_id.empty()) status.hardware_id = std::move(report.hardware_id);
  status.values.reserve(status.values.size() + report.values.size());
  for (auto& [key, value] : report.values) {
    diagnostic_msgs::KeyValue entry;
    entry.key = std::move(key);
    entry.value = std::move(value);
    status.values.push_back(std::move(entry));
  }
}

}  // namespace serial_robot_driver::ros_layer
