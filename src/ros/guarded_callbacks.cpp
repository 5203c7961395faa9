#include "serial_robot_driver/ros/guarded_callbacks.h"

#include <exception>

namespace serial_robot_driver::ros_layer {

bool runGuarded(core::InputRefusals& counters, const std::string& source,
                const std::function<void()>& callback, std::string* error) {
  std::string what;
  try {
    callback();
    return true;
  } catch (const std::exception& e) {
    what = e.what();
  } catch (...) {
    what = "an exception that is not a std::exception";
  }
  counters.failed(source);
  // Throttled: a sender repeating the message must not flood the log; the count is exact.
  ROS_ERROR_THROTTLE(1.0,
                     "%s: internal error, this input was dropped (or answered as a failure): %s",
                     source.c_str(), what.c_str());
  if (error) *error = what;
  return false;
}

}  // namespace serial_robot_driver::ros_layer
