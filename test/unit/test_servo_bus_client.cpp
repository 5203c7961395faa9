// ServoBusClient against a fake bus: the write seam records every frame and answers synchronously
// by calling onFrame() with response bytes written out by hand from docs/protocols.md, section 3.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <map>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "serial_robot_driver/device/servo_bus_client.h"
#include "support/golden_frames.h"

namespace serial_robot_driver::device {
namespace {

using Bytes = std::vector<uint8_t>;
using protocol::FrameFamily;

using namespace golden::servo;  // NOLINT: the frames shared with the rostest

// --- more golden frames (docs/protocols.md, section 3; SUM = byte sum mod 256, values
// little-endian) -
const Bytes kPing5Reply = {0x05, 0x1C, 0x01, 0x01, 0x05, 0x28};
// A PING answer with two content bytes: right CMD and id, wrong shape.
const Bytes kPing3ReplyTooLong = {0x05, 0x1C, 0x01, 0x02, 0x03, 0x00, 0x27};

// WRITE_DATA id 3 soft_start_time: refused (result 0), and a read-back of 200.
const Bytes kWriteSoftStart3Failed = {0x05, 0x1C, 0x04, 0x03, 0x03, 0x32, 0x00, 0x5D};
const Bytes kReadSoftStart3Reply200 = {0x05, 0x1C, 0x03, 0x04, 0x03, 0x32, 0xC8, 0x00, 0x25};

// The bus: records what the client writes and plays the servos by answering synchronously.
class FakeBus {
 public:
  bool connected = true;
  bool echo = false;          // send our own request back first, like a half-duplex adapter
  bool drop_link_on_write = false;
  bool from_other_thread = false;  // answer from a thread of its own, like the link's reader
  ServoBusClient* client = nullptr;
  std::vector<Bytes> written;

  ~FakeBus() { joinAnswerThreads(); }
  void joinAnswerThreads() {
    for (std::thread& thread : answer_threads_) thread.join();
    answer_threads_.clear();
  }

  /// After `request`, deliver `frames`, starting with its `first_answered_write`-th occurrence.
  void answer(const Bytes& request, std::vector<Bytes> frames, int first_answered_write = 1) {
    script_[request] = Script{std::move(frames), first_answered_write, 0};
  }

  bool write(const Bytes& frame) {
    if (!connected) return false;
    std::lock_guard<std::mutex> lock(mutex_);  // two callers may write (the client serializes them)
    written.push_back(frame);
    if (echo) deliver(protocol::servo::kRequestFrames, frame);
    if (drop_link_on_write) client->onLinkDown();
    auto it = script_.find(frame);
    if (it == script_.end()) return true;
    Script& script = it->second;
    if (++script.writes < script.first_answered_write) return true;
    if (from_other_thread) {
      answer_threads_.emplace_back([this, frames = script.frames] {
        for (const Bytes& reply : frames) deliver(protocol::servo::kResponseFrames, reply);
      });
      return true;
    }
    for (const Bytes& reply : script.frames) deliver(protocol::servo::kResponseFrames, reply);
    return true;
  }

 private:
  struct Script {
    std::vector<Bytes> frames;
    int first_answered_write;
    int writes;
  };
  void deliver(FrameFamily family, const Bytes& frame) {
    client->onFrame(family, frame.data(), frame.size(), Clock::now());
  }
  std::map<Bytes, Script> script_;
  std::mutex mutex_;
  std::vector<std::thread> answer_threads_;
};

ServoBusOptions testOptions(bool armed) {
  ServoBusOptions options;
  options.timeout = std::chrono::milliseconds(20);
  options.retries = 1;
  options.allow_dangerous_writes = armed;
  return options;
}

class ServoBusClientTest : public ::testing::Test {
 protected:
  explicit ServoBusClientTest(bool armed = false)
      : client_(testOptions(armed), [this](const Bytes& frame) { return bus_.write(frame); }) {
    bus_.client = &client_;
  }

