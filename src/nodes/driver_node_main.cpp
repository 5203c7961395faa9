// driver_node: loads and validates the parameters, builds the node, spins until SIGINT/SIGTERM,
// then writes a last zero-speed frame before the ports close (ros/run_driver_node.h).
#include "serial_robot_driver/ros/run_driver_node.h"

int main(int argc, char** argv) {
  return serial_robot_driver::ros_layer::runDriverNode(argc, argv);
}
