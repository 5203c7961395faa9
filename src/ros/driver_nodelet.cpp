// serial_robot_driver/DriverNodelet: the same DriverNode as driver_node, loaded into a nodelet
// manager. Consumers in the same manager receive joint_states and imu/data as shared pointers,
// without serialization.
//
// Threading: the manager's worker threads run the global-queue callbacks (cmd_vel, joint_commands,
// base services, the diagnostics timer); the ports' reader threads, the base loop and the servo
// service queue are the driver's own, as in driver_node. Unloading the nodelet, or stopping the
// manager, destroys it: the destructor shuts the driver down, which writes the last zero-speed
// frame before the ports close.
#include <nodelet/nodelet.h>

#include <memory>
#include <pluginlib/class_list_macros.hpp>

#include "serial_robot_driver/ros/driver_node.h"
#include "serial_robot_driver/ros/run_driver_node.h"

namespace serial_robot_driver::ros_layer {

class DriverNodelet : public nodelet::Nodelet {
 public:
  ~DriverNodelet() override {
    if (!driver_) return;
    NODELET_INFO("shutting down: stopping the wheels");
    driver_->shutdown();
  }

 private:
  void onInit() override {
    ros::NodeHandle private_nh = getPrivateNodeHandle();
    DriverParams params;
    try {
      params = loadCheckedParams(private_nh);
    } catch (const ParameterError& e) {
      // A nodelet cannot end its manager; it stays loaded and idle, saying why.
      NODELET_FATAL("%s; the driver does not start", e.what());
      return;
    }
    driver_ = std::make_unique<DriverNode>(getNodeHandle(), private_nh, params);
    driver_->start();
  }

  std::unique_ptr<DriverNode> driver_;
};

}  // namespace serial_robot_driver::ros_layer

PLUGINLIB_EXPORT_CLASS(serial_robot_driver::ros_layer::DriverNodelet, nodelet::Nodelet)
