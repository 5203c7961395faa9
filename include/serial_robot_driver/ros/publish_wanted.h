// Work nobody asked for is not done: a message for a topic nobody subscribes to is not built. Every
// publishing site of the adapters asks this first (subscribers in the same nodelet manager count).
#pragma once

#include <ros/publisher.h>

namespace serial_robot_driver::ros_layer {

/// Whether `publisher` has a subscriber now (false for one not advertised).
inline bool wanted(const ros::Publisher& publisher) {
  return publisher && publisher.getNumSubscribers() > 0;
}

}  // namespace serial_robot_driver::ros_layer
