#include "serial_robot_driver/dds_front/dds_conversions.h"

#include "serial_robot_driver/core/log.h"

namespace serial_robot_driver::dds_front {

void logCallbackError(const std::string& line) {
  static core::LogThrottle throttle(1.0);  // a sender repeating the sample must not flood the log
  if (throttle.pass()) core::log(core::LogLevel::kError, "%s", line.c_str());
}

builtin_interfaces_msg_dds__Time_ toTime(std::chrono::nanoseconds since_epoch) {
  const int64_t ns = since_epoch.count();
  builtin_interfaces_msg_dds__Time_ stamp{};
  stamp.sec = static_cast<int32_t>(ns / 1000000000);
  stamp.nanosec = static_cast<uint32_t>(ns % 1000000000);
  return stamp;
}

std::chrono::nanoseconds fromTime(const builtin_interfaces_msg_dds__Time_& stamp) {
  return std::chrono::seconds(stamp.sec) + std::chrono::nanoseconds(stamp.nanosec);
}

trajectory::TrajectoryCommand toTrajectoryCommand(
    const trajectory_msgs_msg_dds__JointTrajectory_& msg) {
  trajectory::TrajectoryCommand command;
  command.joint_names = dds::toStrings(msg.joint_names);
  for (const auto& point : dds::toVector(msg.points)) {
    command.points.push_back({point.time_from_start.sec + point.time_from_start.nanosec * 1e-9,
                              dds::toVector(point.positions), dds::toVector(point.velocities),
                              dds::toVector(point.accelerations)});
  }
  return command;
}

void setHeader(std_msgs_msg_dds__Header_& header, std::chrono::nanoseconds stamp,
               const std::string& frame) {
  header.stamp = toTime(stamp);
  dds::lend(header.frame_id, frame);
}

JointStateSample::JointStateSample(std::chrono::nanoseconds stamp, std::string frame,
                                   std::vector<std::string> names, std::vector<double> positions,
                                   std::vector<double> velocities)
    : frame_(std::move(frame)),
      names_(std::move(names)),
      positions_(std::move(positions)),
      velocities_(std::move(velocities)),
      name_pointers_(names_) {
  setHeader(sample_.header, stamp, frame_);
  name_pointers_.lendTo(sample_.name);
  dds::lend(sample_.position, positions_);
  dds::lend(sample_.velocity, velocities_);
  dds::lend(sample_.effort, effort_);
}

DiagnosticsSample::DiagnosticsSample(std::chrono::nanoseconds stamp,
                                     std::vector<NamedReport> reports,
                                     std::string default_hardware_id)
    : reports_(std::move(reports)), default_hardware_id_(std::move(default_hardware_id)) {
  // Sized first: the statuses point into values_, which must not move afterwards.
  values_.resize(reports_.size());
  statuses_.resize(reports_.size());
  for (std::size_t i = 0; i < reports_.size(); ++i) {
    const auto& [name, report] = reports_[i];
    for (const auto& [key, value] : report.values) {
      diagnostic_msgs_msg_dds__KeyValue_ entry{};
      dds::lend(entry.key, key);
      dds::lend(entry.value, value);
      values_[i].push_back(entry);
    }
    diagnostic_msgs_msg_dds__DiagnosticStatus_& status = statuses_[i];
    status.level = static_cast<uint8_t>(report.level);
    dds::lend(status.name, name);
    dds::lend(status.message, report.message);
    dds::lend(status.hardware_id,
              report.hardware_id.empty() ? default_hardware_id_ : report.hardware_id);
    dds::lend(status.values, values_[i]);
  }
  setHeader(sample_.header, stamp, no_frame_);
  dds::lend(sample_.status, statuses_);
}

}  // namespace serial_robot_driver::dds_front
