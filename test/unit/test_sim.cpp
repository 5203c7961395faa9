// Tests of the simulated robot. The device classes are driven with explicit time points; RobotSim
// runs in-process on real ptys while the test plays the host through the slave path, with plain
// POSIX I/O and byte vectors written out by hand from docs/protocols.md.
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

#include "serial_robot_driver/protocol/body_codec.h"
#include "serial_robot_driver/protocol/servo_bus_codec.h"
#include "serial_robot_driver/protocol/stream_framer.h"
#include "serial_robot_driver/sim/base_sim.h"
#include "serial_robot_driver/sim/body_sim.h"
#include "serial_robot_driver/sim/command_line.h"
#include "serial_robot_driver/sim/robot_sim.h"
#include "serial_robot_driver/sim/servo_bus_sim.h"
#include "support/golden_frames.h"

namespace serial_robot_driver::sim {
namespace {

using Bytes = std::vector<uint8_t>;
using protocol::FrameFamily;
using protocol::FramerConfig;
using std::chrono::milliseconds;

// --- golden vectors (test/support/golden_frames.h, and more computed by hand from the rules) ---
using namespace golden::base;   // NOLINT: the shared hand-written frames
using namespace golden::body;   // NOLINT
using namespace golden::servo;  // NOLINT

const Bytes kPing1 = {0x12, 0x4C, 0x01, 0x01, 0x01, 0x61};
const Bytes kPing1Reply = {0x05, 0x1C, 0x01, 0x01, 0x01, 0x24};
const Bytes kPing9 = {0x12, 0x4C, 0x01, 0x01, 0x09, 0x69};
const Bytes kPing9Reply = {0x05, 0x1C, 0x01, 0x01, 0x09, 0x2C};
const Bytes kReadVoltage0 = {0x12, 0x4C, 0x03, 0x02, 0x00, 0x01, 0x64};
const Bytes kReadUnknown20 = {0x12, 0x4C, 0x03, 0x02, 0x00, 0x14, 0x77};
// angle_limit_high (51, i16) of id 1 := 900 (0x0384), and read back.
const Bytes kWriteLimitHigh1 = {0x12, 0x4C, 0x04, 0x04, 0x01, 0x33, 0x84, 0x03, 0x21};
const Bytes kWriteLimitHigh1Reply = {0x05, 0x1C, 0x04, 0x03, 0x01, 0x33, 0x01, 0x5D};
const Bytes kReadLimitHigh1 = {0x12, 0x4C, 0x03, 0x02, 0x01, 0x33, 0x97};
const Bytes kReadLimitHigh1Reply = {0x05, 0x1C, 0x03, 0x04, 0x01, 0x33, 0x84, 0x03, 0xE3};
// voltage (read-only) of id 0 := 5000: the servo answers result 0.
const Bytes kWriteVoltage0 = {0x12, 0x4C, 0x04, 0x04, 0x00, 0x01, 0x88, 0x13, 0x02};
const Bytes kWriteVoltage0Reply = {0x05, 0x1C, 0x04, 0x03, 0x00, 0x01, 0x00, 0x29};
const Bytes kReadAngle0ReplyZero = {0x05, 0x1C, 0x0A, 0x03, 0x00, 0x00, 0x00, 0x2E};
const Bytes kReadAngle2 = {0x12, 0x4C, 0x0A, 0x01, 0x02, 0x6B};
const Bytes kReadAngle2Reply90 = {0x05, 0x1C, 0x0A, 0x03, 0x02, 0x84, 0x03, 0xB7};
const Bytes kResponseSwitch2On = {0x12, 0x4C, 0x04, 0x03, 0x02, 0x21, 0x01, 0x89};
const Bytes kResponseSwitch2OnReply = {0x05, 0x1C, 0x04, 0x03, 0x02, 0x21, 0x01, 0x4C};
const Bytes kDamping2 = {0x12, 0x4C, 0x09, 0x03, 0x02, 0xF4, 0x01, 0x61};
const Bytes kDamping2Reply = {0x05, 0x1C, 0x09, 0x02, 0x02, 0x01, 0x2F};
const Bytes kWriteId1To9 = {0x12, 0x4C, 0x04, 0x03, 0x01, 0x22, 0x09, 0x91};
const Bytes kWriteId1To9Reply = {0x05, 0x1C, 0x04, 0x03, 0x01, 0x22, 0x01, 0x4C};
const Bytes kResetUserData9 = {0x12, 0x4C, 0x02, 0x01, 0x09, 0x6A};
const Bytes kResetUserData9Reply = {0x05, 0x1C, 0x02, 0x02, 0x09, 0x01, 0x2F};
const Bytes kReadBatch0 = {0x12, 0x4C, 0x05, 0x01, 0x00, 0x64};
// Broadcast ROTATE to 45.0 deg (0x01C2) in 0 ms.
const Bytes kRotateAllTo45 = {0x12, 0x4C, 0x08, 0x07, 0xFF, 0xC2,
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

bool waitForStats(const RobotSim& sim, const std::function<bool(const SimStats&)>& done,
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

SimOptions onlyBase() {
  SimOptions options;
  options.enable_body = false;
  options.enable_servo_bus = false;
  return options;
}
SimOptions onlyBody() {
  SimOptions options;
  options.enable_base = false;
  options.enable_servo_bus = false;
  return options;
}
SimOptions onlyServoBus() {
  SimOptions options;
  options.enable_base = false;
  options.enable_body = false;
  options.servo_bus.servo_ids = {0, 1, 2, 3, 7};
  options.servo_bus.offline_ids = {7};
  return options;
}

FramerConfig baseHostConfig() { return FramerConfig::forDriver(true, false, false, 0); }
FramerConfig bodyHostConfig(std::size_t servos) {
  return FramerConfig::forDriver(false, true, false, servos);
}
FramerConfig servoHostConfig() { return FramerConfig::forDriver(false, false, true, 0); }

std::string slaveOf(const RobotSim& sim) { return sim.ports().at(0).slave_path; }

// --- devices alone, on explicit time ---------------------------------------------------------

TEST(RobotSimBaseDevice, IntegratesOncePerPidPeriodAndTimesOut) {
  const TimePoint t0{};
  BaseSim base(BaseSimConfig{}, t0);
  Outbox out;
  base.handleFrame(kBoth4Seq0.data(), kBoth4Seq0.size(), t0, &out);
  base.tick(t0 + milliseconds(105), &out);  // 5 periods of 20 ms
  EXPECT_EQ(base.stats().left_ticks, 20);
  EXPECT_EQ(base.stats().right_ticks, 20);
  EXPECT_TRUE(out.empty());

  base.tick(t0 + milliseconds(1002), &out);  // more than 1 s of silence
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].bytes, kErrorStatusSeq0);
  EXPECT_TRUE(base.stats().in_error);
  EXPECT_EQ(base.stats().last_left_speed, 0);  // a base that lost its host stops
  const int64_t ticks_at_error = base.stats().left_ticks;
  base.tick(t0 + milliseconds(2003), &out);  // repeated once per second while in error
  EXPECT_EQ(out.size(), 2u);
  EXPECT_EQ(base.stats().left_ticks, ticks_at_error);
}

TEST(RobotSimBaseDevice, YawRateFollowsTheWheelDifference) {
  const TimePoint t0{};
  BaseSim base(BaseSimConfig{}, t0);
  Outbox out;
  // left 0, right 4 ticks per period: 4 * 50 / 2037.18 m/s on the right wheel, 0.40 m apart.
  const Bytes right4 = {0x55, 0xAA, 0x09, 0x00, 0x01, 0x00, 0x00,
                        0x00, 0x04, 0x00, 0x00, 0x00, 0x00, 0xF3};
  base.handleFrame(right4.data(), right4.size(), t0, &out);
  EXPECT_NEAR(base.yawRate(), (4 * 50 / (1600 / (0.25 * M_PI))) / 0.40, 1e-9);
  EXPECT_GT(base.yawRate(), 0.0);  // right wheel faster: counter-clockwise
}

TEST(RobotSimBaseDevice, TurnSlipTurnsTheChassisLessThanItsWheelsCommand) {
  const TimePoint t0{};
  BaseSimConfig config;
  config.turn_slip = 0.3;
  BaseSim base(config, t0);
  Outbox out;
  const Bytes right4 = {0x55, 0xAA, 0x09, 0x00, 0x01, 0x00, 0x00,
                        0x00, 0x04, 0x00, 0x00, 0x00, 0x00, 0xF3};
  base.handleFrame(right4.data(), right4.size(), t0, &out);
  base.tick(t0 + milliseconds(105), &out);  // 5 PID periods
  // The encoders count every tick; the chassis turns by 70 % of what the ticks command:
  // 5 periods * 4 ticks * (0.25 pi / 1600) m / 0.40 m = 0.0245437 rad commanded.
  EXPECT_EQ(base.stats().right_ticks, 20);
  EXPECT_NEAR(base.stats().yaw_rad, 0.7 * 0.0245437, 1e-6);
  EXPECT_NEAR(base.yawRate(), 0.7 * (4 * 50 / (1600 / (0.25 * M_PI))) / 0.40, 1e-9);
}

TEST(RobotSimBodyDevice, ImuReportsTheChassisHeadingAndYawRate) {
  const TimePoint t0{};
  BodySimConfig config;
  config.telemetry_rate_hz = 50;
  BodySim body(config, t0);
  Outbox out;
  body.tick(t0 + milliseconds(20), ChassisMotion{1.0, 0.5}, &out);
  ASSERT_EQ(out.size(), 1u);
  const auto telemetry =
      protocol::body::decodeTelemetry(out[0].bytes.data(), out[0].bytes.size(), 2);
  ASSERT_TRUE(telemetry.ok());
  // 1 rad at 180 deg / 32768 per LSB: 10430.4 LSB; 0.5 rad/s at 2000 deg/s / 32768: 469.4 LSB.
  EXPECT_EQ(telemetry->imu[protocol::body::kYaw], 10430);
  EXPECT_EQ(telemetry->imu[protocol::body::kGyroZ], 469);
  // A heading beyond pi is reported wrapped, as an attitude module does: 4 rad = 4 - 2 pi.
  out.clear();
  body.tick(t0 + milliseconds(40), ChassisMotion{4.0, 0.0}, &out);
  ASSERT_EQ(out.size(), 1u);
  const auto wrapped = protocol::body::decodeTelemetry(out[0].bytes.data(), out[0].bytes.size(), 2);
  ASSERT_TRUE(wrapped.ok());
  EXPECT_EQ(wrapped->imu[protocol::body::kYaw], -23814);  // -2.2832 rad * 32768 / pi
}

TEST(RobotSimBodyDevice, ServoMovesAtTheBoundedSpeed) {
  const TimePoint t0{};
  BodySimConfig config;
  config.servo_ids = {2, 3};
  config.servo_speed = 1000;
  config.telemetry_rate_hz = 0;
  BodySim body(config, t0);
  body.handleSyncWrite(kSyncWrite2And3.data(), kSyncWrite2And3.size());
  Outbox out;
  body.tick(t0 + milliseconds(500), ChassisMotion{}, &out);
  EXPECT_TRUE(out.empty());  // telemetry off
  EXPECT_NEAR(body.stats().servos[1].position, 2048 - 500, 1e-6);
  EXPECT_EQ(body.stats().servos[1].speed, -1000);
  EXPECT_EQ(body.stats().servos[0].speed, 0);
  body.tick(t0 + milliseconds(2000), ChassisMotion{}, &out);
  EXPECT_NEAR(body.stats().servos[1].position, 1024, 1e-6);
}

// --- the base on a pty -----------------------------------------------------------------------

TEST(RobotSimBase, AnswersBatteryRequestsAndCountsResets) {
  SimOptions options = onlyBase();
  options.base.battery_percent = 64;
  RobotSim sim(options);
  sim.start();
  Host host(slaveOf(sim), baseHostConfig());
  ASSERT_TRUE(host.ok());
  host.send(kBatteryRequestSeq1);
  host.send(kResetSeq2);
  EXPECT_TRUE(host.waitForFrame(kBattery64ReplySeq0));
  EXPECT_TRUE(waitForStats(sim, [](const SimStats& s) { return s.base.resets == 1; }));
  const SimStats stats = sim.stats();
  EXPECT_EQ(stats.base.frames_received, 2u);
  EXPECT_EQ(stats.base.battery_requests, 1u);
  EXPECT_EQ(stats.base.seq_gaps, 0u);
  EXPECT_EQ(stats.sent[static_cast<std::size_t>(OutputKind::kBaseReply)].intact, 1u);
}

TEST(RobotSimBase, SpeedFramesIntegrateAndClearEncodersZeroes) {
  RobotSim sim(onlyBase());
  sim.start();
  Host host(slaveOf(sim), baseHostConfig());
  ASSERT_TRUE(host.ok());
  host.send(kBoth4Seq0);
  ASSERT_TRUE(waitForStats(sim, [](const SimStats& s) { return s.base.left_ticks >= 40; }));
  host.send(kBoth0Seq1);
  ASSERT_TRUE(
      waitForStats(sim, [](const SimStats& s) { return s.base.speed_frames_applied == 2; }));
  SimStats stats = sim.stats();
  EXPECT_EQ(stats.base.left_ticks, stats.base.right_ticks);
  EXPECT_EQ(stats.base.left_ticks % 4, 0);
  EXPECT_EQ(stats.base.last_left_speed, 0);

  host.send(kClearEncodersSeq3);  // SEQ 03 after 01: one gap
  ASSERT_TRUE(waitForStats(sim, [](const SimStats& s) { return s.base.encoder_clears == 1; }));
  stats = sim.stats();
  EXPECT_EQ(stats.base.left_ticks, 0);
  EXPECT_EQ(stats.base.right_ticks, 0);
  EXPECT_EQ(stats.base.seq_gaps, 1u);

  host.send(kBothMinus6Seq0);  // SEQ 00 after 03: another gap
  ASSERT_TRUE(waitForStats(sim, [](const SimStats& s) { return s.base.left_ticks <= -12; }));
  stats = sim.stats();
  EXPECT_EQ(stats.base.last_left_speed, -6);
  EXPECT_EQ(stats.base.last_right_speed, -6);
  EXPECT_EQ(stats.base.seq_gaps, 2u);
}

TEST(RobotSimBase, SilenceRaisesTheTimeoutErrorAndSpeedIsIgnoredUntilReset) {
  RobotSim sim(onlyBase());
  sim.start();
  Host host(slaveOf(sim), baseHostConfig());
  ASSERT_TRUE(host.ok());
  // Nothing sent since power-on: after 1 s the base reports FF.
  ASSERT_TRUE(host.waitForFrame(kErrorStatusSeq0));
  host.send(kBoth4Seq0);
  ASSERT_TRUE(
      waitForStats(sim, [](const SimStats& s) { return s.base.speed_frames_ignored == 1; }));
  EXPECT_EQ(sim.stats().base.left_ticks, 0);
  EXPECT_TRUE(sim.stats().base.in_error);

  host.send(kResetSeq1);
  host.send(kBoth4Seq2);
  ASSERT_TRUE(waitForStats(sim, [](const SimStats& s) { return s.base.left_ticks > 0; }));
  const SimStats stats = sim.stats();
  EXPECT_FALSE(stats.base.in_error);
  EXPECT_EQ(stats.base.resets, 1u);
  EXPECT_EQ(stats.base.speed_frames_applied, 1u);
  EXPECT_GE(stats.base.errors_sent, 1u);
}

// --- the body on a pty -----------------------------------------------------------------------

TEST(RobotSimBody, TelemetryDecodesWithGravityOnZ) {
  RobotSim sim(onlyBody());
  sim.start();
  Host host(slaveOf(sim), bodyHostConfig(2));
  ASSERT_TRUE(host.ok());
  ASSERT_TRUE(host.waitUntil([&] { return host.framesOf(protocol::body::kTelemetryFrames).size() >= 5; }));
  for (const Bytes& frame : host.framesOf(protocol::body::kTelemetryFrames)) {
    ASSERT_EQ(frame.size(), 32u);
    EXPECT_EQ(frame[2], 0x20);
    // Servo 0 at 2048 (08 00), standing still.
    EXPECT_EQ(frame[3], 0x08);
    EXPECT_EQ(frame[4], 0x00);
    const auto telemetry = protocol::body::decodeTelemetry(frame.data(), frame.size(), 2);
    ASSERT_TRUE(telemetry.ok());
    EXPECT_EQ(telemetry->servos[0].position, 2048);
    EXPECT_EQ(telemetry->servos[1].position, 2048);
    EXPECT_EQ(telemetry->servos[0].speed, 0);
    EXPECT_EQ(telemetry->imu[protocol::body::kAccelZ], 2048);  // 1 g at 16 g full scale
    EXPECT_EQ(telemetry->imu[protocol::body::kGyroZ], 0);
    EXPECT_FALSE(telemetry->has_foot);
  }
}

TEST(RobotSimBody, SyncWriteMovesTheServoTowardItsTarget) {
  SimOptions options = onlyBody();
  options.body.servo_ids = {2, 3};
  options.body.servo_speed = 4096;
  RobotSim sim(options);
  sim.start();
  Host host(slaveOf(sim), bodyHostConfig(2));
  ASSERT_TRUE(host.ok());
  host.send(kSyncWrite2And3);
  bool saw_full_speed = false;
  const auto reached = [&] {
    for (const Bytes& frame : host.framesOf(protocol::body::kTelemetryFrames)) {
      const auto telemetry = protocol::body::decodeTelemetry(frame.data(), frame.size(), 2);
      if (!telemetry) continue;
      EXPECT_EQ(telemetry->servos[0].position, 2048);
      if (telemetry->servos[1].speed == -4096) saw_full_speed = true;
      if (telemetry->servos[1].position == 1024 && telemetry->servos[1].speed == 0) return true;
    }
    return false;
  };
  EXPECT_TRUE(host.waitUntil(reached));
  EXPECT_TRUE(saw_full_speed);
  EXPECT_EQ(sim.stats().body.sync_writes_ok, 1u);
}

TEST(RobotSimBody, BadCrcAndUnknownIdsAreCounted) {
  SimOptions options = onlyBody();
  options.body.servo_ids = {2};
  RobotSim sim(options);
  sim.start();
  Host host(slaveOf(sim), bodyHostConfig(1));
  ASSERT_TRUE(host.ok());
  Bytes bad_crc = kSyncWrite2And3;
  bad_crc.back() ^= 0xFF;
  host.send(bad_crc);
  host.send(kSyncWrite2And3);  // id 3 is not on this board
  ASSERT_TRUE(waitForStats(sim, [](const SimStats& s) { return s.body.sync_writes_ok == 1; }));
  const SimStats stats = sim.stats();
  EXPECT_EQ(stats.body.sync_write_unknown_ids, 1u);
  EXPECT_GE(stats.body_port_checksum_errors, 1u);
  EXPECT_NE(formatStats(stats).find("sync_writes_bad 1\n"), std::string::npos);
}

TEST(RobotSimBody, FootAlternateInterleavesFrameLengths) {
  SimOptions options = onlyBody();
  options.body.foot_mode = FootMode::kAlternate;
  RobotSim sim(options);
  sim.start();
  Host host(slaveOf(sim), bodyHostConfig(2));
  ASSERT_TRUE(host.ok());
  ASSERT_TRUE(host.waitUntil([&] { return host.framesOf(protocol::body::kTelemetryFrames).size() >= 6; }));
  const auto frames = host.framesOf(protocol::body::kTelemetryFrames);
  for (std::size_t i = 1; i < frames.size(); ++i) EXPECT_NE(frames[i].size(), frames[i - 1].size());
  for (const Bytes& frame : frames) {
    ASSERT_TRUE(frame.size() == 32u || frame.size() == 48u);
    const auto telemetry = protocol::body::decodeTelemetry(frame.data(), frame.size(), 2);
    ASSERT_TRUE(telemetry.ok());
    EXPECT_EQ(telemetry->has_foot, frame.size() == 48u);
    if (telemetry->has_foot) {
      for (uint16_t reading : telemetry->foot) EXPECT_GT(reading, 100);
    }
  }
}

// --- the servo bus on a pty ------------------------------------------------------------------

class RobotSimServoBus : public ::testing::Test {
 protected:
  void SetUp() override {
    sim_ = std::make_unique<RobotSim>(onlyServoBus());
    sim_->start();
    host_ = std::make_unique<Host>(slaveOf(*sim_), servoHostConfig());
    ASSERT_TRUE(host_->ok());
  }
  // Sends a request and waits for exactly `reply`.
  void expectReply(const Bytes& request, const Bytes& reply) {
    host_->frames().clear();
    host_->send(request);
    EXPECT_TRUE(host_->waitForFrame(reply))
        << "no expected reply to request of cmd " << int(request[2]);
  }
  // Sends a request and checks that nothing answers within a short, generous window.
  void expectSilence(const Bytes& request) {
    host_->frames().clear();
    host_->send(request);
    host_->waitUntil([] { return false; }, milliseconds(150));
    EXPECT_TRUE(host_->framesOf(protocol::servo::kResponseFrames).empty());
  }
  std::unique_ptr<RobotSim> sim_;
  std::unique_ptr<Host> host_;
};

TEST_F(RobotSimServoBus, PingAnswersOnlineServosOnly) {
  expectReply(kPing3, kPing3Reply);
  expectSilence(kPing7);  // configured offline
  expectReply(kPing3, kPing3Reply);
  const SimStats stats = sim_->stats();
  EXPECT_EQ(stats.servo_bus.requests, 3u);
  EXPECT_EQ(stats.servo_bus.unaddressed, 1u);
  EXPECT_EQ(stats.servo_bus.answers, 2u);
}

TEST_F(RobotSimServoBus, VoltageReadIsPlausible) {
  host_->send(kReadVoltage0);
  ASSERT_TRUE(
      host_->waitUntil([&] { return !host_->framesOf(protocol::servo::kResponseFrames).empty(); }));
  const Bytes reply = host_->framesOf(protocol::servo::kResponseFrames).at(0);
  ASSERT_EQ(reply.size(), 9u);  // 05 1C 03 04 id data_id V_L V_H SUM
  EXPECT_EQ(Bytes(reply.begin(), reply.begin() + 6), (Bytes{0x05, 0x1C, 0x03, 0x04, 0x00, 0x01}));
  const int millivolts = reply[6] | (reply[7] << 8);
  EXPECT_GT(millivolts, 7000);
  EXPECT_LT(millivolts, 7800);
}

TEST_F(RobotSimServoBus, WriteIsReadBackAndReadOnlyWritesFail) {
  expectReply(kWriteLimitHigh1, kWriteLimitHigh1Reply);
  expectReply(kReadLimitHigh1, kReadLimitHigh1Reply);
  expectReply(kWriteVoltage0, kWriteVoltage0Reply);
  expectSilence(kReadUnknown20);
  EXPECT_EQ(sim_->stats().servo_bus.unknown_data_ids, 1u);
}

TEST_F(RobotSimServoBus, RotateMovesTheAngleWithoutAnAnswerByDefault) {
  expectReply(kReadAngle0, kReadAngle0ReplyZero);
  host_->frames().clear();
  host_->send(kRotate2To90In500);
  bool reached = false;
  const auto deadline = Clock::now() + milliseconds(3000);
  while (!reached && Clock::now() < deadline) {
    host_->send(kReadAngle2);
    host_->waitUntil([] { return false; }, milliseconds(50));
    reached = host_->countFrames(kReadAngle2Reply90) > 0;
  }
  EXPECT_TRUE(reached);
  // Only READ_ANGLE answers arrived: response_switch is 0, ROTATE is silent.
  for (const Bytes& frame : host_->framesOf(protocol::servo::kResponseFrames)) EXPECT_EQ(frame[2], 0x0A);
}

TEST_F(RobotSimServoBus, ResponseSwitchOneAnswersAfterTheMotion) {
  expectReply(kResponseSwitch2On, kResponseSwitch2OnReply);
  expectReply(kRotate2To90In500, kRotate2Done);
  expectReply(kReadAngle2, kReadAngle2Reply90);  // the answer came once the motion was done
  expectReply(kDamping2, kDamping2Reply);
}

TEST_F(RobotSimServoBus, ServoIdWriteMovesTheServoAndResetSendsItToIdZero) {
  expectReply(kWriteId1To9, kWriteId1To9Reply);
  expectReply(kPing9, kPing9Reply);
  expectSilence(kPing1);
  // Like the servo: the reset restores the factory id 0, and the answer comes from there.
  expectReply(kResetUserData9, kResetUserDataOkFromId0);
  expectSilence(kPing9);
  const auto servos = sim_->stats().servo_bus.servos;
  EXPECT_EQ(std::count_if(servos.begin(), servos.end(),
                          [](const BusServoSnapshot& servo) { return servo.id == 0; }),
            2);
}

// --- ServoBusSim on its own, in simulated time (no threads, no pty) --------------------------

class ServoBusSimMotion : public ::testing::Test {
 protected:
  ServoBusSimMotion() : start_(TimePoint() + std::chrono::hours(1)), sim_(config(), start_) {}
  static ServoBusSimConfig config() {
    ServoBusSimConfig c;
    c.servo_ids = {0, 1};
    c.answer_latency_s = 0.001;
    return c;
  }
  void send(const Bytes& request, double at_s) {
    sim_.handleRequest(request.data(), request.size(), start_ + fromSeconds(at_s));
  }
  double angleAt(double at_s, uint8_t id = 1) {
    Outbox out;
    sim_.tick(start_ + fromSeconds(at_s), &out);
    for (const BusServoSnapshot& servo : sim_.stats().servos) {
      if (servo.id == id) return servo.angle_deg;
    }
    ADD_FAILURE() << "no servo " << int(id);
    return 0.0;
  }
  std::vector<Bytes> answersUntil(double at_s) {
    Outbox out;
    sim_.tick(start_ + fromSeconds(at_s), &out);
    std::vector<Bytes> frames;
    for (Outgoing& frame : out) frames.push_back(std::move(frame.bytes));
    return frames;
  }
  TimePoint start_;
  ServoBusSim sim_;
};

TEST_F(ServoBusSimMotion, MoveByIntervalRunsATrapezoidInTheInterval) {
  send(kMoveByInterval1To90, 0.0);  // 90 deg in 1000 ms, 100 ms ramps: cruise 100 deg/s
  EXPECT_NEAR(angleAt(0.05), 0.5 * 100.0 / 0.1 * 0.05 * 0.05, 1e-6);  // accelerating
  EXPECT_NEAR(angleAt(0.5), 45.0, 1e-6);                              // symmetric midpoint
  EXPECT_LT(angleAt(0.95), 90.0);                                     // still decelerating
  EXPECT_DOUBLE_EQ(angleAt(1.0), 90.0);
  EXPECT_TRUE(answersUntil(1.1).empty());  // response_switch 0: no answer to a move
}

TEST_F(ServoBusSimMotion, MoveByVelocityTakesDistanceOverSpeedPlusTheRamps) {
  send(kMoveByVelocity1ToMinus90, 0.0);  // -90 deg at 360 deg/s, 100 ms ramps: 0.35 s
  EXPECT_NEAR(angleAt(0.175), -45.0, 1e-6);
  EXPECT_GT(angleAt(0.34), -90.0);
  EXPECT_DOUBLE_EQ(angleAt(0.36), -90.0);
}

TEST_F(ServoBusSimMotion, MultiTurnMoveKeepsTheTurnsAndAnswersCmd16) {
  send(kMultiTurnMove1To720, 0.0);  // 720 deg in 2000 ms, no ramps
  EXPECT_NEAR(angleAt(1.0), 360.0, 1e-6);
  EXPECT_DOUBLE_EQ(angleAt(2.0), 720.0);
  send(kReadMultiTurn1, 2.0);
  EXPECT_EQ(answersUntil(2.01), std::vector<Bytes>{kReadMultiTurn1Reply720});
  // READ_ANGLE folds the same angle into one turn: 0.0 deg (05+1C+0A+03+01 = 2F).
  send({0x12, 0x4C, 0x0A, 0x01, 0x01, 0x6A}, 2.02);
  const Bytes folded_reply = {0x05, 0x1C, 0x0A, 0x03, 0x01, 0x00, 0x00, 0x2F};
  EXPECT_EQ(answersUntil(2.03), std::vector<Bytes>{folded_reply});
}

TEST_F(ServoBusSimMotion, MultiTurnMovesByIntervalAndVelocityReachTheirTargets) {
  send(kMultiTurnMoveByInterval1ToMinus360, 0.0);  // 1000 ms, 200 ms ramps
  EXPECT_NEAR(angleAt(0.5), -180.0, 1e-6);
  EXPECT_DOUBLE_EQ(angleAt(1.0), -360.0);
  send(kMultiTurnMoveByVelocity1To3600, 1.0);  // 3960 deg at 360 deg/s + 0.1 s of ramps = 11.1 s
  EXPECT_LT(angleAt(12.0), 3600.0);
  EXPECT_DOUBLE_EQ(angleAt(12.2), 3600.0);
}

TEST_F(ServoBusSimMotion, ResetAnswersFromTheFactoryId) {
  // RESET_USER_DATA id 1: 5E+02+01+01 = 62.
  send({0x12, 0x4C, 0x02, 0x01, 0x01, 0x62}, 0.0);
  EXPECT_EQ(answersUntil(0.01), std::vector<Bytes>{kResetUserDataOkFromId0});
}

TEST_F(ServoBusSimMotion, MoveWithAWrongLengthIsMalformed) {
  Bytes short_move(kMoveByInterval1To90.begin(), kMoveByInterval1To90.end());
  // Drop the power field: N = 9, SUM without the two zero bytes is unchanged, minus 2 for N.
  short_move.erase(short_move.end() - 3, short_move.end() - 1);
  short_move[3] = 0x09;
  short_move.back() = static_cast<uint8_t>(short_move.back() - 2);
  send(short_move, 0.0);
  EXPECT_EQ(sim_.stats().malformed, 1u);
  EXPECT_DOUBLE_EQ(angleAt(2.0), 0.0);
}

TEST_F(RobotSimServoBus, BatchReadAndWriteOfTheUserBlock) {
  host_->send(kReadBatch0);
  ASSERT_TRUE(
      host_->waitUntil([&] { return !host_->framesOf(protocol::servo::kResponseFrames).empty(); }));
  Bytes reply = host_->framesOf(protocol::servo::kResponseFrames).at(0);
  ASSERT_EQ(reply.size(), 5u + 33u);
  EXPECT_EQ(reply[2], 0x05);
  EXPECT_EQ(reply[3], 33);
  const uint8_t* block = &reply[5];
  EXPECT_EQ(block[1], 0);                         // response_switch
  EXPECT_EQ(block[2], 0);                         // servo_id
  EXPECT_EQ(block[4], 5);                         // baudrate 115200
  EXPECT_EQ(block[18], 1);                        // accel_switch
  EXPECT_EQ(block[26] | (block[27] << 8), 1800);  // angle_limit_high, 180.0 deg

  std::array<uint8_t, protocol::servo::kUserBlockSize> new_block{};
  std::copy(block, block + new_block.size(), new_block.begin());
  new_block[26] = 0x84;  // angle_limit_high := 900
  new_block[27] = 0x03;
  host_->frames().clear();
  host_->send(protocol::servo::encodeWriteBatchData(0, new_block));
  EXPECT_TRUE(host_->waitForFrame({0x05, 0x1C, 0x06, 0x02, 0x00, 0x01, 0x2A}));
  const auto servos = sim_->stats().servo_bus.servos;
  ASSERT_FALSE(servos.empty());
  EXPECT_EQ(servos[0].params.at(51), 900);
}

TEST_F(RobotSimServoBus, BroadcastActsOnAllAndAnswersNone) {
  expectSilence(kRotateAllTo45);
  ASSERT_TRUE(waitForStats(*sim_, [](const SimStats& s) {
    return std::all_of(s.servo_bus.servos.begin(), s.servo_bus.servos.end(),
                       [](const BusServoSnapshot& servo) { return servo.angle_deg == 45.0; });
  }));
  EXPECT_EQ(sim_->stats().servo_bus.broadcasts, 1u);
}

// --- the whole robot -------------------------------------------------------------------------

TEST(RobotSim, SharedPortCarriesAllThreeDevicesBehindTheLink) {
  TempDir dir;
  SimOptions options;
  options.link = dir.file("robot");
  RobotSim sim(options);
  sim.start();
  const auto ports = sim.ports();
  ASSERT_EQ(ports.size(), 1u);
  EXPECT_EQ(ports[0].devices, (std::vector<std::string>{"base", "body", "servo_bus"}));
  char target[256] = {};
  ASSERT_GT(::readlink(options.link.c_str(), target, sizeof(target) - 1), 0);
  EXPECT_EQ(std::string(target), ports[0].slave_path);

  Host host(options.link, FramerConfig::forDriver(true, true, true, 2));
  ASSERT_TRUE(host.ok());
  host.send(kBatteryRequestSeq1);
  host.send({0x12, 0x4C, 0x01, 0x01, 0x01, 0x61});  // PING id 1
  EXPECT_TRUE(host.waitForFrame(kPing1Reply));
  EXPECT_TRUE(host.waitUntil([&] {
    return !host.framesOf(protocol::base::kFrames).empty() &&
           host.framesOf(protocol::body::kTelemetryFrames).size() >= 3;
  }));
  EXPECT_EQ(host.framesOf(protocol::base::kFrames).at(0)[4], 0x02);  // the battery reply
}

TEST(RobotSim, DevicesWithTheirOwnLinksGetTheirOwnPtys) {
  TempDir dir;
  SimOptions options;
  options.base_link = dir.file("base");
  options.body_link = dir.file("body");
  options.servo_link = dir.file("body");  // naming the same link: shared
  RobotSim sim(options);
  sim.start();
  const auto ports = sim.ports();
  ASSERT_EQ(ports.size(), 2u);
  EXPECT_EQ(ports[1].devices, (std::vector<std::string>{"body", "servo_bus"}));
  EXPECT_NE(ports[0].slave_path, ports[1].slave_path);

  Host base_host(dir.file("base"), baseHostConfig());
  ASSERT_TRUE(base_host.ok());
  base_host.send(kSyncWrite2And3);  // the board is not on this port
  base_host.send(kResetSeq2);
  ASSERT_TRUE(waitForStats(sim, [](const SimStats& s) { return s.base.resets == 1; }));
  const SimStats stats = sim.stats();
  EXPECT_EQ(stats.frames_for_absent_device, 1u);
  EXPECT_EQ(stats.body.sync_writes_ok, 0u);
}

TEST(RobotSim, IntactFramesReceivedMatchTheSendCountersUnderFaults) {
  SimOptions options = onlyBody();
  options.body.telemetry_rate_hz = 200;
  options.faults.seed = 7;
  options.faults.corrupt_rate = 0.2;
  options.faults.drop_rate = 0.2;
  options.faults.garbage_rate_hz = 30;
  RobotSim sim(options);
  sim.start();
  Host host(slaveOf(sim), bodyHostConfig(2));
  ASSERT_TRUE(host.ok());
  host.waitUntil([&] { return host.framesOf(protocol::body::kTelemetryFrames).size() >= 100; });
  sim.stop();  // the pty stays open: drain everything that was sent
  for (int i = 0; i < 10; ++i) host.pump(20);
  host.feedPadding();
  const SimStats stats = sim.stats();
  const SendCounters& telemetry = stats.sent[static_cast<std::size_t>(OutputKind::kTelemetry)];
  EXPECT_GT(telemetry.damaged, 0u);
  EXPECT_GT(stats.garbage_bursts, 0u);
  EXPECT_EQ(host.framesOf(protocol::body::kTelemetryFrames).size(), telemetry.intact);
  EXPECT_EQ(telemetry.intact + telemetry.damaged + telemetry.discarded,
            stats.body.telemetry_generated);
}

// --pace-baud bounds can only be checked from one side without timing assertions: a paced line is
// never faster than its baud rate, however slow or busy the machine is.
TEST(RobotSim, PacedPortSendsNoFasterThanItsBaudRate) {
  SimOptions options = onlyBody();
  options.body.telemetry_rate_hz = 200;  // several times what 9600 baud carries
  options.pace_baud = 9600;              // 960 bytes/s
  RobotSim sim(options);
  sim.start();
  Host host(slaveOf(sim), bodyHostConfig(2));
  ASSERT_TRUE(host.ok());
  for (int i = 0; i < 5; ++i) host.pump(20);  // what was sent before we listened
  const std::size_t before = host.bytesRead();
  const auto start = Clock::now();
  // Sent before the window, read during it: on a slow machine the pty holds more than one write.
  const std::size_t held_at_start = host.pending();
  host.waitUntil([&] { return host.bytesRead() - before >= 400; }, milliseconds(10000));
  const double elapsed_s = std::chrono::duration<double>(Clock::now() - start).count();
  const std::size_t received = host.bytesRead() - before;
  EXPECT_GE(received, 400u);
  // What the line carried in that time, plus one write's worth in flight at the start.
  EXPECT_LE(static_cast<double>(received - std::min(received, held_at_start)),
            960.0 * elapsed_s + 16.0);
  EXPECT_FALSE(host.framesOf(protocol::body::kTelemetryFrames).empty());  // cut into slices, not damaged
  EXPECT_EQ(host.framerStats().checksum_errors, 0u);
}

TEST(RobotSim, PacedPortTakesBytesInNoFasterThanItsBaudRate) {
  SimOptions options = onlyBody();
  options.body.servo_ids = {2, 3};
  options.body.telemetry_rate_hz = 0;
  options.pace_baud = 9600;
  RobotSim sim(options);
  sim.start();
  Host host(slaveOf(sim), bodyHostConfig(2));
  ASSERT_TRUE(host.ok());
  constexpr int kFrames = 6;
  const auto start = Clock::now();
  for (int i = 0; i < kFrames; ++i) host.send(kSyncWrite2And3);
  ASSERT_TRUE(waitForStats(
      sim, [](const SimStats& s) { return s.body.sync_writes_ok == kFrames; },
      milliseconds(10000)));
  const double elapsed_s = std::chrono::duration<double>(Clock::now() - start).count();
  // The last frame reached the board only once all its bits were through the line.
  const double line_s = kFrames * kSyncWrite2And3.size() * 10.0 / 9600.0;
  EXPECT_GE(elapsed_s, line_s - 0.001);
}

// The answer of a paced servo comes after the request's bits, the servo's latency and the
// answer's bits, each on the line's clock: never sooner, and (checked by driver_bench, not here)
// not later either.
TEST(RobotSim, PacedServoAnswersAfterTheRequestTheLatencyAndTheAnswerOnTheLine) {
  SimOptions options = onlyServoBus();
  options.pace_baud = 9600;
  options.servo_bus.answer_latency_s = 0.005;
  RobotSim sim(options);
  sim.start();
  Host host(slaveOf(sim), servoHostConfig());
  ASSERT_TRUE(host.ok());
  for (int round = 0; round < 3; ++round) {
    host.frames().clear();
    const auto start = Clock::now();
    host.send(kReadAngle0);
    ASSERT_TRUE(host.waitForFrame(kReadAngle0ReplyZero, milliseconds(10000)));
    const double elapsed_s = std::chrono::duration<double>(Clock::now() - start).count();
    const double line_s = (kReadAngle0.size() + kReadAngle0ReplyZero.size()) * 10.0 / 9600.0;
    EXPECT_GE(elapsed_s, line_s + 0.005 - 0.0005);
  }
}

TEST(RobotSim, ServoFaultsGarbleOrSuppressAnswers) {
  SimOptions options = onlyServoBus();
  options.faults.servo_fault_rate = 1.0;
  RobotSim sim(options);
  sim.start();
  Host host(slaveOf(sim), servoHostConfig());
  ASSERT_TRUE(host.ok());
  for (int i = 0; i < 20; ++i) host.send(kPing3);
  ASSERT_TRUE(waitForStats(sim, [](const SimStats& s) { return s.servo_bus.answers == 20; }));
  for (int i = 0; i < 5; ++i) host.pump(20);
  host.feedPadding();
  const SendCounters answers =
      sim.stats().sent[static_cast<std::size_t>(OutputKind::kServoResponse)];
  EXPECT_EQ(answers.intact, 0u);
  EXPECT_GT(answers.suppressed, 0u);
  EXPECT_GT(answers.damaged, 0u);
  EXPECT_EQ(answers.suppressed + answers.damaged, 20u);
  EXPECT_EQ(host.countFrames(kPing3Reply), 0u);
}

TEST(RobotSim, UnplugRemovesTheLinkAndReplugRecreatesIt) {
  TempDir dir;
  SimOptions options = onlyBody();
  options.link = dir.file("robot");
  options.faults.unplug_every_s = 0.2;
  options.faults.unplug_duration_s = 0.3;
  std::mutex events_mutex;
  std::vector<std::string> events;
  options.on_event = [&](const std::string& text) {
    std::lock_guard<std::mutex> lock(events_mutex);
    events.push_back(text);
  };
  RobotSim sim(options);
  sim.start();
  struct stat info {};
  ASSERT_TRUE(waitForStats(sim, [](const SimStats& s) { return s.unplugs >= 1; }));
  const bool link_gone = ::lstat(options.link.c_str(), &info) != 0;
  const bool still_unplugged = sim.stats().replugs == 0;
  if (still_unplugged) {
    EXPECT_TRUE(link_gone);
  }
  ASSERT_TRUE(waitForStats(sim, [](const SimStats& s) { return s.replugs >= 1; }));
  sim.stop();
  char target[256] = {};
  ASSERT_GT(::readlink(options.link.c_str(), target, sizeof(target) - 1), 0);
  EXPECT_EQ(std::string(target), sim.ports().at(0).slave_path);
  std::lock_guard<std::mutex> lock(events_mutex);
  ASSERT_GE(events.size(), 2u);
  EXPECT_NE(events[0].find("unplugged"), std::string::npos);
}

TEST(RobotSim, StatsFileHasKeyValueLines) {
  TempDir dir;
  SimOptions options;
  options.stats_file = dir.file("stats");
  RobotSim sim(options);
  sim.start();
  {
    Host host(slaveOf(sim), baseHostConfig());
    ASSERT_TRUE(host.ok());
    host.send(kResetSeq2);
    ASSERT_TRUE(waitForStats(sim, [](const SimStats& s) {
      return s.base.resets == 1 && s.body.telemetry_generated > 2;
    }));
  }
  sim.stop();
  std::ifstream in(options.stats_file);
  ASSERT_TRUE(in.good());
  std::map<std::string, std::string> values;
  std::string key, value;
  while (in >> key >> value) values[key] = value;
  for (const char* expected :
       {"telemetry_sent_intact", "base_frames_received", "base_resets", "base_speed_frames_applied",
        "base_speed_frames_ignored", "base_errors_sent", "left_ticks", "right_ticks",
        "last_left_speed", "last_right_speed", "sync_writes_ok", "sync_writes_bad",
        "servo_1_position", "servo_2_position", "servo_requests", "bus_servo_0_angle_deg"}) {
    EXPECT_EQ(values.count(expected), 1u) << expected;
  }
  EXPECT_EQ(values["base_resets"], "1");
  EXPECT_NE(values["telemetry_sent_intact"], "0");
}

// --- command line ----------------------------------------------------------------------------

CommandLine parse(std::vector<const char*> args) {
  args.insert(args.begin(), "robot_sim");
  return parseCommandLine(static_cast<int>(args.size()), args.data());
}

TEST(RobotSimCommandLine, ParsesFlagsAndIgnoresRoslaunchArguments) {
  const CommandLine line =
      parse({"--servo-ids", "3,4,5", "--foot-alternate", "__name:=sim", "__log:=/tmp/x.log",
             "--seed=9", "--corrupt-rate", "0.5", "--base-link", "/tmp/b", "--no-servo-bus",
             "--battery", "40", "--telemetry-rate", "0", "--offline-ids", "7"});
  ASSERT_TRUE(line.error.empty()) << line.error;
  EXPECT_FALSE(line.help);
  EXPECT_EQ(line.options.body.servo_ids, (std::vector<uint8_t>{3, 4, 5}));
  EXPECT_EQ(line.options.body.foot_mode, FootMode::kAlternate);
  EXPECT_EQ(line.options.faults.seed, 9u);
  EXPECT_DOUBLE_EQ(line.options.faults.corrupt_rate, 0.5);
  EXPECT_EQ(line.options.base_link.value_or(""), "/tmp/b");
  EXPECT_FALSE(line.options.body_link.has_value());
  EXPECT_FALSE(line.options.enable_servo_bus);
  EXPECT_EQ(line.options.base.battery_percent, 40);
  EXPECT_DOUBLE_EQ(line.options.body.telemetry_rate_hz, 0.0);
  EXPECT_EQ(line.options.servo_bus.offline_ids, (std::vector<uint8_t>{7}));
  EXPECT_EQ(line.options.pace_baud, 0u);  // off unless asked for
  EXPECT_EQ(parse({"--pace-baud", "115200"}).options.pace_baud, 115200u);
}

TEST(RobotSimCommandLine, RejectsUnknownFlagsAndBadValues) {
  EXPECT_FALSE(parse({"--bogus"}).error.empty());
  EXPECT_FALSE(parse({"--pace-baud", "fast"}).error.empty());
  EXPECT_FALSE(parse({"--corrupt-rate", "1.5"}).error.empty());
  EXPECT_FALSE(parse({"--servo-ids", "1,x"}).error.empty());
  EXPECT_FALSE(parse({"--servo-ids", "255"}).error.empty());
  EXPECT_FALSE(parse({"--battery"}).error.empty());
  EXPECT_FALSE(parse({"--foot=1"}).error.empty());
  EXPECT_FALSE(parse({"--no-base", "--no-body", "--no-servo-bus"}).error.empty());
  EXPECT_TRUE(parse({"--help"}).help);
}

TEST(RobotSimCommandLine, HelpListsTheFlagsWithTheirDefaults) {
  const std::string text = usage();
  for (const char* expected :
       {"--battery PCT", "battery percent the base reports (default 87)", "--servo-ids 1,2",
        "(default 1,2)", "--telemetry-rate HZ", "(default 50)", "--servo-latency-ms MS",
        "(default 1.5)", "--no-servo-bus", "--foot-alternate", "--seed N", "--stats-file PATH",
        "--unplug-duration S", "Faults (seeded):"}) {
    EXPECT_NE(text.find(expected), std::string::npos) << expected << " missing from:\n" << text;
  }
}

}  // namespace
}  // namespace serial_robot_driver::sim
