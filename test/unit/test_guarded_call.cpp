// core::runGuarded and core::serveGuarded (core/guarded_call.h): an exception from a callback is
// counted under its source, logged once and swallowed; a service answers it as a failure, every
// other field at its default.
#include <gtest/gtest.h>

#include <stdexcept>
#include <string>
#include <vector>

#include "serial_robot_driver/core/guarded_call.h"

namespace serial_robot_driver::core {
namespace {

struct TriggerLike {
  bool success = true;
  std::string message;
};
struct PingLike {
  bool online = true;
  std::string message;
  std::string servo_type = "unread";
};
struct NoOutcomeFields {
  int value = 7;
};

class GuardedCall : public ::testing::Test {
 protected:
  CallbackErrorLog log() {
    return [this](const std::string& line) { lines_.push_back(line); };
  }
  InputRefusals refusals_;
  std::vector<std::string> lines_;
};

TEST_F(GuardedCall, AnExceptionIsCountedLoggedOnceAndSwallowed) {
  std::string error;
  EXPECT_TRUE(runGuarded(
      refusals_, "cmd_vel", [] {}, &error, log()));
  EXPECT_TRUE(lines_.empty());
  EXPECT_FALSE(runGuarded(
      refusals_, "joint_trajectory", [] { throw std::runtime_error("Duration is out of range"); },
      &error, log()));
  EXPECT_EQ(error, "Duration is out of range");
  ASSERT_EQ(lines_.size(), 1u);
  EXPECT_EQ(lines_[0],
            "joint_trajectory: internal error, this input was dropped (or answered as a failure): "
            "Duration is out of range");
  EXPECT_FALSE(runGuarded(refusals_, "joint_trajectory", [] { throw 42; }, nullptr, {}));
  EXPECT_EQ(refusals_.stats().errors.at("joint_trajectory"), 2u);
  EXPECT_EQ(refusals_.stats().errors.count("cmd_vel"), 0u);
  EXPECT_TRUE(refusals_.stats().refused.empty()) << "an error is not a refused input";
}

TEST_F(GuardedCall, AnExceptionWithAnEmptyOrHugeTextIsStillAnswered) {
  std::string error = "stale";
  EXPECT_FALSE(runGuarded(
      refusals_, "", [] { throw std::runtime_error(""); }, &error, log()));
  EXPECT_EQ(error, "");
  const std::string huge(100000, 'e');
  TriggerLike res;
  EXPECT_TRUE(serveGuarded(
      refusals_, "imu/calibrate", res, [&]() -> bool { throw std::runtime_error(huge); }, log()));
  EXPECT_EQ(res.message, "internal error: " + huge);
  EXPECT_EQ(refusals_.stats().errors.at(""), 1u);
}

TEST_F(GuardedCall, AServiceAnswersAnExceptionAsAFailureWithEveryOtherFieldAtItsDefault) {
  PingLike ping;
  EXPECT_TRUE(serveGuarded(
      refusals_, "servo/ping", ping,
      [&]() -> bool {
        ping.servo_type = "half";
        throw std::out_of_range("index");
      },
      log()))
      << "answered, so the caller reads the message";
  EXPECT_FALSE(ping.online);
  EXPECT_EQ(ping.message, "internal error: index");
  EXPECT_EQ(ping.servo_type, "unread") << "the response's defaults, not half an answer";

  NoOutcomeFields bare;
  bare.value = 1;
  EXPECT_TRUE(serveGuarded(
      refusals_, "x", bare, []() -> bool { throw 1; }, log()));
  EXPECT_EQ(bare.value, 7);
  EXPECT_EQ(refusals_.stats().errors.size(), 2u);
}

TEST_F(GuardedCall, AServiceThatReturnsIsLeftAsItAnswered) {
  TriggerLike res;
  EXPECT_FALSE(serveGuarded(
      refusals_, "base/reset", res,
      [&] {
        res.message = "declined";
        return false;
      },
      log()));
  EXPECT_TRUE(res.success);
  EXPECT_EQ(res.message, "declined");
  EXPECT_TRUE(lines_.empty());
}

}  // namespace
}  // namespace serial_robot_driver::core
