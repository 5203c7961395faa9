// ~replay_bag: the ports' bytes come from a bag's serial_raw (recorded with ~capture) instead of
// the wire. The bag is read whole at start-up with the rosbag C++ API; each configured port then
// gets a transport::RecordedStream, so the very same links, framers, devices and publishers run.
// Recorded stamps are placed on the replay's own steady timeline (transport::ReplayPacing), where
// the links' timers see the recorded silences; the published frames carry the recorded stamps
// again (conversions.h, ArrivalStamps).
#pragma once

#include <map>
#include <memory>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include "serial_robot_driver/core/serial_link.h"
#include "serial_robot_driver/ros/driver_params.h"
#include "serial_robot_driver/transport/recorded_stream.h"

namespace serial_robot_driver::ros_layer {

/// A bag that cannot be replayed; what() names the bag and the problem.
class ReplayError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// The inbound chunks of a bag's serial_raw topic, per port, in recorded order.
struct Recording {
  std::string topic;  ///< the serial_raw topic found, e.g. /serial_raw or /robot1/serial_raw
  std::map<std::string, std::vector<transport::RecordedChunk>> ports;
  std::size_t outbound_chunks = 0;  ///< recorded writes: not replayed
  transport::RecordedStamp end{0};  ///< the bag's latest stamp (any topic)
};

/// Reads every serial_raw chunk of the bag at `path`. Throws ReplayError when the file is missing
/// or is no readable bag, when it has no serial_raw topic (or several, from several drivers), or
/// when that topic holds no inbound chunk.
Recording readRecording(const std::string& path);

/// The ports `params` drives (its enabled devices' paths).
std::set<std::string> configuredPorts(const DriverParams& params);

/// The recording of a bag, ready to stand in for the ports.
class BagReplay {
 public:
  /// Reads the bag of params.replay_bag. Throws ReplayError as readRecording() does, and when the
  /// bag has chunks of a port that `params` does not configure.
  explicit BagReplay(const DriverParams& params);

  /// Streams for SerialLink: every (re)open of a port reads on where the last one stopped.
  core::SerialLink::StreamFactory streamFactory() const;
  /// The recorded pace counts from now (call just before the links start).
  void startClock() { pacing_->restart(); }
  /// The replay's timeline, for the stamps of what the replay publishes (DriverParams).
  std::shared_ptr<const transport::ReplayPacing> timeline() const { return pacing_; }
  /// Every port has handed out its last chunk.
  bool finished() const;
  /// One line for the log: chunks and bytes fed, writes discarded.
  std::string summary() const;
  const Recording& recording() const { return recording_; }

 private:
  std::string path_;
  Recording recording_;
  std::shared_ptr<transport::ReplayPacing> pacing_;
  std::map<std::string, std::shared_ptr<transport::RecordedPort>> ports_;
};

}  // namespace serial_robot_driver::ros_layer
