// What the tests of the simulated robot share: hand-written frames, a host that plays the driver
// on a sim pty with plain POSIX I/O, a temporary directory and the options of one-device sims.
#pragma once

#include <fcntl.h>
#include <gtest/gtest.h>
#include <poll.h>
#include <stdlib.h>
#include <sys/ioctl.h>
#include <sys/stat.h>
#include <termios.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <fstream>
#include <functional>
#include <map>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "serial_robot_driver/devices/base/sim/base_sim.h"
#include "serial_robot_driver/devices/body/body_codec.h"
#include "serial_robot_driver/devices/body/sim/body_sim.h"
#include "serial_robot_driver/devices/servo_bus/servo_bus_codec.h"
#include "serial_robot_driver/devices/servo_bus/sim/servo_bus_sim.h"
#include "serial_robot_driver/protocol/stream_framer.h"
#include "serial_robot_driver/sim/command_line.h"
#include "serial_robot_driver/sim/robot_sim.h"
#include "support/framer_configs.h"
#include "support/golden_frames.h"

namespace serial_robot_driver::sim::sim_test {

using Bytes = std::vector<uint8_t>;
using protocol::FrameFamily;
using protocol::FramerConfig;
using std::chrono::milliseconds;

// --- golden vectors (test/support/golden_frames.h, and more computed by hand from the rules) ---
using namespace golden::base;   // NOLINT: the shared hand-written frames
using namespace golden::body;   // NOLINT
using namespace golden::servo;  // NOLINT

inline const Bytes kPing1 = {0x12, 0x4C, 0x01, 0x01, 0x01, 0x61};
inline const Bytes kPing1Reply = {0x05, 0x1C, 0x01, 0x01, 0x01, 0x24};
inline const Bytes kPing9 = {0x12, 0x4C, 0x01, 0x01, 0x09, 0x69};
inline const Bytes kPing9Reply = {0x05, 0x1C, 0x01, 0x01, 0x09, 0x2C};
inline const Bytes kReadVoltage0 = {0x12, 0x4C, 0x03, 0x02, 0x00, 0x01, 0x64};
inline const Bytes kReadUnknown20 = {0x12, 0x4C, 0x03, 0x02, 0x00, 0x14, 0x77};
// angle_limit_high (51, i16) of id 1 := 900 (0x0384), and read back.
inline const Bytes kWriteLimitHigh1 = {0x12, 0x4C, 0x04, 0x04, 0x01, 0x33, 0x84, 0x03, 0x21};
inline const Bytes kWriteLimitHigh1Reply = {0x05, 0x1C, 0x04, 0x03, 0x01, 0x33, 0x01, 0x5D};
inline const Bytes kReadLimitHigh1 = {0x12, 0x4C, 0x03, 0x02, 0x01, 0x33, 0x97};
inline const Bytes kReadLimitHigh1Reply = {0x05, 0x1C, 0x03, 0x04, 0x01, 0x33, 0x84, 0x03, 0xE3};
// voltage (read-only) of id 0 := 5000: the servo answers result 0.
inline const Bytes kWriteVoltage0 = {0x12, 0x4C, 0x04, 0x04, 0x00, 0x01, 0x88, 0x13, 0x02};
inline const Bytes kWriteVoltage0Reply = {0x05, 0x1C, 0x04, 0x03, 0x00, 0x01, 0x00, 0x29};
inline const Bytes kReadAngle0ReplyZero = {0x05, 0x1C, 0x0A, 0x03, 0x00, 0x00, 0x00, 0x2E};
inline const Bytes kReadAngle2 = {0x12, 0x4C, 0x0A, 0x01, 0x02, 0x6B};
inline const Bytes kReadAngle2Reply90 = {0x05, 0x1C, 0x0A, 0x03, 0x02, 0x84, 0x03, 0xB7};
inline const Bytes kResponseSwitch2On = {0x12, 0x4C, 0x04, 0x03, 0x02, 0x21, 0x01, 0x89};
inline const Bytes kResponseSwitch2OnReply = {0x05, 0x1C, 0x04, 0x03, 0x02, 0x21, 0x01, 0x4C};
inline const Bytes kDamping2 = {0x12, 0x4C, 0x09, 0x03, 0x02, 0xF4, 0x01, 0x61};
inline const Bytes kDamping2Reply = {0x05, 0x1C, 0x09, 0x02, 0x02, 0x01, 0x2F};
inline const Bytes kWriteId1To9 = {0x12, 0x4C, 0x04, 0x03, 0x01, 0x22, 0x09, 0x91};
inline const Bytes kWriteId1To9Reply = {0x05, 0x1C, 0x04, 0x03, 0x01, 0x22, 0x01, 0x4C};
inline const Bytes kResetUserData9 = {0x12, 0x4C, 0x02, 0x01, 0x09, 0x6A};
inline const Bytes kResetUserData9Reply = {0x05, 0x1C, 0x02, 0x02, 0x09, 0x01, 0x2F};
inline const Bytes kReadBatch0 = {0x12, 0x4C, 0x05, 0x01, 0x00, 0x64};
// Broadcast ROTATE to 45.0 deg (0x01C2) in 0 ms.
inline const Bytes kRotateAllTo45 = {0x12, 0x4C, 0x08, 0x07, 0xFF, 0xC2,
                                     0x01, 0x00, 0x00, 0x00, 0x00, 0x2F};

// --- helpers ---------------------------------------------------------------------------------

struct HostFrame {
  FrameFamily family;
  Bytes bytes;
};

// The driver's side of a sim port: plain POSIX, raw termios, a framer to split what arrives.
class Host {
 public:
  Host(const std::string& path, const FramerConfig& config)
      : framer_(config, [this](FrameFamily family, const uint8_t* data, std::size_t size) {
          frames_.push_back(HostFrame{family, Bytes(data, data + size)});
        }) {
    fd_ = ::open(path.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK);
    if (fd_ >= 0) {
      termios settings{};
      ::tcgetattr(fd_, &settings);
      ::cfmakeraw(&settings);
      ::tcsetattr(fd_, TCSANOW, &settings);
    }
  }
  ~Host() {
    if (fd_ >= 0) ::close(fd_);
  }
  bool ok() const { return fd_ >= 0; }

