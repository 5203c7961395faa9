// ~replay_bag without the bag format: the ports' bytes come from a recording of serial_raw (chunks
// recorded with ~capture) instead of the wire. A front end reads the recording from its own
// format (the ROS one from a rosbag: ros/bag_replay.h) and hands it here; each configured port then
// gets a transport::RecordedStream, so the very same links, framers and devices run. Recorded
// stamps are placed on the replay's own steady timeline (transport::ReplayPacing), where the links'
// timers see the recorded silences. ROS-free.
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <map>
#include <memory>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include "serial_robot_driver/core/serial_link.h"
#include "serial_robot_driver/params/driver_params.h"
#include "serial_robot_driver/transport/recorded_stream.h"

namespace serial_robot_driver::core {

/// A recording that cannot be replayed; what() names the file and the problem.
class ReplayError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// The inbound chunks of a recording's serial_raw topic, per port, in recorded order.
struct Recording {
  std::string topic;  ///< the serial_raw topic found, e.g. /serial_raw or /robot1/serial_raw
  std::map<std::string, std::vector<transport::RecordedChunk>> ports;
  std::size_t outbound_chunks = 0;  ///< recorded writes: not replayed
  transport::RecordedStamp end{0};  ///< the recording's latest stamp (any topic)
};

/// Adds one recorded chunk of `port` stamped `stamp` to `recording`: an inbound one to its port's
/// chunks (and the recording's end), a recorded write only to the count (writes are not
/// replayed).
void addRecordedChunk(Recording& recording, const std::string& port, bool outbound,
                      transport::RecordedStamp stamp, std::vector<uint8_t> data);

/// "serial_raw" itself or the last name of a namespaced one ("/robot1/serial_raw").
bool isSerialRawTopic(const std::string& topic);
/// The one serial_raw topic among the `topics` of the recording at `path`. Throws ReplayError
/// when there is none (naming the topics there are) or several (from several drivers).
std::string serialRawTopic(const std::string& path, const std::set<std::string>& topics);
/// Throws ReplayError when `recording` (of `path`) holds no inbound chunk.
void requireInboundChunks(const std::string& path, const Recording& recording);

/// The ports `params` drives (its enabled devices' paths).
std::set<std::string> configuredPorts(const params::DriverParams& params);

/// A recording, ready to stand in for the ports.
class RecordingReplay {
 public:
  /// The recording `recording` of the file `path`, paced at params.replay_rate. Throws ReplayError
  /// when it has no inbound chunk or chunks of a port that `params` does not configure.
  RecordingReplay(std::string path, Recording recording, const params::DriverParams& params);

  /// Points the driver at the replay: `stream_factory` reads the recording, `params` stamp by its
  /// timeline, and a port reopens without waiting (the recording's stamps pace a recorded reopen;
  /// waiting reconnect_interval would not).
  void standIn(params::DriverParams& params, SerialLink::StreamFactory& stream_factory) const;
  /// Streams for SerialLink: every (re)open of a port reads on where the last one stopped.
  SerialLink::StreamFactory streamFactory() const;
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

/// Before the first replayed chunk: time for subscribers that are already running to connect to
/// the topics the front end has just offered (a message nobody subscribes to is not even built).
constexpr std::chrono::milliseconds kReplaySettle{1500};
/// After the last replayed chunk: how long the front end stays up so that subscribers (a recorder,
/// a test) receive the tail of what it published before the connections close.
constexpr std::chrono::milliseconds kReplayLinger{1500};

/// How fast a replay at `rate` goes, for the log: "2.000000x the recorded pace", or "full speed"
/// (rate 0).
std::string replayPaceText(double rate);

}  // namespace serial_robot_driver::core
