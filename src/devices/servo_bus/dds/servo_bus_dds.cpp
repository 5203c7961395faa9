// The bus servos on the ROS 2 graph: servo_states out, one sample per polled servo's answer,
// stamped when the answer arrived, as on ROS 1. The servo/* services and servo_commands stay on
// ROS 1 for now (docs/ros2.md).
#include <memory>

#include "serial_robot_driver/core/wall_stamps.h"
#include "serial_robot_driver/dds/publisher.h"
#include "serial_robot_driver/dds_front/dds_conversions.h"
#include "serial_robot_driver/dds_front/dds_device_module.h"
#include "serial_robot_driver/devices/servo_bus/servo_bus_device.h"

namespace serial_robot_driver::devices::servo_bus::dds {

namespace ddsl = serial_robot_driver::dds;

class ServoBusDds : public dds_front::DeviceFrontEnd {
 public:
  ServoBusDds(ddsl::Participant& participant, const params::DriverParams& params,
              ServoBusDevice& device)
      : stamps_(params.replay_timeline), states_(participant, "servo_states") {
    ServoBusOutputs outputs;
    outputs.servo_state = [this](const JointPosition& state, core::Clock::time_point arrival) {
      if (!states_.hasSubscribers()) return;
      const dds_front::JointStateSample sample(stamps_(arrival), "", {state.name},
                                               {state.position});
      states_.publish(sample.sample());
    };
    device.addOutputs(std::move(outputs));
  }

  void shutdown() override {}

 private:
  const core::WallStamps stamps_;
  ddsl::Publisher<sensor_msgs_msg_dds__JointState_> states_;
};

namespace {
std::unique_ptr<dds_front::DeviceFrontEnd> attach(ddsl::Participant& participant,
                                                  const params::DriverParams& params,
                                                  core::Device& device) {
  return std::make_unique<ServoBusDds>(participant, params, static_cast<ServoBusDevice&>(device));
}
}  // namespace

}  // namespace serial_robot_driver::devices::servo_bus::dds

namespace serial_robot_driver::devices::servo_bus {
extern const dds_front::DdsDeviceModule kDdsModule{.name = "servo_bus", .attach = dds::attach};
}  // namespace serial_robot_driver::devices::servo_bus
