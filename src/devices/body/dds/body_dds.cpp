// The servo controller board on the ROS 2 graph: joint_states and imu/data out (one sample each per
// telemetry frame, stamped with the frame's arrival as on ROS 1), joint_commands in. Only
// translation: the readings, the covariances and the command checks are BodyDevice's.
#include <memory>

#include "serial_robot_driver/core/wall_stamps.h"
#include "serial_robot_driver/dds/c_types.h"
#include "serial_robot_driver/dds/publisher.h"
#include "serial_robot_driver/dds/subscription.h"
#include "serial_robot_driver/dds_front/dds_conversions.h"
#include "serial_robot_driver/dds_front/dds_device_module.h"
#include "serial_robot_driver/dds_front/guarded_subscription.h"
#include "serial_robot_driver/devices/body/body_device.h"

namespace serial_robot_driver::devices::body::dds {

namespace ddsl = serial_robot_driver::dds;

namespace {

geometry_msgs_msg_dds__Vector3_ toVector3(const Eigen::Vector3d& v) {
  return {v.x(), v.y(), v.z()};
}

/// REP-145 sensor_msgs/Imu of a frame (imuReading(), the gyro bias subtracted), header left out.
sensor_msgs_msg_dds__Imu_ toImu(const BodyFrame& frame) {
  const ImuReading reading =
      imuReading(frame.telemetry, frame.imu, frame.imu_axes, frame.gyro_bias);
  sensor_msgs_msg_dds__Imu_ msg{};
  msg.linear_acceleration = toVector3(reading.linear_acceleration);
  msg.angular_velocity = toVector3(reading.angular_velocity);
  msg.orientation = {reading.orientation.x, reading.orientation.y, reading.orientation.z,
                     reading.orientation.w};
  const ImuCovariances covariances = imuCovariances(frame.imu);
  std::copy(covariances.orientation.begin(), covariances.orientation.end(),
            msg.orientation_covariance);
  std::copy(covariances.angular_velocity.begin(), covariances.angular_velocity.end(),
            msg.angular_velocity_covariance);
  std::copy(covariances.linear_acceleration.begin(), covariances.linear_acceleration.end(),
            msg.linear_acceleration_covariance);
  return msg;
}

}  // namespace

class BodyDds : public dds_front::DeviceFrontEnd {
 public:
  BodyDds(ddsl::Participant& participant, const params::DriverParams& params, BodyDevice& device)
      : stamps_(params.replay_timeline),
        joint_states_(participant, "joint_states"),
        imu_(participant, "imu/data"),
        joint_commands_(dds_front::subscribeGuarded<sensor_msgs_msg_dds__JointState_>(
            participant, device.inputRefusals(), "joint_commands",
            [&device](const sensor_msgs_msg_dds__JointState_& msg) {
              device.commandJoints({ddsl::toStrings(msg.name), ddsl::toVector(msg.position)});
            })) {
    device.addOutputs({[this](const BodyFrame& frame) { publishFrame(frame); }});
  }

  void shutdown() override { joint_commands_.reset(); }

 private:
  using Commands = ddsl::Subscription<sensor_msgs_msg_dds__JointState_>;

  void publishFrame(const BodyFrame& frame) {
    const std::chrono::nanoseconds stamp = stamps_(frame.arrival);
    if (joint_states_.hasSubscribers()) {
      const dds_front::JointStateSample joints(stamp, "", frame.joints.names,
                                               frame.joints.positions, frame.joints.velocities);
      joint_states_.publish(joints.sample());
    }
    if (imu_.hasSubscribers()) {
      sensor_msgs_msg_dds__Imu_ imu = toImu(frame);
      dds_front::setHeader(imu.header, stamp, frame.imu.frame_id);
      imu_.publish(imu);
    }
  }

  const core::WallStamps stamps_;
  ddsl::Publisher<sensor_msgs_msg_dds__JointState_> joint_states_;
  ddsl::Publisher<sensor_msgs_msg_dds__Imu_> imu_;
  std::unique_ptr<Commands> joint_commands_;
};

namespace {
std::unique_ptr<dds_front::DeviceFrontEnd> attach(ddsl::Participant& participant,
                                                  const params::DriverParams& params,
                                                  core::Device& device) {
  return std::make_unique<BodyDds>(participant, params, static_cast<BodyDevice&>(device));
}
}  // namespace

}  // namespace serial_robot_driver::devices::body::dds

namespace serial_robot_driver::devices::body {
extern const dds_front::DdsDeviceModule kDdsModule{.name = "body", .attach = dds::attach};
}  // namespace serial_robot_driver::devices::body
