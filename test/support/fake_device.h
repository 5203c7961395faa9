// ROS-free scripted device for the rostests: plays the base, the board or the bus servos on a pty
// whose symlink the node under test opens.
//
// Threading: a PtyFrameReader thread reads everything the node writes (so its writes never stall),
// records the raw bytes and the verified frames of the current session, and answers frames the
// script matches from that same thread. The test thread scripts, writes and inspects under a mutex.
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "serial_robot_driver/protocol/stream_framer.h"
#include "serial_robot_driver/sim/pseudo_terminal.h"
#include "support/pty_frame_reader.h"

namespace test_support {

class FakeDevice {
 public:
  using Clock = std::chrono::steady_clock;
  using Bytes = std::vector<uint8_t>;

  /// One verified frame the node wrote.
  struct Frame {
    serial_robot_driver::protocol::FrameFamily family;
    Bytes bytes;
    Clock::time_point arrival;
  };
  using Match = std::function<bool(const Frame&)>;

  /// `framer` chooses the frame families recognised in what the node writes. With `echo`, every
  /// frame is written back before its replies (an adapter with its transmit line looped back).
  /// Not plugged yet: call plug().
  FakeDevice(std::string link_path, serial_robot_driver::protocol::FramerConfig framer,
             bool echo = false);
  ~FakeDevice();
  FakeDevice(const FakeDevice&) = delete;
  FakeDevice& operator=(const FakeDevice&) = delete;

  /// Creates a new pty at the link path: a fresh session (the recordings start empty).
  void plug();
  /// Closes the pty and removes the link: to the node, an unplugged adapter.
  void unplug();

  /// Script: on a frame equal to `request`, write `replies` in this order (none: stay silent, but
  /// still count it). A later rule for the same bytes replaces the earlier one.
  void answer(const Bytes& request, std::vector<Bytes> replies);
  /// Script: on a frame `match` accepts (when no exact rule took it), write `replies`.
  void answerWhen(Match match, std::vector<Bytes> replies);
  /// How often the rule for exactly `request` was hit.
  std::size_t hits(const Bytes& request) const;

  void write(const Bytes& bytes);

  /// The frames of this session, in arrival order.
  std::vector<Frame> frames() const;
  std::size_t frameCount() const;
  /// Waits until `done` holds for the frames of this session.
  bool waitForFrames(const std::function<bool(const std::vector<Frame>&)>& done,
                     double timeout_s) const;

  /// Raw bytes of this session: a position to read from later...
  std::size_t mark() const;
  Bytes bytesSince(std::size_t mark) const;
  /// ...or consumed in order: the next `count` bytes not yet taken, waiting up to `timeout_s`
  /// (fewer when they do not come).
  Bytes takeBytes(std::size_t count, double timeout_s);
  /// Marks everything received so far as taken.
  void skipReceived();

  /// The framer's counters of this session (of the last one once unplugged).
  serial_robot_driver::protocol::FramerStats framerStats() const;
  Clock::time_point pluggedAt() const;

 private:
  struct Rule {
    Bytes exact;  ///< empty: use `match`
    Match match;
    std::vector<Bytes> replies;
    std::size_t hits = 0;
  };

  void onFrame(serial_robot_driver::protocol::FrameFamily family, const uint8_t* data,
               std::size_t size, Clock::time_point arrival);

  const std::string link_path_;
  const serial_robot_driver::protocol::FramerConfig framer_config_;
  const bool echo_;

  mutable std::mutex mutex_;  ///< guards everything below except pty_ and reader_
  std::vector<Rule> rules_;
  std::vector<Frame> frames_;
  Bytes received_;
  std::size_t taken_ = 0;
  serial_robot_driver::protocol::FramerStats last_session_stats_;
  Clock::time_point plugged_at_;

  // Replaced only by plug()/unplug() on the test thread; the reader writes replies to pty_.
  std::unique_ptr<serial_robot_driver::sim::PseudoTerminal> pty_;
  std::unique_ptr<PtyFrameReader> reader_;  // after pty_: it is stopped first
};

}  // namespace test_support
