// ROS-free reader of a pty master for tests and benchmarks that play a device: splits what the
// driver writes into verified frames on a thread of its own.
#pragma once

#include <atomic>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <mutex>
#include <thread>

#include "serial_robot_driver/protocol/stream_framer.h"
#include "serial_robot_driver/sim/pseudo_terminal.h"

namespace test_support {

/// Reads the master side of `pty` on its own thread (so the driver's writes never stall), feeds a
/// StreamFramer and hands every verified frame to `on_frame` with the time the chunk holding its
/// last byte was read. A read error (the pty closed under it) is waited out until destruction.
/// The pty must outlive the reader. It reads any other byte source the same way (a benchmark's
/// loopback TCP end) given as a ReadFunction.
class PtyFrameReader {
 public:
  using Clock = std::chrono::steady_clock;
  using FrameCallback =
      std::function<void(serial_robot_driver::protocol::FrameFamily family, const uint8_t* data,
                         std::size_t size, Clock::time_point arrival)>;
  /// Every chunk as read, before the framer sees it.
  using ChunkCallback = std::function<void(const uint8_t* data, std::size_t size)>;
  /// Reads as PseudoTerminal::read does: up to `capacity` bytes within `timeout_ms`, 0 on timeout.
  using ReadFunction =
      std::function<std::size_t(uint8_t* buffer, std::size_t capacity, int timeout_ms)>;

  PtyFrameReader(serial_robot_driver::sim::PseudoTerminal& pty,
                 const serial_robot_driver::protocol::FramerConfig& config, FrameCallback on_frame,
                 ChunkCallback on_chunk = nullptr);
  /// The same over `read`, which must stay callable until destruction.
  PtyFrameReader(ReadFunction read, const serial_robot_driver::protocol::FramerConfig& config,
                 FrameCallback on_frame, ChunkCallback on_chunk = nullptr);
  /// Stops and joins the thread.
  ~PtyFrameReader();
  PtyFrameReader(const PtyFrameReader&) = delete;
  PtyFrameReader& operator=(const PtyFrameReader&) = delete;

  /// The framer's counters after the last chunk it was fed (resyncs, checksum errors, ...).
  serial_robot_driver::protocol::FramerStats framerStats() const;

 private:
  void run();

  ReadFunction read_;
  serial_robot_driver::protocol::StreamFramer framer_;  // reader thread only
  Clock::time_point chunk_arrival_;
  FrameCallback on_frame_;
  ChunkCallback on_chunk_;
  mutable std::mutex stats_mutex_;
  serial_robot_driver::protocol::FramerStats stats_;
  std::atomic<bool> stopping_{false};
  std::thread thread_;
};

}  // namespace test_support
