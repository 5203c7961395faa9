// dds_driver: the driver on a ROS 2 graph only, configured by driver_node's parameter file
// (dds_front/run_dds_driver.h).
#include "serial_robot_driver/dds_front/run_dds_driver.h"

int main(int argc, char** argv) { return serial_robot_driver::dds_front::runDdsDriver(argc, argv); }
