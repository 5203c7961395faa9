// devices::servo_bus::ServoServices, the servo/* services without a front end: each call's reply
// (its own fields only when the call succeeded), its message, the refusals counted under the
// service's name and the log lines (every outcome at debug, a changed setting at info), with
// extreme requests (NaN and infinite angles, huge names, the broadcast id, the largest values).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "serial_robot_driver/core/e_stop.h"
#include "serial_robot_driver/core/log.h"
#include "serial_robot_driver/devices/servo_bus/servo_services.h"
#include "support/servo_bus_rig.h"

namespace serial_robot_driver::devices::servo_bus {
namespace {

using Level = core::LogLevel;

class ServoServicesTest : public ServoBusTest {
 protected:
  void SetUp() override {
    makeBus({});
    claims_ = std::make_unique<ServoMotionClaims>(*bus_, joints_);
    core::setLogSink([this](Level level, const std::string& line) {
      if (line.rfind("servo/", 0) == 0) logged_.emplace_back(level, line);  // the services' own
    });
  }
  void TearDown() override { core::setLogSink({}); }

  ServoServices services() { return ServoServices(*bus_, *claims_, refusals_); }
  uint64_t refused(const std::string& source) const {
    const core::InputRefusalStats stats = refusals_.stats();
    const auto found = stats.refused.find(source);
    return found == stats.refused.end() ? 0 : found->second;
  }
  std::size_t linesAt(Level level) const {
    std::size_t count = 0;
    for (const auto& entry : logged_) count += entry.first == level ? 1 : 0;
    return count;
  }

