// The body in the robot description: the IMU's link where --imu-xyz / --imu-rpy place it, and
// one servo joint per body joint, limited to what its servo reaches.
#include <cmath>

#include "serial_robot_driver/description/robot_description.h"
#include "serial_robot_driver/devices/body/body_params.h"
#include "serial_robot_driver/devices/body/body_readings.h"
#include "serial_robot_driver/params/driver_params.h"

namespace serial_robot_driver::devices::body {

namespace {

using description::numbers;

void drawImu(const description::DriverParams& params, const description::Chassis& chassis,
             const description::Mounts& mounts, description::UrdfWriter& urdf) {
  const std::string imu_link = description::linkName(params.section(kImuSection).frame_id);
  const description::Mount mount = description::mountOf(mounts, "imu");
  urdf.link(imu_link, "imu/frame_id",
            description::visual(description::box(0.03, 0.03, 0.01), "imu"));
  urdf.joint(imu_link + "_joint", "imu/frame_id", "fixed", chassis.root_link, imu_link,
             numbers({mount.xyz[0], mount.xyz[1], mount.xyz[2]}),
             numbers({mount.rpy[0], mount.rpy[1], mount.rpy[2]}), "");
}

std::vector<description::ServoJoint> servoJoints(const description::DriverParams& params) {
  std::vector<description::ServoJoint> servos;
  if (!params.section(kBodySection).enabled) return servos;
  for (const BodyJoint& joint : makeBodyJoints(params.section(kBodySection))) {
    const auto [lower, upper] = joint.calibration.reachableRadians();
    // The board's speed unit is not known (body/velocity_scale); one turn per second.
    servos.push_back({joint.name, "body/joint_names", lower, upper, 2.0 * M_PI});
  }
  return servos;
}

}  // namespace

extern const description::DescriptionPart kDescription{
    .mounts = {{"imu", "imu_link"}}, .fixed = drawImu, .servo_joints = servoJoints};

}  // namespace serial_robot_driver::devices::body
