// The parameters every device has: whether it runs and where it talks.
#pragma once

#include <string>

namespace serial_robot_driver::params {

/// ~<device>/enabled, ~<device>/port, ~<device>/baud.
struct DevicePortParams {
  bool enabled = true;
  std::string port;  ///< empty: the node-wide ~port
  int baud = 0;      ///< 0: the node-wide ~baud
};

}  // namespace serial_robot_driver::params
