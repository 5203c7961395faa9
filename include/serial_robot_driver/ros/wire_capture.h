// ~capture: every chunk each port reads or writes goes out on serial_raw
// (serial_robot_driver/SerialChunk), for rosbag and ~replay_bag.
//
// Threading model: onChunk() runs on whichever thread moved the bytes (a port's reader thread, the
// base loop, a service or subscriber thread). It only stamps the chunk, copies it into a message
// and queues it; its own thread publishes, so a slow serialization or a stalled subscriber never
// delays the base loop or the telemetry path. The queue is bounded: past kMaxQueued chunks, new
// chunks are dropped and counted (diagnostics "wire capture").
#pragma once

#include <diagnostic_updater/diagnostic_updater.h>
#include <ros/ros.h>

#include <condition_variable>
#include <cstdint>
#include <deque>
#include <mutex>
#include <thread>

#include "serial_robot_driver/SerialChunk.h"
#include "serial_robot_driver/device/serial_link.h"
#include "serial_robot_driver/ros/conversions.h"

namespace serial_robot_driver::ros_layer {

struct WireCaptureStats {
  uint64_t chunks = 0;     ///< published
  uint64_t bytes = 0;      ///< in published chunks
  uint64_t dropped = 0;    ///< chunks lost to a full queue
  std::size_t queued = 0;  ///< waiting to be published now
};

class WireCapture : public device::ChunkObserver {
 public:
  /// About 10 s of a busy 1 Mbaud port; a backlog beyond this means the publisher cannot keep up.
  static constexpr std::size_t kMaxQueued = 20000;

  /// Advertises serial_raw and starts the publishing thread.
  WireCapture(ros::NodeHandle& nh, const DriverParams& params);
  /// Publishes what is still queued, then stops the thread.
  ~WireCapture() override;

  void onChunk(const device::WireChunk& chunk) override;
  WireCaptureStats stats() const;
  void diagnose(diagnostic_updater::DiagnosticStatusWrapper& status) const;

 private:
  void publishLoop();

  const ArrivalStamps stamps_;
  ros::Publisher publisher_;
  mutable std::mutex mutex_;
  std::condition_variable wake_;
  std::deque<serial_robot_driver::SerialChunk> queue_;
  bool stopping_ = false;
  WireCaptureStats stats_;
  std::thread thread_;
};

}  // namespace serial_robot_driver::ros_layer
