// ~capture: every chunk each port reads or writes goes out on serial_raw
// (serial_robot_driver/SerialChunk), for rosbag and ~replay_bag.
//
// Threading model: onChunk() runs on whichever thread moved the bytes (a port's reader thread, the
// base loop, a service or subscriber thread). It only stamps the chunk, copies it into a message
// and queues it in the core's CaptureQueue (core/capture_queue.h: bounded, every loss counted),
// whose own thread publishes, so a slow serialization or a stalled subscriber never delays the
// base loop or the telemetry path. Each message roscpp serializes for serial_raw (once, for all
// its subscribers) holds one of the queue's in-flight tokens until roscpp releases its buffer, so
// roscpp's per-subscriber queues (which silently discard their oldest message when full) never
// overflow; roscpp's own queue is set to max_in_roscpp as a backstop that is never reached.
#pragma once

#include <diagnostic_updater/diagnostic_updater.h>
#include <ros/ros.h>

#include <boost/shared_ptr.hpp>
#include <cstddef>

#include "serial_robot_driver/SerialChunk.h"
#include "serial_robot_driver/core/capture_queue.h"
#include "serial_robot_driver/core/serial_link.h"
#include "serial_robot_driver/core/wire_capture_status.h"
#include "serial_robot_driver/ros/conversions.h"

namespace serial_robot_driver::ros_layer {

// Its counters and status are the core's (device/wire_capture_status.h).
using core::WireCaptureStats;

/// The capture queue's limits (core/capture_queue.h), the in-flight ones being roscpp's.
struct WireCaptureLimits {
  std::size_t max_queued = core::CaptureQueueLimits{}.max_queued;
  /// Published chunks roscpp may hold unsent (its per-subscriber outgoing queues, the longest one).
  std::size_t max_in_roscpp = core::CaptureQueueLimits{}.max_in_flight;
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
  struct Release;

  /// Publishes `msg` and returns its size in bytes (on the queue's thread).
  std::size_t publish(const boost::shared_ptr<serial_robot_driver::SerialChunk>& msg);

  const ArrivalStamps stamps_;
  ros::Publisher publisher_;
  core::CaptureQueue queue_;  // after publisher_: its thread stops before publisher_ goes
};

}  // namespace serial_robot_driver::ros_layer
