// The body in the simulator registry: a built-in model robot_sim hosts by name (sim_options.h).
#include "serial_robot_driver/sim/sim_device_module.h"

namespace serial_robot_driver::devices::body {

extern const sim::SimDeviceModule kSimModule{"body", nullptr, {}};

}  // namespace serial_robot_driver::devices::body