  const std::vector<trajectory::BusJoint> joints_;
  std::unique_ptr<ServoMotionClaims> claims_;
  core::InputRefusals refusals_;
  std::vector<std::pair<Level, std::string>> logged_;
};

TEST_F(ServoServicesTest, ARead_GivesTheValueInItsUnitAndLogsTheOutcomeAtDebug) {
  answers_[golden::servo::kReadVoltage3] = golden::servo::kReadVoltage3Reply;
  const ServoReadReply reply = services().read(3, "voltage");
  ASSERT_TRUE(reply.ok) << reply.message;
  EXPECT_EQ(reply.value, 7400);
  EXPECT_EQ(reply.unit, "mV");
  EXPECT_FALSE(reply.message.empty());
  ASSERT_EQ(logged_.size(), 1u);
  EXPECT_EQ(logged_[0].first, Level::kDebug);
  EXPECT_EQ(logged_[0].second, "servo/read: " + reply.message);
  EXPECT_EQ(refused("servo/read"), 0u);
}

TEST_F(ServoServicesTest, AnUnknownHugeParameterNameIsRefusedCountedAndNotEchoedWhole) {
  const ServoReadReply reply = services().read(3, std::string(100000, 'x'));
  EXPECT_FALSE(reply.ok);
  EXPECT_EQ(reply.value, 0);
  EXPECT_EQ(reply.unit, "");
  EXPECT_LT(reply.message.size(), 1000u) << "the name is cut";
  EXPECT_EQ(refused("servo/read"), 1u);
  ASSERT_EQ(logged_.size(), 1u);
  EXPECT_EQ(logged_[0].second.rfind("servo/read failed (unknown parameter): ", 0), 0u)
      << logged_[0].second;
  EXPECT_TRUE(written().empty());
}

TEST_F(ServoServicesTest, AnEmptyParameterNameIsRefused) {
  EXPECT_FALSE(services().read(3, "").ok);
  EXPECT_EQ(refused("servo/read"), 1u);
}

TEST_F(ServoServicesTest, ADangerousWriteNamesTheParameterThatArmsItAndIsNotAnnounced) {
  const ServoReply reply = services().write(3, "servo_id", 5);
  EXPECT_FALSE(reply.ok);
  EXPECT_NE(reply.message.find("(set ~servo_bus/allow_dangerous_writes to true to arm it)"),
            std::string::npos)
      << reply.message;
  EXPECT_EQ(refused("servo/write"), 1u);
  EXPECT_EQ(linesAt(Level::kInfo), 0u);
  EXPECT_TRUE(written().empty());
}

TEST_F(ServoServicesTest, TheLargestAndSmallestValuesAreRefusedAsOutOfRange) {
  for (int64_t value : {std::numeric_limits<int64_t>::max(), std::numeric_limits<int64_t>::min()}) {
    const ServoReply reply = services().write(3, "soft_start_time", value);
    EXPECT_FALSE(reply.ok) << value;
  }
  EXPECT_EQ(refused("servo/write"), 2u);
  EXPECT_TRUE(written().empty());
}

TEST_F(ServoServicesTest, AWriteThatChangedASettingIsAnnouncedAtInfo) {
  answers_[golden::servo::kWriteSoftStart3] = golden::servo::kWriteSoftStart3Ok;
  answers_[golden::servo::kReadSoftStart3] = golden::servo::kReadSoftStart3Reply300;
  const ServoReply reply = services().write(3, "soft_start_time", 300);
  ASSERT_TRUE(reply.ok) << reply.message;
  ASSERT_EQ(linesAt(Level::kInfo), 1u);
  EXPECT_EQ(logged_.back().second, "servo/write: " + reply.message);
}

TEST_F(ServoServicesTest, ASilentServoFailsWithoutCountingARefusal) {
  const ServoReply reply = services().ping(7);
  EXPECT_FALSE(reply.ok);
  EXPECT_EQ(refused("servo/ping"), 0u) << "the servo's silence is not the caller's mistake";
  ASSERT_EQ(logged_.size(), 1u);
  EXPECT_EQ(logged_[0].second.rfind("servo/ping failed (", 0), 0u) << logged_[0].second;
}

TEST_F(ServoServicesTest, TheBroadcastIdIsRefusedForAnswersItCannotGive) {
  EXPECT_FALSE(services().ping(kBroadcastId).ok);
  EXPECT_FALSE(services().readAngle(kBroadcastId, true).ok);
  EXPECT_FALSE(services().info(kBroadcastId).ok);
  EXPECT_EQ(refused("servo/ping"), 1u);
  EXPECT_EQ(refused("servo/read_angle"), 1u);
  EXPECT_EQ(refused("servo/info"), 1u);
  EXPECT_TRUE(written().empty());
}

TEST_F(ServoServicesTest, AnAngleIsGivenOnlyWhenItWasRead) {
  const ServoAngleReply read = services().readAngle(0, false);
  ASSERT_TRUE(read.ok) << read.message;
  EXPECT_DOUBLE_EQ(read.angle_deg, 90.2);
  EXPECT_EQ(read.turns, 0);
  const ServoAngleReply silent = services().readAngle(5, false);
  EXPECT_FALSE(silent.ok);
  EXPECT_EQ(silent.angle_deg, 0.0);
}

TEST_F(ServoServicesTest, AScanOfNoIdsOrThroughTheBroadcastIdIsRefused) {
  const ServoScanReply backwards = services().scan(10, 0);
  EXPECT_FALSE(backwards.ok);
  EXPECT_TRUE(backwards.ids.empty());
  EXPECT_FALSE(services().scan(0, kBroadcastId).ok);
  EXPECT_EQ(refused("servo/scan"), 2u);
  EXPECT_TRUE(written().empty());
}

TEST_F(ServoServicesTest, NonFiniteAnglesMoveNothingAndAreCountedAsRefused) {
  for (double angle : {std::nan(""), std::numeric_limits<double>::infinity(), -1e308}) {
    MoveRequest move;
    move.id = 1;
    move.angle_deg = angle;
    EXPECT_FALSE(services().move(move).ok) << angle;
    RotateRequest rotate;
    rotate.id = 1;
    rotate.angle_deg = angle;
    EXPECT_FALSE(services().rotate(rotate).ok) << angle;
  }
  EXPECT_EQ(refused("servo/move"), 3u);
  EXPECT_EQ(refused("servo/rotate"), 3u);
  EXPECT_TRUE(written().empty());
}

TEST_F(ServoServicesTest, UnderTheEStopMotionIsRefusedUnderEachServicesName) {
  core::EStop e_stop;
  claims_->attachEStop(e_stop);
  e_stop.set(true);
  ServoServices calls = services();
  const ServoReply moved = calls.move(rotate2To90In500());
  EXPECT_FALSE(moved.ok);
  EXPECT_NE(moved.message.find("e_stop is engaged"), std::string::npos) << moved.message;
  EXPECT_FALSE(calls.hold({}).ok);
  EXPECT_FALSE(calls.spin(continuousSpin0()).ok);
  const core::EStopStats stats = e_stop.stats();
  for (const char* source : {"servo/move", "servo/hold", "servo/spin"}) {
    EXPECT_EQ(stats.refused.count(source), 1u) << source;
  }
  EXPECT_TRUE(written().empty());
}

TEST_F(ServoServicesTest, ARelaxOfTheBroadcastIdTwiceStillAnswers) {
  EXPECT_FALSE(services().relax({kBroadcastId, kBroadcastId}).message.empty());
}

}  // namespace
}  // namespace serial_robot_driver::devices::servo_bus