  FakeBus bus_;
  ServoBusClient client_;
};

class ServoBusClientArmedTest : public ServoBusClientTest {
 protected:
  ServoBusClientArmedTest() : ServoBusClientTest(true) {}
};

TEST_F(ServoBusClientTest, PingOnlineSendsGoldenRequest) {
  bus_.answer(kPing3, {kPing3Reply});
  const ServoStatus status = client_.ping(3);
  EXPECT_TRUE(status.ok()) << status.message;
  EXPECT_EQ(bus_.written, std::vector<Bytes>{kPing3});
  EXPECT_NE(status.message.find("servo 3 is online"), std::string::npos) << status.message;
  const ServoBusStats stats = client_.stats();
  EXPECT_EQ(stats.transactions, 1u);
  EXPECT_EQ(stats.retries, 0u);
  EXPECT_EQ(stats.timeouts, 0u);
}

TEST_F(ServoBusClientTest, PingOfflineTriesRetriesPlusOneTimes) {
  const ServoStatus status = client_.ping(7);
  EXPECT_EQ(status.error, ServoError::kTimeout);
  EXPECT_EQ(status.message, "servo 7 did not answer PING within 20 ms (2 attempts)");
  EXPECT_EQ(bus_.written, (std::vector<Bytes>{kPing7, kPing7}));
  const ServoBusStats stats = client_.stats();
  EXPECT_EQ(stats.transactions, 1u);
  EXPECT_EQ(stats.retries, 1u);
  EXPECT_EQ(stats.timeouts, 1u);
}

TEST_F(ServoBusClientTest, AnswerToTheRetryCompletesTheTransaction) {
  bus_.answer(kPing3, {kPing3Reply}, /*first_answered_write=*/2);
  const ServoStatus status = client_.ping(3);
  EXPECT_TRUE(status.ok()) << status.message;
  EXPECT_EQ(bus_.written.size(), 2u);
  EXPECT_EQ(client_.stats().retries, 1u);
  EXPECT_EQ(client_.stats().timeouts, 0u);
}

TEST_F(ServoBusClientTest, MismatchedAnswersAreCountedAndIgnored) {
  // Another servo's PING answer and an answer to another command come first.
  bus_.answer(kPing3, {kPing4Reply, kReadAngle0Reply902, kPing3Reply});
  const ServoStatus status = client_.ping(3);
  EXPECT_TRUE(status.ok()) << status.message;
  EXPECT_EQ(client_.stats().mismatched, 2u);
  EXPECT_EQ(bus_.written.size(), 1u);
}

TEST_F(ServoBusClientTest, OnlyMismatchedAnswersMeanOffline) {
  bus_.answer(kPing7, {kPing4Reply});
  const ServoStatus status = client_.ping(7);
  EXPECT_EQ(status.error, ServoError::kTimeout);
  EXPECT_EQ(client_.stats().mismatched, 2u);
}

TEST_F(ServoBusClientTest, EchoOfOurRequestIsSkipped) {
  bus_.echo = true;
  bus_.answer(kPing3, {kPing3Reply});
  const ServoStatus status = client_.ping(3);
  EXPECT_TRUE(status.ok()) << status.message;
  EXPECT_EQ(client_.stats().echoes, 1u);
  EXPECT_EQ(client_.stats().mismatched, 0u);
}

TEST_F(ServoBusClientTest, AnswerOfTheWrongShapeIsReportedAsMalformed) {
  bus_.answer(kPing3, {kPing3ReplyTooLong});
  const ServoStatus status = client_.ping(3);
  EXPECT_EQ(status.error, ServoError::kBadAnswer);
  EXPECT_EQ(bus_.written.size(), 2u);  // re-sent once
  EXPECT_EQ(client_.stats().garbled, 2u);
}

TEST_F(ServoBusClientTest, AnswersArrivingWithoutARequestAreMismatched) {
  client_.onFrame(protocol::servo::kResponseFrames, kPing3Reply.data(), kPing3Reply.size(),
                  Clock::now());
  EXPECT_EQ(client_.stats().mismatched, 1u);
}

TEST(ServoBusClientThreadsTest, ConcurrentCallersAreServedOneAfterTheOther) {
  FakeBus bus;
  bus.from_other_thread = true;
  ServoBusOptions options;
  options.timeout = std::chrono::milliseconds(5000);  // generous: the answer comes from a thread
  ServoBusClient client(options, [&bus](const Bytes& frame) { return bus.write(frame); });
  bus.client = &client;
  bus.answer(kPing3, {kPing3Reply});
  bus.answer(kReadVoltage3, {kReadVoltage3Reply});

  ServoStatus ping_status;
  std::thread pinger([&] { ping_status = client.ping(3); });
  ServoParamValue voltage;
  const ServoStatus read_status = client.readParam(3, "voltage", &voltage);
  pinger.join();
  bus.joinAnswerThreads();
  EXPECT_TRUE(ping_status.ok()) << ping_status.message;
  EXPECT_TRUE(read_status.ok()) << read_status.message;
  EXPECT_EQ(voltage.value, 7400);
  EXPECT_EQ(client.stats().transactions, 2u);
  EXPECT_EQ(client.stats().mismatched, 0u);
  EXPECT_EQ(bus.written.size(), 2u);
}

TEST_F(ServoBusClientTest, PortDownFailsFast) {
  bus_.connected = false;
  const ServoStatus status = client_.ping(3);
  EXPECT_EQ(status.error, ServoError::kNotConnected);
  EXPECT_EQ(status.message, "servo bus port is not connected");
  EXPECT_EQ(client_.stats().timeouts, 0u);
}

TEST_F(ServoBusClientTest, PortLostWhileWaitingFailsWithoutWaitingOut) {
  bus_.drop_link_on_write = true;
  const ServoStatus status = client_.ping(3);
  EXPECT_EQ(status.error, ServoError::kNotConnected);
  EXPECT_EQ(bus_.written.size(), 1u);  // not re-sent on a dead port
}

TEST_F(ServoBusClientTest, ShutdownFailsLaterCalls) {
  client_.shutdown();
  EXPECT_EQ(client_.ping(3).error, ServoError::kShutdown);
  EXPECT_TRUE(bus_.written.empty());
}

TEST_F(ServoBusClientTest, ReadUnsignedParameterInItsUnit) {
  bus_.answer(kReadVoltage3, {kReadVoltage3Reply});
  ServoParamValue value;
  const ServoStatus status = client_.readParam(3, "voltage", &value);
  ASSERT_TRUE(status.ok()) << status.message;
  EXPECT_EQ(value.value, 7400);
  EXPECT_EQ(value.unit, "mV");
  EXPECT_EQ(value.data_id, 1);
  EXPECT_EQ(bus_.written, std::vector<Bytes>{kReadVoltage3});
}

TEST_F(ServoBusClientTest, ReadSignedParameterByDataIdText) {
  bus_.answer(kReadLimitLow3, {kReadLimitLow3Reply});
  ServoParamValue value;
  const ServoStatus status = client_.readParam(3, "52", &value);
  ASSERT_TRUE(status.ok()) << status.message;
  EXPECT_EQ(value.value, -900);
  EXPECT_EQ(value.unit, "0.1deg");
  EXPECT_EQ(value.name, "angle_limit_low");
}

TEST_F(ServoBusClientTest, ReadAnswerAboutAnotherParameterIsIgnored) {
  bus_.answer(kReadLimitLow3, {kReadVoltage3Reply, kReadLimitLow3Reply});
  ServoParamValue value;
  ASSERT_TRUE(client_.readParam(3, "angle_limit_low", &value).ok());
  EXPECT_EQ(value.value, -900);
  EXPECT_EQ(client_.stats().mismatched, 1u);
}

TEST_F(ServoBusClientTest, ReadAngleInDegrees) {
  bus_.answer(kReadAngle0, {kReadAngle0Reply902});
  double angle = 0.0;
  const ServoStatus status = client_.readAngle(0, &angle);
  ASSERT_TRUE(status.ok()) << status.message;
  EXPECT_DOUBLE_EQ(angle, 90.2);
  EXPECT_EQ(bus_.written, std::vector<Bytes>{kReadAngle0});
}

TEST_F(ServoBusClientTest, WriteIsReadBack) {
  bus_.answer(kWriteSoftStart3, {kWriteSoftStart3Ok});
  bus_.answer(kReadSoftStart3, {kReadSoftStart3Reply300});
  const ServoStatus status = client_.writeParam(3, "soft_start_time", 300);
  EXPECT_TRUE(status.ok()) << status.message;
  EXPECT_EQ(bus_.written, (std::vector<Bytes>{kWriteSoftStart3, kReadSoftStart3}));
}

TEST_F(ServoBusClientTest, WriteResultZeroIsAFailureWithoutReadBack) {
  bus_.answer(kWriteSoftStart3, {kWriteSoftStart3Failed});
  const ServoStatus status = client_.writeParam(3, "50", 300);
  EXPECT_EQ(status.error, ServoError::kRefused);
  EXPECT_EQ(bus_.written, std::vector<Bytes>{kWriteSoftStart3});
}

TEST_F(ServoBusClientTest, WriteWithDifferentReadBackFails) {
  bus_.answer(kWriteSoftStart3, {kWriteSoftStart3Ok});
  bus_.answer(kReadSoftStart3, {kReadSoftStart3Reply200});
  const ServoStatus status = client_.writeParam(3, "soft_start_time", 300);
  EXPECT_EQ(status.error, ServoError::kReadBackMismatch);
  EXPECT_NE(status.message.find("reads back 200"), std::string::npos) << status.message;
}

TEST_F(ServoBusClientTest, RotateSendsGoldenFrameWithoutWaiting) {
  RotateRequest request;
  request.id = 2;
  request.angle_deg = 90.0;
  request.interval_ms = 500;
  const ServoStatus status = client_.rotate(request);
  EXPECT_TRUE(status.ok()) << status.message;
  EXPECT_EQ(bus_.written, std::vector<Bytes>{kRotate2To90In500});
  EXPECT_EQ(client_.stats().commands, 1u);
  EXPECT_EQ(client_.stats().transactions, 0u);
}

TEST_F(ServoBusClientTest, RotateWithWaitGetsTheCompletionAnswer) {
  bus_.answer(kRotate2To90In500, {kRotate2Done});
  RotateRequest request;
  request.id = 2;
  request.angle_deg = 90.0;
  request.interval_ms = 500;
  request.wait = true;
  const ServoStatus status = client_.rotate(request);
  EXPECT_TRUE(status.ok()) << status.message;
  EXPECT_EQ(client_.stats().transactions, 1u);
}

TEST_F(ServoBusClientTest, MotionWaitTimesOutWithoutResending) {
  const ServoStatus status = client_.damping(0, 500, /*wait=*/true);
  EXPECT_EQ(status.error, ServoError::kTimeout);
  EXPECT_NE(status.message.find("response_switch"), std::string::npos) << status.message;
  EXPECT_EQ(bus_.written, std::vector<Bytes>{kDamping0At500});
}

TEST_F(ServoBusClientTest, SpinAndDampingSendGoldenFrames) {
  SpinRequest spin;
  spin.id = 0;
  spin.mode = 1;
  spin.speed_dps = 100;
  ASSERT_TRUE(client_.spin(spin).ok());
  spin.clockwise = true;
  spin.mode = 2;
  spin.value = 5;
  ASSERT_TRUE(client_.spin(spin).ok());
  ASSERT_TRUE(client_.damping(0, 500, false).ok());
  EXPECT_EQ(bus_.written,
            (std::vector<Bytes>{kSpin0CcwContinuous, kSpin0Cw5Turns, kDamping0At500}));
}

TEST_F(ServoBusClientTest, BroadcastMotionWithoutWaitIsAllowed) {
  RotateRequest rotate;
  rotate.id = 255;
  EXPECT_TRUE(client_.rotate(rotate).ok());
  SpinRequest spin;
  spin.id = 255;
  EXPECT_TRUE(client_.spin(spin).ok());
  EXPECT_TRUE(client_.damping(255, 0, false).ok());
  EXPECT_EQ(bus_.written.size(), 3u);
}

TEST_F(ServoBusClientTest, ReadAllDecodesTheUserBlock) {
  bus_.answer(kReadBatch3, {kReadBatch3Reply});
  std::vector<ServoParamValue> values;
  const ServoStatus status = client_.readAll(3, &values);
  ASSERT_TRUE(status.ok()) << status.message;
  EXPECT_EQ(bus_.written, std::vector<Bytes>{kReadBatch3});

  const std::vector<std::pair<std::string, int64_t>> expected = {
      {"reserved_32", 0},         {"response_switch", 0},     {"servo_id", 3},
      {"reserved_35", 0},         {"baudrate", 5},            {"stall_protect_mode", 1},
      {"stall_power_limit", 4000}, {"over_volt_low", 4500},   {"over_volt_high", 14000},
      {"over_temperature", 80},   {"over_power", 12000},      {"over_current", 3000},
      {"accel_switch", 1},        {"reserved_45", 0},         {"po_lock_switch", 0},
      {"wb_lock_switch", 1},      {"angle_limit_switch", 1},  {"soft_start_switch", 0},
      {"soft_start_time", 300},   {"angle_limit_high", 1800}, {"angle_limit_low", -1800},
      {"angle_mid_offset", -5}};
  ASSERT_EQ(values.size(), 22u);
  for (std::size_t i = 0; i < expected.size(); ++i) {
    EXPECT_EQ(values[i].name, expected[i].first) << i;
    EXPECT_EQ(values[i].value, expected[i].second) << values[i].name;
    EXPECT_EQ(values[i].data_id, 32 + i);
  }
  EXPECT_EQ(values[6].unit, "mW");
  EXPECT_EQ(values[20].unit, "0.1deg");
}

TEST_F(ServoBusClientArmedTest, ServoIdChangePingsTheNewIdThenReadsBackThere) {
  bus_.answer(kWriteServoId3To5, {kWriteServoId3To5Ok});
  bus_.answer(kReadServoId5, {kReadServoId5Reply});
  const ServoStatus status = client_.writeParam(3, "servo_id", 5);
  EXPECT_TRUE(status.ok()) << status.message;
  // PING 5 twice (nobody there), then the write, then the read-back at the new id.
  EXPECT_EQ(bus_.written,
            (std::vector<Bytes>{kPing5, kPing5, kWriteServoId3To5, kReadServoId5}));
}

TEST_F(ServoBusClientArmedTest, ServoIdChangeRefusedWhenTheNewIdAnswers) {
  bus_.answer(kPing5, {kPing5Reply});
  const ServoStatus status = client_.writeParam(3, "servo_id", 5);
  EXPECT_EQ(status.error, ServoError::kIdInUse);
  EXPECT_EQ(bus_.written, std::vector<Bytes>{kPing5});
}

TEST_F(ServoBusClientArmedTest, ResetUserData) {
  bus_.answer(kResetUserData3, {kResetUserData3Ok});
  const ServoStatus status = client_.resetUserData(3);
  EXPECT_TRUE(status.ok()) << status.message;
  EXPECT_EQ(bus_.written, std::vector<Bytes>{kResetUserData3});
}

TEST_F(ServoBusClientArmedTest, ResetUserDataAnsweredFromTheDefaultId) {
  bus_.answer(kResetUserData3, {kResetUserDataOkFromId0});
  const ServoStatus status = client_.resetUserData(3);
  EXPECT_TRUE(status.ok()) << status.message;
  EXPECT_EQ(bus_.written, std::vector<Bytes>{kResetUserData3});
}

TEST_F(ServoBusClientArmedTest, SilentResetSucceedsWhenIdZeroAnswersPing) {
  bus_.answer(kPing0, {kPing0Reply});
  const ServoStatus status = client_.resetUserData(3);
  EXPECT_TRUE(status.ok()) << status.message;
  EXPECT_NE(status.message.find("id 0"), std::string::npos) << status.message;
  EXPECT_EQ(bus_.written, (std::vector<Bytes>{kResetUserData3, kPing0}));
}

TEST_F(ServoBusClientArmedTest, SilentResetWithNobodyAtIdZeroFails) {
  const ServoStatus status = client_.resetUserData(3);
  EXPECT_EQ(status.error, ServoError::kTimeout) << status.message;
  // retries = 1: two rounds of reset + PING 0.
  EXPECT_EQ(bus_.written, (std::vector<Bytes>{kResetUserData3, kPing0, kResetUserData3, kPing0}));
}

TEST_F(ServoBusClientTest, MoveChoosesTheCommandFromTheRequest) {
  MoveRequest plain;
  plain.id = 2;
  plain.angle_deg = 90.0;
  plain.interval_ms = 500;
  EXPECT_TRUE(client_.move(plain).ok());

  MoveRequest ramps;
  ramps.id = 1;
  ramps.angle_deg = 90.0;
  ramps.interval_ms = 1000;
  ramps.accel_ms = 100;
  ramps.decel_ms = 100;
  EXPECT_TRUE(client_.move(ramps).ok());

  MoveRequest velocity;
  velocity.id = 1;
  velocity.angle_deg = -90.0;
  velocity.velocity_dps = 360.0;
  velocity.accel_ms = 100;
  velocity.decel_ms = 100;
  EXPECT_TRUE(client_.move(velocity).ok());

  MoveRequest multi;
  multi.id = 1;
  multi.multi_turn = true;
  multi.angle_deg = 720.0;
  multi.interval_ms = 2000;
  EXPECT_TRUE(client_.move(multi).ok());

  MoveRequest multi_ramps;
  multi_ramps.id = 1;
  multi_ramps.multi_turn = true;
  multi_ramps.angle_deg = -360.0;
  multi_ramps.interval_ms = 1000;
  multi_ramps.accel_ms = 200;
  multi_ramps.decel_ms = 200;
  EXPECT_TRUE(client_.move(multi_ramps).ok());

  MoveRequest multi_velocity;
  multi_velocity.id = 1;
  multi_velocity.multi_turn = true;
  multi_velocity.angle_deg = 3600.0;
  multi_velocity.velocity_dps = 360.0;
  multi_velocity.accel_ms = 100;
  multi_velocity.decel_ms = 100;
  EXPECT_TRUE(client_.move(multi_velocity).ok());

  EXPECT_EQ(bus_.written,
            (std::vector<Bytes>{kRotate2To90In500, kMoveByInterval1To90, kMoveByVelocity1ToMinus90,
                                kMultiTurnMove1To720, kMultiTurnMoveByInterval1ToMinus360,
                                kMultiTurnMoveByVelocity1To3600}));
  EXPECT_EQ(client_.stats().commands, 6u);
}

TEST_F(ServoBusClientTest, MoveByVelocityWithoutRampsSendsTheShortestRamps) {
  MoveRequest velocity;
  velocity.id = 1;
  velocity.angle_deg = -90.0;
  velocity.velocity_dps = 360.0;
  ASSERT_TRUE(client_.move(velocity).ok());
  // CMD 12 id 1, -900 (7C FC), 3600 (10 0E), accel 20 (14 00), decel 20, power 0.
  // 5E+0C+0B+01+7C+FC+10+0E+14+14 = 0x234 -> 34
  const Bytes expected = {0x12, 0x4C, 0x0C, 0x0B, 0x01, 0x7C, 0xFC, 0x10,
                          0x0E, 0x14, 0x00, 0x14, 0x00, 0x00, 0x00, 0x34};
  EXPECT_EQ(bus_.written, std::vector<Bytes>{expected});
}

TEST_F(ServoBusClientTest, ReadMultiTurnAngle) {
  bus_.answer(kReadMultiTurn1, {kReadMultiTurn1Reply720});
  MultiTurnReading reading;
  const ServoStatus status = client_.readMultiTurnAngle(1, &reading);
  ASSERT_TRUE(status.ok()) << status.message;
  EXPECT_DOUBLE_EQ(reading.angle_deg, 720.0);
  EXPECT_EQ(reading.turns, 2);
  EXPECT_EQ(bus_.written, std::vector<Bytes>{kReadMultiTurn1});
}

TEST_F(ServoBusClientTest, ScanListsTheIdsThatAnswerWithOneAttemptEach) {
  bus_.answer(kPing3, {kPing3Reply});
  bus_.answer(kPing5, {kPing5Reply});
  std::vector<uint8_t> ids;
  const ServoStatus status = client_.scan(3, 7, &ids);
  ASSERT_TRUE(status.ok()) << status.message;
  EXPECT_EQ(ids, (std::vector<uint8_t>{3, 5}));
  // 3 silent ids (4, 6, 7) cost one PING each: no retries.
  ASSERT_EQ(bus_.written.size(), 5u);
  EXPECT_EQ(bus_.written.front(), kPing3);
  EXPECT_EQ(bus_.written.back(), kPing7);
  EXPECT_EQ(client_.stats().retries, 0u);
}

TEST(BusMutexTest, AWaitingForegroundCallerGoesBeforeBackgroundWork) {
  BusMutex bus;
  std::mutex order_mutex;
  std::vector<std::string> order;
  const auto record = [&](const char* who) {
    std::lock_guard<std::mutex> lock(order_mutex);
    order.push_back(who);
  };
  bus.lock();  // a transaction in progress
  std::thread foreground([&] {
    std::lock_guard<BusMutex> held(bus);
    record("foreground");
  });
  while (bus.foregroundWaiting() == 0) std::this_thread::yield();
  std::thread background([&] {
    bus.lockBackground();
    record("background");
    bus.unlock();
  });
  bus.unlock();
  foreground.join();
  background.join();
  EXPECT_EQ(order, (std::vector<std::string>{"foreground", "background"}));
}

// --- every rejection: the right error, a message naming the problem, and not one byte written ---

struct Rejection {
  const char* name;
  bool armed;
  ServoError error;
  const char* message_part;
  std::function<ServoStatus(ServoBusClient&)> call;
};

RotateRequest rotateTo(uint8_t id, double angle_deg, bool wait) {
  RotateRequest request;
  request.id = id;
  request.angle_deg = angle_deg;
  request.interval_ms = 100;
  request.wait = wait;
  return request;
}

SpinRequest spinWith(uint8_t id, uint8_t mode, uint16_t speed, uint16_t value, bool wait) {
  SpinRequest request;
  request.id = id;
  request.mode = mode;
  request.speed_dps = speed;
  request.value = value;
  request.wait = wait;
  return request;
}

MoveRequest moveTo(uint8_t id, double angle_deg, bool multi_turn) {
  MoveRequest request;
  request.id = id;
  request.angle_deg = angle_deg;
  request.multi_turn = multi_turn;
  return request;
}

ServoStatus readInto(ServoBusClient& client, uint8_t id, const char* param) {
  ServoParamValue value;
  return client.readParam(id, param, &value);
}

const Rejection kRejections[] = {
    {"ReadUnknownParam", false, ServoError::kUnknownParam, "'volts'",
     [](ServoBusClient& c) { return readInto(c, 3, "volts"); }},
    {"ReadUnknownDataId", false, ServoError::kUnknownParam, "'9'",
     [](ServoBusClient& c) { return readInto(c, 3, "9"); }},
    {"WriteUnknownParam", false, ServoError::kUnknownParam, "'speed'",
     [](ServoBusClient& c) { return c.writeParam(3, "speed", 1); }},
    {"WriteReadOnly", false, ServoError::kReadOnly, "read-only",
     [](ServoBusClient& c) { return c.writeParam(3, "voltage", 7000); }},
    {"WriteOutOfRange", false, ServoError::kOutOfRange, "out of range",
     [](ServoBusClient& c) { return c.writeParam(3, "response_switch", 2); }},
    {"WriteOutOfTypeRange", false, ServoError::kOutOfRange, "out of range",
     [](ServoBusClient& c) { return c.writeParam(3, "angle_limit_low", -40000); }},
    {"WriteServoIdUnarmed", false, ServoError::kDangerous, "dangerous",
     [](ServoBusClient& c) { return c.writeParam(3, "servo_id", 5); }},
    {"WriteBaudrateUnarmed", false, ServoError::kDangerous, "dangerous",
     [](ServoBusClient& c) { return c.writeParam(3, "36", 5); }},
    {"ArmedServoIdOutOfRange", true, ServoError::kOutOfRange, "out of range",
     [](ServoBusClient& c) { return c.writeParam(3, "servo_id", 255); }},
    {"ResetUnarmed", false, ServoError::kDangerous, "dangerous",
     [](ServoBusClient& c) { return c.resetUserData(3); }},
    {"PingBroadcast", false, ServoError::kInvalidArgument, "broadcast",
     [](ServoBusClient& c) { return c.ping(255); }},
    {"ReadBroadcast", false, ServoError::kInvalidArgument, "broadcast",
     [](ServoBusClient& c) { return readInto(c, 255, "voltage"); }},
    {"WriteBroadcast", true, ServoError::kInvalidArgument, "broadcast",
     [](ServoBusClient& c) { return c.writeParam(255, "soft_start_time", 10); }},
    {"ReadAngleBroadcast", false, ServoError::kInvalidArgument, "broadcast",
     [](ServoBusClient& c) {
       double angle = 0.0;
       return c.readAngle(255, &angle);
     }},
    {"ReadAllBroadcast", false, ServoError::kInvalidArgument, "broadcast",
     [](ServoBusClient& c) {
       std::vector<ServoParamValue> values;
       return c.readAll(255, &values);
     }},
    {"ResetBroadcastArmed", true, ServoError::kInvalidArgument, "broadcast",
     [](ServoBusClient& c) { return c.resetUserData(255); }},
    {"RotateBroadcastWait", false, ServoError::kInvalidArgument, "broadcast",
     [](ServoBusClient& c) { return c.rotate(rotateTo(255, 10.0, true)); }},
    {"SpinBroadcastWait", false, ServoError::kInvalidArgument, "broadcast",
     [](ServoBusClient& c) { return c.spin(spinWith(255, 0, 0, 0, true)); }},
    {"DampingBroadcastWait", false, ServoError::kInvalidArgument, "broadcast",
     [](ServoBusClient& c) { return c.damping(255, 100, true); }},
    {"RotateAngleTooLarge", false, ServoError::kInvalidArgument, "out of range",
     [](ServoBusClient& c) { return c.rotate(rotateTo(2, 3276.8, false)); }},
    {"RotateAngleTooSmall", false, ServoError::kInvalidArgument, "out of range",
     [](ServoBusClient& c) { return c.rotate(rotateTo(2, -3276.9, false)); }},
    {"RotateAngleNaN", false, ServoError::kInvalidArgument, "finite",
     [](ServoBusClient& c) { return c.rotate(rotateTo(2, std::nan(""), false)); }},
    {"SpinModeOutOfRange", false, ServoError::kInvalidArgument, "spin mode 4",
     [](ServoBusClient& c) { return c.spin(spinWith(0, 4, 100, 0, false)); }},
    {"SpinWaitTooLong", false, ServoError::kInvalidArgument, "wait = false",
     [](ServoBusClient& c) { return c.spin(spinWith(0, 2, 1, 1000, true)); }},
    {"WriteResponseSwitchUnarmed", false, ServoError::kDangerous, "answered",
     [](ServoBusClient& c) { return c.writeParam(3, "response_switch", 1); }},
    {"WriteReservedUnarmed", false, ServoError::kDangerous, "reserved",
     [](ServoBusClient& c) { return c.writeParam(3, "reserved_45", 1); }},
    {"WriteStallModeZero", false, ServoError::kOutOfRange, "1..2",
     [](ServoBusClient& c) { return c.writeParam(3, "stall_protect_mode", 0); }},
    {"WriteSwitchTwo", false, ServoError::kOutOfRange, "0..1",
     [](ServoBusClient& c) { return c.writeParam(3, "angle_limit_switch", 2); }},
    {"MoveSingleTurnAbove180", false, ServoError::kInvalidArgument, "+-180",
     [](ServoBusClient& c) { return c.move(moveTo(1, 180.1, false)); }},
    {"MoveSingleTurnBelowMinus180", false, ServoError::kInvalidArgument, "+-180",
     [](ServoBusClient& c) { return c.move(moveTo(1, -180.5, false)); }},
    {"MoveMultiTurnTooFar", false, ServoError::kInvalidArgument, "+-368640",
     [](ServoBusClient& c) { return c.move(moveTo(1, 368640.5, true)); }},
    {"MoveAngleNaN", false, ServoError::kInvalidArgument, "finite",
     [](ServoBusClient& c) { return c.move(moveTo(1, std::nan(""), false)); }},
    {"MoveAngleInfinite", false, ServoError::kInvalidArgument, "finite",
     [](ServoBusClient& c) { return c.move(moveTo(1, INFINITY, true)); }},
    {"MoveVelocityNaN", false, ServoError::kInvalidArgument, "velocity_dps is not",
     [](ServoBusClient& c) {
       MoveRequest r = moveTo(1, 10, false);
       r.velocity_dps = std::nan("");
       return c.move(r);
     }},
    {"MoveVelocityAbove750", false, ServoError::kInvalidArgument, "750",
     [](ServoBusClient& c) {
       MoveRequest r = moveTo(1, 10, false);
       r.velocity_dps = 750.5;
       return c.move(r);
     }},
    {"MoveVelocityNegative", false, ServoError::kInvalidArgument, "negative",
     [](ServoBusClient& c) {
       MoveRequest r = moveTo(1, 10, false);
       r.velocity_dps = -10;
       return c.move(r);
     }},
    {"MoveAccelUnder20", false, ServoError::kInvalidArgument, "accel_ms 19",
     [](ServoBusClient& c) {
       MoveRequest r = moveTo(1, 10, false);
       r.interval_ms = 1000;
       r.accel_ms = 19;
       return c.move(r);
     }},
    {"MoveDecelUnder20ByVelocity", false, ServoError::kInvalidArgument, "decel_ms 1",
     [](ServoBusClient& c) {
       MoveRequest r = moveTo(1, 10, true);
       r.velocity_dps = 100;
       r.decel_ms = 1;
       return c.move(r);
     }},
    {"MoveSingleTurnIntervalAboveU16", false, ServoError::kInvalidArgument, "65535",
     [](ServoBusClient& c) {
       MoveRequest r = moveTo(1, 10, false);
       r.interval_ms = 65536;
       return c.move(r);
     }},
    {"MoveRampsLongerThanInterval", false, ServoError::kInvalidArgument, "accel + decel",
     [](ServoBusClient& c) {
       MoveRequest r = moveTo(1, 10, false);
       r.interval_ms = 100;
       r.accel_ms = 80;
       r.decel_ms = 80;
       return c.move(r);
     }},
    {"ReadMultiTurnBroadcast", false, ServoError::kInvalidArgument, "broadcast",
     [](ServoBusClient& c) {
       MultiTurnReading reading;
       return c.readMultiTurnAngle(255, &reading);
     }},
    {"ScanBroadcast", false, ServoError::kInvalidArgument, "broadcast",
     [](ServoBusClient& c) {
       std::vector<uint8_t> ids;
       return c.scan(250, 255, &ids);
     }},
    {"ScanReversedRange", false, ServoError::kInvalidArgument, "above last_id",
     [](ServoBusClient& c) {
       std::vector<uint8_t> ids;
       return c.scan(9, 3, &ids);
     }},
};

class ServoBusClientRejectionTest : public ::testing::TestWithParam<Rejection> {};

TEST_P(ServoBusClientRejectionTest, RejectsWithoutWritingAByte) {
  const Rejection& rejection = GetParam();
  FakeBus bus;
  ServoBusClient client(testOptions(rejection.armed),
                        [&bus](const Bytes& frame) { return bus.write(frame); });
  bus.client = &client;
  const ServoStatus status = rejection.call(client);
  EXPECT_EQ(status.error, rejection.error) << status.message;
  EXPECT_NE(status.message.find(rejection.message_part), std::string::npos) << status.message;
  EXPECT_TRUE(bus.written.empty());
}

INSTANTIATE_TEST_SUITE_P(ServoBusClient, ServoBusClientRejectionTest,
                         ::testing::ValuesIn(kRejections),
                         [](const ::testing::TestParamInfo<Rejection>& info) {
                           return std::string(info.param.name);
                         });

}  // namespace
}  // namespace serial_robot_driver::device
