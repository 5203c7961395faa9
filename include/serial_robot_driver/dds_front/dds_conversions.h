// What every device's DDS front end shares: stamps, headers, JointState and DiagnosticArray
// samples built from core values. The generated C structs point into storage these own (a sample
// only has to live until publish() returns), so each sample is a small non-copyable object. No
// participant, no I/O: unit-tested against the CDR bytes without a network.
#pragma once

#include <chrono>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "serial_robot_driver/core/guarded_call.h"
#include "serial_robot_driver/core/input_refusals.h"
#include "serial_robot_driver/core/status_report.h"
#include "serial_robot_driver/dds/c_types.h"
#include "serial_robot_driver/dds/messages.h"
#include "serial_robot_driver/trajectory/command.h"

namespace serial_robot_driver::dds_front {

/// An error a guarded() callback let out, as the core's log writes it (at most once a second).
void logCallbackError(const std::string& line);

/// `callback` guarded as the ROS side guards its subscriptions (core/guarded_call.h): an
/// exception it lets out is counted in `counters` ("callback errors: <source>"), logged and
/// dropped; the dispatch thread never sees it. `counters` outlives the callback.
template <typename Message>
std::function<void(const Message&)> guarded(core::InputRefusals& counters, std::string source,
                                            std::function<void(const Message&)> callback) {
  return
      [&counters, source = std::move(source), callback = std::move(callback)](const Message& msg) {
        core::runGuarded(
            counters, source, [&] { callback(msg); }, nullptr, logCallbackError);
      };
}

/// builtin_interfaces/Time of a wall-clock time (core/wall_stamps.h), nanoseconds since the epoch.
builtin_interfaces_msg_dds__Time_ toTime(std::chrono::nanoseconds since_epoch);
/// The wall-clock time a received stamp stands for (negative fields count as they are).
std::chrono::nanoseconds fromTime(const builtin_interfaces_msg_dds__Time_& stamp);

/// A received trajectory_msgs/JointTrajectory as the core's trajectories take it.
trajectory::TrajectoryCommand toTrajectoryCommand(
    const trajectory_msgs_msg_dds__JointTrajectory_& msg);
/// `header` stamped and in `frame` (lent: `frame` must outlive the publish).
void setHeader(std_msgs_msg_dds__Header_& header, std::chrono::nanoseconds stamp,
               const std::string& frame);

/// A sensor_msgs/JointState sample and its storage; empty velocities stay empty, effort is empty.
class JointStateSample {
 public:
  JointStateSample(std::chrono::nanoseconds stamp, std::string frame,
                   std::vector<std::string> names, std::vector<double> positions,
                   std::vector<double> velocities = {});
  JointStateSample(const JointStateSample&) = delete;
  JointStateSample& operator=(const JointStateSample&) = delete;
  const sensor_msgs_msg_dds__JointState_& sample() const { return sample_; }

 private:
  std::string frame_;
  std::vector<std::string> names_;
  std::vector<double> positions_, velocities_, effort_;
  dds::StringPointers name_pointers_;
  sensor_msgs_msg_dds__JointState_ sample_{};
};

/// One diagnostic status: its name as published ("driver_node: base") and its core report.
using NamedReport = std::pair<std::string, core::StatusReport>;

/// A diagnostic_msgs/DiagnosticArray sample of `reports` and its storage, as diagnostic_updater
/// writes it: a report without a hardware_id gets `default_hardware_id` (the node's ~port).
class DiagnosticsSample {
 public:
  DiagnosticsSample(std::chrono::nanoseconds stamp, std::vector<NamedReport> reports,
                    std::string default_hardware_id);
  DiagnosticsSample(const DiagnosticsSample&) = delete;
  DiagnosticsSample& operator=(const DiagnosticsSample&) = delete;
  const diagnostic_msgs_msg_dds__DiagnosticArray_& sample() const { return sample_; }

 private:
  std::vector<NamedReport> reports_;
  std::vector<std::vector<diagnostic_msgs_msg_dds__KeyValue_>> values_;  // one list per status
  std::vector<diagnostic_msgs_msg_dds__DiagnosticStatus_> statuses_;
  std::string default_hardware_id_;
  std::string no_frame_;
  diagnostic_msgs_msg_dds__DiagnosticArray_ sample_{};
};

}  // namespace serial_robot_driver::dds_front
