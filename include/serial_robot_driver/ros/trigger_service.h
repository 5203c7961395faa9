// A std_srvs/Trigger service that answers with what a device's request returned (core::Outcome),
// guarded like every other callback (ros/guarded_callbacks.h).
#pragma once

#include <ros/ros.h>
#include <std_srvs/Trigger.h>

#include <functional>
#include <string>

#include "serial_robot_driver/core/input_refusals.h"
#include "serial_robot_driver/core/outcome.h"
#include "serial_robot_driver/ros/guarded_callbacks.h"

namespace serial_robot_driver::ros_layer {

inline ros::ServiceServer advertiseTrigger(ros::NodeHandle& nh, core::InputRefusals& counters,
                                           const std::string& service,
                                           std::function<core::Outcome()> request) {
  using Request = std_srvs::Trigger::Request;
  using Response = std_srvs::Trigger::Response;
  const boost::function<bool(Request&, Response&)> serve = [request](Request&, Response& res) {
    const core::Outcome outcome = request();
    res.success = outcome.success;
    res.message = outcome.message;
    return true;
  };
  return nh.advertiseService<Request, Response>(
      service, guardedService<Request, Response>(counters, service, serve));
}

}  // namespace serial_robot_driver::ros_layer
