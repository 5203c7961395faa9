// robot_description: prints the URDF of the robot a driver parameter file configures
// (description/robot_description_command.h).
#include <iostream>
#include <string>
#include <vector>

#include "serial_robot_driver/description/robot_description_command.h"

int main(int argc, char** argv) {
  return serial_robot_driver::description::runRobotDescription(
      std::vector<std::string>(argv + 1, argv + argc), std::cout, std::cerr);
}
