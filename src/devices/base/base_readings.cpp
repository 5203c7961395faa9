#include "serial_robot_driver/devices/base/base_readings.h"

#include <cmath>

namespace serial_robot_driver::devices::base {

BatteryReading batteryReading(uint8_t percent) { return {percent / 100.0}; }

YawRotation yawRotation(double yaw) { return {std::sin(yaw / 2.0), std::cos(yaw / 2.0)}; }

}  // namespace serial_robot_driver::devices::base
