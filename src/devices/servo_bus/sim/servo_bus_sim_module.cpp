// The servo bus in the simulator registry: a built-in model robot_sim hosts by name
// (sim_options.h).
#include "serial_robot_driver/sim/sim_device_module.h"

namespace serial_robot_driver::devices::servo_bus {

extern const sim::SimDeviceModule kSimModule{"servo_bus", nullptr, {}};

}  // namespace serial_robot_driver::devices::servo_bus
