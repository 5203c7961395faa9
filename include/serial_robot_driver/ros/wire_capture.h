// ~capture: every chunk each port reads or writes goes out on serial_raw
// (serial_robot_driver/SerialChunk), for rosbag and ~replay_bag.
//
// Threading model: onChunk() runs on whichever thread moved the bytes (a port's reader thread, the
// base loop, a service or subscriber thread). It only stamps the chunk, copies it into a message
// and queues it; its own thread publishes, so a slow serialization or a stalled subscriber never
// delays the base loop or the telemetry path.
//
// Memory is bounded and every loss is counted, in one place: the capture's own queue. roscpp keeps
// one outgoing queue per subscriber and silently discards the oldest message of a full one (its
// statistics count a message as sent when it is queued), so its overflow cannot be counted.
// Instead roscpp is never let to overflow: each message roscpp serializes for serial_raw (once, for
// all its subscribers) gets a buffer whose release the capture sees, and the publishing thread
// hands roscpp a new chunk only while fewer than max_in_roscpp such buffers are alive. A subscriber
// whose queue holds that many unsent chunks (a slow rosbag, a stalled link) therefore holds the
// publishing back; the capture's own queue fills, and past max_queued new chunks are dropped and
// counted (diagnostics "wire capture"). Every subscriber sees the same stream: a chunk that was
// published reached every subscriber's queue, a lost one is in "chunks dropped". The price: one
// stalled subscriber holds back the others too. roscpp's own queue is set to max_in_roscpp as a
// backstop that is never reached.
#pragma once

#include <diagnostic_updater/diagnostic_updater.h>
#include <ros/ros.h>

#include <boost/shared_ptr.hpp>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <memory>
#include <mutex>
#include <thread>

#include "serial_robot_driver/SerialChunk.h"
#include "serial_robot_driver/core/serial_link.h"
#include "serial_robot_driver/core/wire_capture_status.h"
#include "serial_robot_driver/ros/conversions.h"

namespace serial_robot_driver::ros_layer {

// Its counters and status are the core's (device/wire_capture_status.h).
using core::WireCaptureStats;

struct WireCaptureLimits {
  /// About 10 s of a busy 1 Mbaud port; a backlog beyond this means the subscribers cannot keep up.
  std::size_t max_queued = 20000;
  /// Published chunks roscpp may hold unsent (its per-subscriber outgoing queues, the longest one).
  std::size_t max_in_roscpp = 1000;
};

class WireCapture : public core::ChunkObserver {
 public:
  /// Advertises serial_raw and starts the publishing thread.
  WireCapture(ros::NodeHandle& nh, const DriverParams& params, WireCaptureLimits limits = {});
  /// Publishes what is still queued while roscpp has room (what it has no room for is counted as
  /// dropped: a stalled subscriber cannot hold the node's exit), then stops the thread.
  ~WireCapture() override;

  void onChunk(const core::WireChunk& chunk) override;
  WireCaptureStats stats() const;
  void diagnose(diagnostic_updater::DiagnosticStatusWrapper& status) const;

 private:
  /// What the buffers handed to roscpp report to; shared with them, as roscpp may release one
  /// after the capture is gone.
  struct Shared {
    std::mutex mutex;  // guards the capture's queue, stats and stopping flag as well
    std::condition_variable wake;
    std::size_t in_roscpp = 0;
  };
  struct Release;

  void publishLoop();
  void publish(const boost::shared_ptr<serial_robot_driver::SerialChunk>& msg);

  const ArrivalStamps stamps_;
  const WireCaptureLimits limits_;
  const std::shared_ptr<Shared> shared_ = std::make_shared<Shared>();
  ros::Publisher publisher_;
  std::deque<serial_robot_driver::SerialChunk> queue_;
  bool stopping_ = false;
  WireCaptureStats stats_;
  std::thread thread_;
};

}  // namespace serial_robot_driver::ros_layer
