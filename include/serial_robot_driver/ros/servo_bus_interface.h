// ROS face of the UART bus servos: the servo/* services and the "serial_robot_driver: servo_bus"
// diagnostic status. The bus logic (transactions, validation, messages) is device::ServoBusClient.
//
// Threading: the services are served from this class's OWN callback queue by its own AsyncSpinner
// (2 threads). A servo call blocks for up to timeout * (retries + 1), or for a whole motion when
// `wait` is set; on the global queue that would hold up cmd_vel and joint_commands.
#pragma once

#include <memory>
#include <vector>

#include <diagnostic_updater/diagnostic_updater.h>
#include <ros/callback_queue.h>
#include <ros/ros.h>

#include "serial_robot_driver/ServoDamping.h"
#include "serial_robot_driver/ServoPing.h"
#include "serial_robot_driver/ServoRead.h"
#include "serial_robot_driver/ServoReadAll.h"
#include "serial_robot_driver/ServoReadAngle.h"
#include "serial_robot_driver/ServoResetUserData.h"
#include "serial_robot_driver/ServoRotate.h"
#include "serial_robot_driver/ServoSpin.h"
#include "serial_robot_driver/ServoWrite.h"
#include "serial_robot_driver/device/serial_link.h"
#include "serial_robot_driver/device/servo_bus_client.h"
#include "serial_robot_driver/ros/device_interface.h"
#include "serial_robot_driver/ros/driver_params.h"
#include "serial_robot_driver/ros/queue_spinner.h"

namespace serial_robot_driver::ros_layer {

/// Client options from ~servo_bus/{timeout, retries, allow_dangerous_writes}.
device::ServoBusOptions makeServoBusOptions(const DriverParams& params);

class ServoBusInterface : public DeviceInterface {
 public:
  /// Registers the client with `link` and advertises servo/* in `nh`'s namespace. Must be
  /// constructed before the link is started.
  ServoBusInterface(ros::NodeHandle& nh, const DriverParams& params, device::SerialLink& link,
                    diagnostic_updater::Updater& diagnostics);
  ~ServoBusInterface();
  ServoBusInterface(const ServoBusInterface&) = delete;
  ServoBusInterface& operator=(const ServoBusInterface&) = delete;

  /// Starts the service spinner: calls are served from here on.
  void start() override;
  /// Fails a call in progress, stops the services and joins the spinner threads. Idempotent.
  void shutdown() override;
  void diagnose(diagnostic_updater::DiagnosticStatusWrapper& status) override;

 private:

  device::SerialLink& link_;
  device::ServoBusClient client_;
  diagnostic_updater::Updater& diagnostics_;
  ros::CallbackQueue queue_;
  ros::NodeHandle nh_;  // the caller's namespace, bound to queue_
  std::vector<ros::ServiceServer> services_;
  std::unique_ptr<QueueSpinner> spinner_;
  bool shut_down_ = false;
};

}  // namespace serial_robot_driver::ros_layer
