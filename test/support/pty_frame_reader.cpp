// ROS-free reader of a pty master for tests and benchmarks that play a device (see the header).
#include "support/pty_frame_reader.h"

#include <vector>

#include "serial_robot_driver/transport/byte_stream.h"

namespace test_support {

namespace protocol = serial_robot_driver::protocol;
namespace transport = serial_robot_driver::transport;
namespace sim = serial_robot_driver::sim;

PtyFrameReader::PtyFrameReader(sim::PseudoTerminal& pty, const protocol::FramerConfig& config,
                               FrameCallback on_frame, ChunkCallback on_chunk)
    : PtyFrameReader([&pty](uint8_t* buffer, std::size_t capacity,
                            int timeout_ms) { return pty.read(buffer, capacity, timeout_ms); },
                     config, std::move(on_frame), std::move(on_chunk)) {}

PtyFrameReader::PtyFrameReader(ReadFunction read, const protocol::FramerConfig& config,
                               FrameCallback on_frame, ChunkCallback on_chunk)
    : read_(std::move(read)),
      framer_(config, [this](protocol::FrameFamily family, const uint8_t* data,
                             std::size_t size) { on_frame_(family, data, size, chunk_arrival_); }),
      on_frame_(std::move(on_frame)),
      on_chunk_(std::move(on_chunk)),
      thread_([this] { run(); }) {}

PtyFrameReader::~PtyFrameReader() {
  stopping_ = true;
  thread_.join();
}

protocol::FramerStats PtyFrameReader::framerStats() const {
  std::lock_guard<std::mutex> lock(stats_mutex_);
  return stats_;
}

void PtyFrameReader::run() {
  std::vector<uint8_t> chunk(4096);
  while (!stopping_) {
    std::size_t count = 0;
    try {
      count = read_(chunk.data(), chunk.size(), 20);
    } catch (const transport::TransportError&) {
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
      continue;
    }
    if (count == 0) continue;
    chunk_arrival_ = Clock::now();
    if (on_chunk_) on_chunk_(chunk.data(), count);
    framer_.feed(chunk.data(), count);
    std::lock_guard<std::mutex> lock(stats_mutex_);
    stats_ = framer_.stats();
  }
}

}  // namespace test_support
