#include "serial_robot_driver/ros/guarded_callbacks.h"

namespace serial_robot_driver::ros_layer {

void logCallbackError(const std::string& line) { ROS_ERROR_THROTTLE(1.0, "%s", line.c_str()); }

bool runGuarded(core::InputRefusals& counters, const std::string& source,
                const std::function<void()>& callback, std::string* error) {
  return core::runGuarded(counters, source, callback, error, logCallbackError);
}

}  // namespace serial_robot_driver::ros_layer
