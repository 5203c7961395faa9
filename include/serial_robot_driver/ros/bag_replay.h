// ~replay_bag: the ports' bytes come from a bag's serial_raw (recorded with ~capture) instead of
// the wire. The bag is read whole at start-up with the rosbag C++ API into the core's Recording;
// the core's RecordingReplay (core/recording_replay.h) then stands in for the ports, so the very
// same links, framers, devices and publishers run. The published frames carry the recorded stamps
// again (conversions.h, ArrivalStamps).
#pragma once

#include <string>

#include "serial_robot_driver/core/recording_replay.h"
#include "serial_robot_driver/ros/driver_params.h"

namespace serial_robot_driver::ros_layer {

using core::configuredPorts;
using core::Recording;
using core::ReplayError;

/// Reads every serial_raw chunk of the bag at `path`. Throws ReplayError when the file is missing
/// or is no readable bag, when it has no serial_raw topic (or several, from several drivers), or
/// when that topic holds no inbound chunk.
Recording readRecording(const std::string& path);

/// The recording of a bag, ready to stand in for the ports.
class BagReplay : public core::RecordingReplay {
 public:
  /// Reads the bag of params.replay_bag. Throws ReplayError as readRecording() does, and when the
  /// bag has chunks of a port that `params` does not configure.
  explicit BagReplay(const DriverParams& params)
      : RecordingReplay(params.replay_bag, readRecording(params.replay_bag), params) {}
};

}  // namespace serial_robot_driver::ros_layer
