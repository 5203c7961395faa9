// Each simulated device alone behind RobotSim's pty, with the test playing the host through the
// slave path and byte vectors written out by hand from docs/protocols.md.
#include <gtest/gtest.h>

#include "support/sim_host.h"

namespace serial_robot_driver::sim {
namespace {

using namespace sim_test;  // NOLINT: the shared fixture

// --- the base on a pty -----------------------------------------------------------------------

TEST(RobotSimBase, AnswersBatteryRequestsAndCountsResets) {
  SimOptions options = onlyBase();
  devices::base::sim::baseConfig(options).battery_percent = 64;
  RobotSim sim(options);
  sim.start();
  Host host(slaveOf(sim), baseHostConfig());
  ASSERT_TRUE(host.ok());
  host.send(kBatteryRequestSeq1);
  host.send(kResetSeq2);
  EXPECT_TRUE(host.waitForFrame(kBattery64ReplySeq0));
  EXPECT_TRUE(waitForStats(
      sim, [](const SimStats& s) { return devices::base::sim::baseStats(s).resets == 1; }));
  const SimStats stats = sim.stats();
  EXPECT_EQ(devices::base::sim::baseStats(stats).frames_received, 2u);
  EXPECT_EQ(devices::base::sim::baseStats(stats).battery_requests, 1u);
  EXPECT_EQ(devices::base::sim::baseStats(stats).seq_gaps, 0u);
  EXPECT_EQ(stats.sentOf(devices::base::sim::kBaseReplyOutput).intact, 1u);
}

TEST(RobotSimBase, SpeedFramesIntegrateAndClearEncodersZeroes) {
  RobotSim sim(onlyBase());
  sim.start();
  Host host(slaveOf(sim), baseHostConfig());
  ASSERT_TRUE(host.ok());
  host.send(kBoth4Seq0);
  ASSERT_TRUE(waitForStats(
      sim, [](const SimStats& s) { return devices::base::sim::baseStats(s).left_ticks >= 40; }));
  host.send(kBoth0Seq1);
  ASSERT_TRUE(waitForStats(sim, [](const SimStats& s) {
    return devices::base::sim::baseStats(s).speed_frames_applied == 2;
  }));
  SimStats stats = sim.stats();
  EXPECT_EQ(devices::base::sim::baseStats(stats).left_ticks,
            devices::base::sim::baseStats(stats).right_ticks);
  EXPECT_EQ(devices::base::sim::baseStats(stats).left_ticks % 4, 0);
  EXPECT_EQ(devices::base::sim::baseStats(stats).last_left_speed, 0);

  host.send(kClearEncodersSeq3);  // SEQ 03 after 01: one gap
  ASSERT_TRUE(waitForStats(
      sim, [](const SimStats& s) { return devices::base::sim::baseStats(s).encoder_clears == 1; }));
  stats = sim.stats();
  EXPECT_EQ(devices::base::sim::baseStats(stats).left_ticks, 0);
  EXPECT_EQ(devices::base::sim::baseStats(stats).right_ticks, 0);
  EXPECT_EQ(devices::base::sim::baseStats(stats).seq_gaps, 1u);

  host.send(kBothMinus6Seq0);  // SEQ 00 after 03: another gap
  ASSERT_TRUE(waitForStats(
      sim, [](const SimStats& s) { return devices::base::sim::baseStats(s).left_ticks <= -12; }));
  stats = sim.stats();
  EXPECT_EQ(devices::base::sim::baseStats(stats).last_left_speed, -6);
  EXPECT_EQ(devices::base::sim::baseStats(stats).last_right_speed, -6);
  EXPECT_EQ(devices::base::sim::baseStats(stats).seq_gaps, 2u);
}

TEST(RobotSimBase, SilenceRaisesTheTimeoutErrorAndSpeedIsIgnoredUntilReset) {
  RobotSim sim(onlyBase());
  sim.start();
  Host host(slaveOf(sim), baseHostConfig());
  ASSERT_TRUE(host.ok());
  // Nothing sent since power-on: after 1 s the base reports FF.
  ASSERT_TRUE(host.waitForFrame(kErrorStatusSeq0));
  host.send(kBoth4Seq0);
  ASSERT_TRUE(waitForStats(sim, [](const SimStats& s) {
    return devices::base::sim::baseStats(s).speed_frames_ignored == 1;
  }));
  EXPECT_EQ(devices::base::sim::baseStats(sim.stats()).left_ticks, 0);
  EXPECT_TRUE(devices::base::sim::baseStats(sim.stats()).in_error);

  host.send(kResetSeq1);
  host.send(kBoth4Seq2);
  ASSERT_TRUE(waitForStats(
      sim, [](const SimStats& s) { return devices::base::sim::baseStats(s).left_ticks > 0; }));
  const SimStats stats = sim.stats();
  EXPECT_FALSE(devices::base::sim::baseStats(stats).in_error);
  EXPECT_EQ(devices::base::sim::baseStats(stats).resets, 1u);
  EXPECT_EQ(devices::base::sim::baseStats(stats).speed_frames_applied, 1u);
  EXPECT_GE(devices::base::sim::baseStats(stats).errors_sent, 1u);
}

// --- the body on a pty -----------------------------------------------------------------------

TEST(RobotSimBody, TelemetryDecodesWithGravityOnZ) {
  RobotSim sim(onlyBody());
  sim.start();
  Host host(slaveOf(sim), bodyHostConfig(2));
  ASSERT_TRUE(host.ok());
  ASSERT_TRUE(
      host.waitUntil([&] { return host.framesOf(devices::body::kTelemetryFrames).size() >= 5; }));
  for (const Bytes& frame : host.framesOf(devices::body::kTelemetryFrames)) {
    ASSERT_EQ(frame.size(), 32u);
    EXPECT_EQ(frame[2], 0x20);
    // Servo 0 at 2048 (08 00), standing still.
    EXPECT_EQ(frame[3], 0x08);
    EXPECT_EQ(frame[4], 0x00);
    const auto telemetry = devices::body::decodeTelemetry(frame.data(), frame.size(), 2);
    ASSERT_TRUE(telemetry.ok());
    EXPECT_EQ(telemetry->servos[0].position, 2048);
    EXPECT_EQ(telemetry->servos[1].position, 2048);
    EXPECT_EQ(telemetry->servos[0].speed, 0);
    EXPECT_EQ(telemetry->imu[devices::body::kAccelZ], 2048);  // 1 g at 16 g full scale
    EXPECT_EQ(telemetry->imu[devices::body::kGyroZ], 0);
    EXPECT_FALSE(telemetry->has_foot);
  }
}

TEST(RobotSimBody, SyncWriteMovesTheServoTowardItsTarget) {
  SimOptions options = onlyBody();
  devices::body::sim::bodyConfig(options).servo_ids = {2, 3};
  devices::body::sim::bodyConfig(options).servo_speed = 4096;
  RobotSim sim(options);
  sim.start();
  Host host(slaveOf(sim), bodyHostConfig(2));
  ASSERT_TRUE(host.ok());
  host.send(kSyncWrite2And3);
  bool saw_full_speed = false;
  const auto reached = [&] {
    for (const Bytes& frame : host.framesOf(devices::body::kTelemetryFrames)) {
      const auto telemetry = devices::body::decodeTelemetry(frame.data(), frame.size(), 2);
      if (!telemetry) continue;
      EXPECT_EQ(telemetry->servos[0].position, 2048);
      if (telemetry->servos[1].speed == -4096) saw_full_speed = true;
      if (telemetry->servos[1].position == 1024 && telemetry->servos[1].speed == 0) return true;
    }
    return false;
  };
  EXPECT_TRUE(host.waitUntil(reached));
  EXPECT_TRUE(saw_full_speed);
  EXPECT_EQ(devices::body::sim::bodyStats(sim.stats()).sync_writes_ok, 1u);
}

TEST(RobotSimBody, BadCrcAndUnknownIdsAreCounted) {
  SimOptions options = onlyBody();
  devices::body::sim::bodyConfig(options).servo_ids = {2};
  RobotSim sim(options);
  sim.start();
  Host host(slaveOf(sim), bodyHostConfig(1));
  ASSERT_TRUE(host.ok());
  Bytes bad_crc = kSyncWrite2And3;
  bad_crc.back() ^= 0xFF;
  host.send(bad_crc);
  host.send(kSyncWrite2And3);  // id 3 is not on this board
  ASSERT_TRUE(waitForStats(
      sim, [](const SimStats& s) { return devices::body::sim::bodyStats(s).sync_writes_ok == 1; }));
  const SimStats stats = sim.stats();
  EXPECT_EQ(devices::body::sim::bodyStats(stats).sync_write_unknown_ids, 1u);
  EXPECT_GE(devices::body::sim::bodyStats(stats).port_checksum_errors, 1u);
  EXPECT_NE(formatStats(stats).find("sync_writes_bad 1\n"), std::string::npos);
}

TEST(RobotSimBody, FootAlternateInterleavesFrameLengths) {
  SimOptions options = onlyBody();
  devices::body::sim::bodyConfig(options).foot_mode = devices::body::sim::FootMode::kAlternate;
  RobotSim sim(options);
  sim.start();
  Host host(slaveOf(sim), bodyHostConfig(2));
  ASSERT_TRUE(host.ok());
  ASSERT_TRUE(
      host.waitUntil([&] { return host.framesOf(devices::body::kTelemetryFrames).size() >= 6; }));
  const auto frames = host.framesOf(devices::body::kTelemetryFrames);
  for (std::size_t i = 1; i < frames.size(); ++i) EXPECT_NE(frames[i].size(), frames[i - 1].size());
  for (const Bytes& frame : frames) {
    ASSERT_TRUE(frame.size() == 32u || frame.size() == 48u);
    const auto telemetry = devices::body::decodeTelemetry(frame.data(), frame.size(), 2);
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
    EXPECT_TRUE(host_->framesOf(devices::servo_bus::kResponseFrames).empty());
  }
  std::unique_ptr<RobotSim> sim_;
  std::unique_ptr<Host> host_;
};

TEST_F(RobotSimServoBus, PingAnswersOnlineServosOnly) {
  expectReply(kPing3, kPing3Reply);
  expectSilence(kPing7);  // configured offline
  expectReply(kPing3, kPing3Reply);
  const SimStats stats = sim_->stats();
  EXPECT_EQ(devices::servo_bus::sim::servoBusStats(stats).requests, 3u);
  EXPECT_EQ(devices::servo_bus::sim::servoBusStats(stats).unaddressed, 1u);
  EXPECT_EQ(devices::servo_bus::sim::servoBusStats(stats).answers, 2u);
}

TEST_F(RobotSimServoBus, VoltageReadIsPlausible) {
  host_->send(kReadVoltage0);
  ASSERT_TRUE(host_->waitUntil(
      [&] { return !host_->framesOf(devices::servo_bus::kResponseFrames).empty(); }));
  const Bytes reply = host_->framesOf(devices::servo_bus::kResponseFrames).at(0);
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
  EXPECT_EQ(devices::servo_bus::sim::servoBusStats(sim_->stats()).unknown_data_ids, 1u);
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
  for (const Bytes& frame : host_->framesOf(devices::servo_bus::kResponseFrames))
    EXPECT_EQ(frame[2], 0x0A);
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
  const auto servos = devices::servo_bus::sim::servoBusStats(sim_->stats()).servos;
  EXPECT_EQ(std::count_if(servos.begin(), servos.end(),
                          [](const devices::servo_bus::sim::BusServoSnapshot& servo) {
                            return servo.id == 0;
                          }),
            2);
}

TEST_F(RobotSimServoBus, BatchReadAndWriteOfTheUserBlock) {
  host_->send(kReadBatch0);
  ASSERT_TRUE(host_->waitUntil(
      [&] { return !host_->framesOf(devices::servo_bus::kResponseFrames).empty(); }));
  Bytes reply = host_->framesOf(devices::servo_bus::kResponseFrames).at(0);
  ASSERT_EQ(reply.size(), 5u + 33u);
  EXPECT_EQ(reply[2], 0x05);
  EXPECT_EQ(reply[3], 33);
  const uint8_t* block = &reply[5];
  EXPECT_EQ(block[1], 0);                         // response_switch
  EXPECT_EQ(block[2], 0);                         // servo_id
  EXPECT_EQ(block[4], 5);                         // baudrate 115200
  EXPECT_EQ(block[18], 1);                        // accel_switch
  EXPECT_EQ(block[26] | (block[27] << 8), 1800);  // angle_limit_high, 180.0 deg

  std::array<uint8_t, devices::servo_bus::kUserBlockSize> new_block{};
  std::copy(block, block + new_block.size(), new_block.begin());
  new_block[26] = 0x84;  // angle_limit_high := 900
  new_block[27] = 0x03;
  host_->frames().clear();
  host_->send(devices::servo_bus::encodeWriteBatchData(0, new_block));
  EXPECT_TRUE(host_->waitForFrame({0x05, 0x1C, 0x06, 0x02, 0x00, 0x01, 0x2A}));
  const auto servos = devices::servo_bus::sim::servoBusStats(sim_->stats()).servos;
  ASSERT_FALSE(servos.empty());
  EXPECT_EQ(servos[0].params.at(51), 900);
}

TEST_F(RobotSimServoBus, BroadcastActsOnAllAndAnswersNone) {
  expectSilence(kRotateAllTo45);
  ASSERT_TRUE(waitForStats(*sim_, [](const SimStats& s) {
    return std::all_of(devices::servo_bus::sim::servoBusStats(s).servos.begin(),
                       devices::servo_bus::sim::servoBusStats(s).servos.end(),
                       [](const devices::servo_bus::sim::BusServoSnapshot& servo) {
                         return servo.angle_deg == 45.0;
                       });
  }));
  EXPECT_EQ(devices::servo_bus::sim::servoBusStats(sim_->stats()).broadcasts, 1u);
}

}  // namespace
}  // namespace serial_robot_driver::sim
