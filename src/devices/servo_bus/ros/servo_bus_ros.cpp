#include "serial_robot_driver/devices/servo_bus/ros/servo_bus_ros.h"

#include "serial_robot_driver/ros/conversions.h"
#include "serial_robot_driver/ros/guarded_callbacks.h"
#include "serial_robot_driver/ros/publish_wanted.h"

namespace serial_robot_driver::devices::servo_bus::ros {

ServoBusRos::ServoBusRos(::ros::NodeHandle& nh, ServoBusDevice& device)
    : device_(device), services_(nh, device.bus(), device.claims(), device.inputRefusals()) {
  states_pub_ = ros_layer::advertiseCounted<sensor_msgs::JointState>(nh, "servo_states", 10);
  ServoBusOutputs outputs;
  outputs.servo_state = [this](const JointPosition& state, core::Clock::time_point arrival) {
    if (!ros_layer::wanted(states_pub_)) return;  // nobody asked for it
    states_pub_.publish(busJointState(state, ros_layer::toRosTime(arrival)));
  };
  device.addOutputs(std::move(outputs));
  const ros_layer::SubscriberCallback<sensor_msgs::JointState> on_commands =
      [this](const sensor_msgs::JointState::ConstPtr& msg) {
        device_.commandServos({msg->name, msg->position, msg->velocity});
      };
  commands_sub_ = nh.subscribe<sensor_msgs::JointState>(
      "servo_commands", 10,
      ros_layer::guardedSubscriber(device.inputRefusals(), "servo_commands", on_commands),
      ::ros::VoidConstPtr(), ::ros::TransportHints().tcpNoDelay());
}

ServoBusRos::~ServoBusRos() { shutdown(); }

void ServoBusRos::start() {
  if (started_ || shut_down_) return;
  started_ = true;
  services_.start();
}

void ServoBusRos::shutdown() {
  if (shut_down_) return;
  shut_down_ = true;
  commands_sub_.shutdown();
  device_.shutdown();  // fails a call waiting on the bus, so the spinners can stop quickly
  services_.shutdown();
}

}  // namespace serial_robot_driver::devices::servo_bus::ros
