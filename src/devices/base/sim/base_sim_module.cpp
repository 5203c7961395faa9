// The base in the simulator registry: a built-in model robot_sim hosts by name (sim_options.h).
#include "serial_robot_driver/sim/sim_device_module.h"

namespace serial_robot_driver::devices::base {

extern const sim::SimDeviceModule kSimModule{"base", nullptr, {}};

}  // namespace serial_robot_driver::devices::base