  void send(const Bytes& bytes) {
    ASSERT_EQ(::write(fd_, bytes.data(), bytes.size()), static_cast<ssize_t>(bytes.size()));
  }

  // Reads what is there within `timeout_ms` and feeds the framer.
  void pump(int timeout_ms) {
    pollfd fds{fd_, POLLIN, 0};
    if (::poll(&fds, 1, timeout_ms) <= 0) return;
    uint8_t buffer[4096];
    ssize_t n = 0;
    while ((n = ::read(fd_, buffer, sizeof(buffer))) > 0) {
      bytes_read_ += static_cast<std::size_t>(n);
      framer_.feed(buffer, static_cast<std::size_t>(n));
    }
  }
  std::size_t bytesRead() const { return bytes_read_; }
  /// Bytes the pty holds that were not read yet (already sent by the other side).
  std::size_t pending() const {
    int held = 0;
    return ::ioctl(fd_, FIONREAD, &held) == 0 && held > 0 ? static_cast<std::size_t>(held) : 0;
  }

  // Pumps until `done()` or the (generous) timeout; returns done().
  bool waitUntil(const std::function<bool()>& done, milliseconds timeout = milliseconds(3000)) {
    const auto deadline = Clock::now() + timeout;
    while (!done() && Clock::now() < deadline) pump(10);
    return done();
  }

  // Waits for a frame equal to `expected` (frames seen before are searched too).
  bool waitForFrame(const Bytes& expected, milliseconds timeout = milliseconds(3000)) {
    return waitUntil([&] { return countFrames(expected) > 0; }, timeout);
  }
  std::size_t countFrames(const Bytes& expected) const {
    return static_cast<std::size_t>(std::count_if(
        frames_.begin(), frames_.end(), [&](const HostFrame& f) { return f.bytes == expected; }));
  }
  std::vector<Bytes> framesOf(FrameFamily family) const {
    std::vector<Bytes> result;
    for (const HostFrame& frame : frames_) {
      if (frame.family == family) result.push_back(frame.bytes);
    }
    return result;
  }
  // Forces a decision on a candidate that waits for bytes that will never come.
  void feedPadding() {
    const Bytes zeros(512, 0);
    framer_.feed(zeros.data(), zeros.size());
  }
  std::vector<HostFrame>& frames() { return frames_; }
  const protocol::FramerStats& framerStats() const { return framer_.stats(); }

 private:
  int fd_ = -1;
  std::size_t bytes_read_ = 0;
  protocol::StreamFramer framer_;
  std::vector<HostFrame> frames_;
};

inline bool waitForStats(const RobotSim& sim, const std::function<bool(const SimStats&)>& done,
                         milliseconds timeout = milliseconds(3000)) {
  const auto deadline = Clock::now() + timeout;
  while (Clock::now() < deadline) {
    if (done(sim.stats())) return true;
    std::this_thread::sleep_for(milliseconds(5));
  }
  return done(sim.stats());
}

class TempDir {
 public:
  TempDir() {
    char pattern[] = "/tmp/robot_sim_test_XXXXXX";
    const char* made = ::mkdtemp(pattern);
    path_ = made != nullptr ? made : "/tmp";
  }
  ~TempDir() {
    // Only what the tests create: links, a stats file and its temporary.
    for (const char* name : {"robot", "base", "body", "servo", "stats", "stats.tmp"}) {
      ::unlink((path_ + "/" + name).c_str());
    }
    ::rmdir(path_.c_str());
  }
  std::string file(const std::string& name) const { return path_ + "/" + name; }

 private:
  std::string path_;
};

inline SimOptions onlyBase() {
  SimOptions options;
  options.device("body").enabled = false;
  options.device("servo_bus").enabled = false;
  return options;
}
inline SimOptions onlyBody() {
  SimOptions options;
  options.device("base").enabled = false;
  options.device("servo_bus").enabled = false;
  return options;
}
inline SimOptions onlyServoBus() {
  SimOptions options;
  options.device("base").enabled = false;
  options.device("body").enabled = false;
  devices::servo_bus::sim::servoBusConfig(options).servo_ids = {0, 1, 2, 3, 7};
  devices::servo_bus::sim::servoBusConfig(options).offline_ids = {7};
  return options;
}

inline FramerConfig baseHostConfig() { return test_support::driverFramer({"base"}); }
inline FramerConfig bodyHostConfig(std::size_t servos) {
  return test_support::driverFramer({"body"}, servos);
}
inline FramerConfig servoHostConfig() { return test_support::driverFramer({"servo_bus"}); }

inline std::string slaveOf(const RobotSim& sim) { return sim.ports().at(0).slave_path; }

}  // namespace serial_robot_driver::sim::sim_test
