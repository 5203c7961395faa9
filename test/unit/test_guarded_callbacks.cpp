// The last line between an input and roscpp (ros/guarded_callbacks.h): an exception from a
// callback is counted and swallowed, a service answers it as a failure. No roscore needed.
#include <gtest/gtest.h>
#include <ros/time.h>
#include <std_msgs/Bool.h>
#include <std_srvs/Trigger.h>

#include <stdexcept>
#include <string>

#include "serial_robot_driver/ServoPing.h"
#include "serial_robot_driver/ros/guarded_callbacks.h"

namespace serial_robot_driver::ros_layer {
namespace {

class GuardedCallbacks : public ::testing::Test {
 protected:
  void SetUp() override { ros::Time::init(); }  // the throttled log reads the clock
  core::InputRefusals refusals;
};

TEST_F(GuardedCallbacks, AnExceptionIsCountedAndSwallowed) {
  std::string error;
  EXPECT_TRUE(runGuarded(
      refusals, "cmd_vel", [] {}, &error));
  EXPECT_FALSE(runGuarded(
      refusals, "joint_trajectory", [] { throw std::runtime_error("Duration is out of range"); },
      &error));
  EXPECT_EQ(error, "Duration is out of range");
  EXPECT_FALSE(runGuarded(refusals, "joint_trajectory", [] { throw 42; }));
  EXPECT_EQ(refusals.stats().errors.at("joint_trajectory"), 2u);
  EXPECT_EQ(refusals.stats().errors.count("cmd_vel"), 0u);

  const auto callback = guardedSubscriber<std_msgs::Bool>(
      refusals, "e_stop", [](const std_msgs::Bool::ConstPtr&) { throw std::logic_error("bug"); });
  EXPECT_NO_THROW(callback(boost::make_shared<const std_msgs::Bool>()));
  EXPECT_EQ(refusals.stats().errors.at("e_stop"), 1u);
}

TEST_F(GuardedCallbacks, AServiceAnswersAnExceptionAsAFailure) {
  const auto trigger = guardedService<std_srvs::Trigger::Request, std_srvs::Trigger::Response>(
      refusals, "imu/calibrate", [](std_srvs::Trigger::Request&, std_srvs::Trigger::Response& res) {
        res.success = true;
        throw std::runtime_error("boom");
        return true;
      });
  std_srvs::Trigger::Request req;
  std_srvs::Trigger::Response res;
  EXPECT_TRUE(trigger(req, res)) << "answered, so the caller reads the message";
  EXPECT_FALSE(res.success);
  EXPECT_EQ(res.message, "internal error: boom");

  using Ping = serial_robot_driver::ServoPing;
  const auto ping = guardedService<Ping::Request, Ping::Response>(
      refusals, "servo/ping", [](Ping::Request&, Ping::Response& res) {
        res.online = true;
        throw std::out_of_range("index");
        return true;
      });
  Ping::Request ping_req;
  Ping::Response ping_res;
  EXPECT_TRUE(ping(ping_req, ping_res));
  EXPECT_FALSE(ping_res.online);
  EXPECT_EQ(ping_res.message, "internal error: index");
  EXPECT_EQ(refusals.stats().errors.size(), 2u);

  // A call that returns normally is left as it answered.
  const auto fine = guardedService<std_srvs::Trigger::Request, std_srvs::Trigger::Response>(
      refusals, "base/reset", [](std_srvs::Trigger::Request&, std_srvs::Trigger::Response& r) {
        r.success = true;
        return true;
      });
  EXPECT_TRUE(fine(req, res));
  EXPECT_TRUE(res.success);
}

}  // namespace
}  // namespace serial_robot_driver::ros_layer
