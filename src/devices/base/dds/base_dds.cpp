// The base on the ROS 2 graph: cmd_vel and cmd_vel_stamped in, odom, tf, wheel_states and battery
// out, with the names, frames, units and stamps of its ROS 1 topics (ros/base_ros.cpp). Only
// translation: the checks, the deadman and the counting are BaseDevice's.
#include <limits>
#include <memory>

#include "serial_robot_driver/core/wall_stamps.h"
#include "serial_robot_driver/dds/publisher.h"
#include "serial_robot_driver/dds/ros_conventions.h"
#include "serial_robot_driver/dds/subscription.h"
#include "serial_robot_driver/dds_front/dds_conversions.h"
#include "serial_robot_driver/dds_front/dds_device_module.h"
#include "serial_robot_driver/dds_front/guarded_subscription.h"
#include "serial_robot_driver/devices/base/base_device.h"

namespace serial_robot_driver::devices::base::dds {

namespace ddsl = serial_robot_driver::dds;
using dds_front::setHeader;

namespace {

/// sensor_msgs/BatteryState: the charge; what the base does not report is NaN or UNKNOWN (0).
sensor_msgs_msg_dds__BatteryState_ toBatteryState(const BatteryReading& battery) {
  sensor_msgs_msg_dds__BatteryState_ msg{};
  const float unknown = std::numeric_limits<float>::quiet_NaN();
  msg.voltage = msg.temperature = msg.current = unknown;
  msg.charge = msg.capacity = msg.design_capacity = unknown;
  msg.percentage = static_cast<float>(battery.fraction);
  msg.present = true;
  return msg;
}

/// The pose of a sample: position and heading.
geometry_msgs_msg_dds__Pose_ toPose(const OdometrySample& sample) {
  const YawRotation rotation = yawRotation(sample.pose.yaw);
  geometry_msgs_msg_dds__Pose_ pose{};
  pose.position.x = sample.pose.x;
  pose.position.y = sample.pose.y;
  pose.orientation.z = rotation.z;
  pose.orientation.w = rotation.w;
  return pose;
}

}  // namespace

class BaseDds : public dds_front::DeviceFrontEnd {
 public:
  BaseDds(ddsl::Participant& participant, const params::DriverParams& params, BaseDevice& device)
      : device_(device),
        stamps_(params.replay_timeline),
        odom_(participant, "odom"),
        wheel_states_(participant, "wheel_states"),
        battery_(participant, "battery"),
        tf_(device.params().publish_tf ? std::make_unique<Tf>(participant, "/tf") : nullptr),
        cmd_vel_(dds_front::subscribeGuarded<geometry_msgs_msg_dds__Twist_>(
            participant, device.inputRefusals(), "cmd_vel",
            [this](const geometry_msgs_msg_dds__Twist_& msg) {
              device_.commandTwist({msg.linear.x, msg.angular.z});
            })),
        cmd_vel_stamped_(dds_front::subscribeGuarded<geometry_msgs_msg_dds__TwistStamped_>(
            participant, device.inputRefusals(), "cmd_vel_stamped",
            [this](const geometry_msgs_msg_dds__TwistStamped_& msg) {
              device_.commandTwist({msg.twist.linear.x, msg.twist.angular.z});
            })) {
    BaseOutputs outputs;
    outputs.odometry = [this](const OdometrySample& sample) { publishOdometry(sample); };
    outputs.battery = [this](const BatteryReading& reading, core::Clock::time_point arrival) {
      sensor_msgs_msg_dds__BatteryState_ msg = toBatteryState(reading);
      setHeader(msg.header, stamps_(arrival), no_frame_);
      ddsl::lend(msg.location, no_frame_);
      ddsl::lend(msg.serial_number, no_frame_);
      battery_.publish(msg);
    };
    device.addOutputs(std::move(outputs));
  }

  void shutdown() override {
    cmd_vel_.reset();
    cmd_vel_stamped_.reset();
  }

 private:
  using Twists = ddsl::Subscription<geometry_msgs_msg_dds__Twist_>;
  using StampedTwists = ddsl::Subscription<geometry_msgs_msg_dds__TwistStamped_>;
  using Tf = ddsl::Publisher<tf2_msgs_msg_dds__TFMessage_>;

  void publishOdometry(const OdometrySample& sample) {
    const std::chrono::nanoseconds stamp = stamps_(sample.time);
    const BaseParams& started = device_.params();
    if (odom_.hasSubscribers()) {
      nav_msgs_msg_dds__Odometry_ odom{};
      setHeader(odom.header, stamp, started.odom_frame);
      ddsl::lend(odom.child_frame_id, started.base_frame);
      odom.pose.pose = toPose(sample);
      odom.twist.twist.linear.x = sample.linear;
      odom.twist.twist.angular.z = sample.angular;
      const OdometryCovariances covariances =
          odometryCovariances(sample.position_variance, sample.yaw_variance);
      std::copy(covariances.pose.begin(), covariances.pose.end(), odom.pose.covariance);
      std::copy(covariances.twist.begin(), covariances.twist.end(), odom.twist.covariance);
      odom_.publish(odom);
    }
    if (tf_ && device_.tuned()->publish_tf) publishTf(sample, stamp);
    if (wheel_states_.hasSubscribers()) {
      const dds_front::JointStateSample wheels(
          stamp, started.base_frame, {started.left_wheel_joint, started.right_wheel_joint},
          {sample.wheel_angles.x(), sample.wheel_angles.y()},
          {sample.wheel_rates.x(), sample.wheel_rates.y()});
      wheel_states_.publish(wheels.sample());
    }
  }

  void publishTf(const OdometrySample& sample, std::chrono::nanoseconds stamp) {
    const BaseParams& started = device_.params();
    geometry_msgs_msg_dds__TransformStamped_ transform{};
    setHeader(transform.header, stamp, started.odom_frame);
    ddsl::lend(transform.child_frame_id, started.base_frame);
    const geometry_msgs_msg_dds__Pose_ pose = toPose(sample);
    transform.transform.translation.x = pose.position.x;
    transform.transform.translation.y = pose.position.y;
    transform.transform.rotation = pose.orientation;
    tf2_msgs_msg_dds__TFMessage_ msg{};
    msg.transforms._buffer = &transform;
    msg.transforms._length = msg.transforms._maximum = 1;
    tf_->publish(msg);
  }

  BaseDevice& device_;
  const core::WallStamps stamps_;
  const std::string no_frame_;
  ddsl::Publisher<nav_msgs_msg_dds__Odometry_> odom_;
  ddsl::Publisher<sensor_msgs_msg_dds__JointState_> wheel_states_;
  ddsl::Publisher<sensor_msgs_msg_dds__BatteryState_> battery_;
  std::unique_ptr<Tf> tf_;  // only with ~base/publish_tf at start, as on the ROS side
  std::unique_ptr<Twists> cmd_vel_;
  std::unique_ptr<StampedTwists> cmd_vel_stamped_;
};

namespace {
std::unique_ptr<dds_front::DeviceFrontEnd> attach(ddsl::Participant& participant,
                                                  const params::DriverParams& params,
                                                  core::Device& device) {
  return std::make_unique<BaseDds>(participant, params, static_cast<BaseDevice&>(device));
}
}  // namespace

}  // namespace serial_robot_driver::devices::base::dds

namespace serial_robot_driver::devices::base {
extern const dds_front::DdsDeviceModule kDdsModule{.name = "base", .attach = dds::attach};
}  // namespace serial_robot_driver::devices::base
