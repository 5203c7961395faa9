// What became of a request a device answers (a reset, a calibration): whether it was done and the
// words for the caller, the same for every front end (ROS's std_srvs/Trigger copies both).
#pragma once

#include <string>

namespace serial_robot_driver::core {

struct Outcome {
  bool success = false;
  std::string message;
};

}  // namespace serial_robot_driver::core
