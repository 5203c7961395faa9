// driver_node: loads and validates the parameters, builds the node, spins until SIGINT/SIGTERM,
// then writes a last zero-speed frame before the ports close.
#include <atomic>
#include <csignal>

#include <ros/ros.h>

#include "serial_robot_driver/ros/driver_node.h"

namespace {
std::atomic<bool> g_stop_requested{false};
void requestStop(int) { g_stop_requested = true; }
}  // namespace

int main(int argc, char** argv) {
  // Our own SIGINT handler: roscpp's would tear the node down before the zero-speed frame is out.
  ros::init(argc, argv, "driver_node", ros::init_options::NoSigintHandler);
  std::signal(SIGINT, requestStop);
  std::signal(SIGTERM, requestStop);

  ros::NodeHandle nh;
  ros::NodeHandle private_nh("~");
  using serial_robot_driver::ros_layer::DriverParams;
  DriverParams params;
  try {
    std::vector<std::string> unknown;
    params = serial_robot_driver::ros_layer::loadParams(private_nh, &unknown);
    for (const auto& key : unknown) {
      ROS_WARN("unknown parameter ~%s is ignored (a typo?)", key.c_str());
    }
    params.validate();
  } catch (const serial_robot_driver::ros_layer::ParameterError& e) {
    ROS_FATAL("%s", e.what());
    ros::shutdown();
    return 2;
  }

  serial_robot_driver::ros_layer::DriverNode node(nh, private_nh, params);
  node.start();
  // Global queue: cmd_vel, joint_commands, base services, diagnostics timer. Two threads so a
  // subscriber callback never waits behind the diagnostics update.
  ros::AsyncSpinner spinner(2);
  spinner.start();
  while (!g_stop_requested && ros::ok()) {
    ros::WallDuration(0.05).sleep();
  }
  ROS_INFO("shutting down: stopping the wheels");
  node.shutdown();
  spinner.stop();
  ros::shutdown();
  return 0;
}
