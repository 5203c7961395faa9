// serial_robot_driver/DriverNodelet: the same DriverNode as driver_node, loaded into a nodelet
// manager. Consumers in the same manager receive joint_states and imu/data as shared pointers,
// without serialization.
//
// Threading: the manager's worker threads run the global-queue callbacks (cmd_vel, joint_commands,
// base services, the diagnostics timer); the ports' reader threads, the base loop and the servo
// service queue are the driver's own, as in driver_node. Unloading the nodelet, or stopping the
// manager, destroys it: the destructor shuts the driver down, which writes the last zero-speed
// frame before the ports close.
//
// ~replay_bag works as in driver_node: the ports' bytes come from the bag and the real ports are
// never opened. A nodelet cannot end its manager, so at the end of the bag it logs the summary and
// stays loaded, idle; a bag that cannot be replayed is refused with the reason, and nothing starts.
#include <nodelet/nodelet.h>

#include <chrono>
#include <memory>
#include <pluginlib/class_list_macros.hpp>
#include <string>

#include "serial_robot_driver/ros/bag_replay.h"
#include "serial_robot_driver/ros/driver_node.h"
#include "serial_robot_driver/ros/run_driver_node.h"

namespace serial_robot_driver::ros_layer {

class DriverNodelet : public nodelet::Nodelet {
 public:
  ~DriverNodelet() override {
    replay_start_.stop();
    replay_watch_.stop();
    if (!driver_) return;
    NODELET_INFO("shutting down: stopping the wheels and the bus servos");
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
    core::SerialLink::StreamFactory stream_factory;
    if (!params.replay_bag.empty()) {
      try {
        replay_ = std::make_unique<BagReplay>(params);
      } catch (const ReplayError& e) {
        NODELET_FATAL("%s; the driver does not start (no port is opened)", e.what());
        return;
      }
      replay_->standIn(params, stream_factory);
      NODELET_INFO("replaying %s from %s (rate %g; 0: full speed)",
                   replay_->recording().topic.c_str(), params.replay_bag.c_str(),
                   params.replay_rate);
    }
    driver_ = std::make_unique<DriverNode>(getNodeHandle(), private_nh, params, stream_factory);
    if (!replay_) {
      driver_->start();
      return;
    }
    // As driver_node: give subscribers time to connect before the first chunk, then watch for the
    // end of the bag. Both on wall timers, so onInit() does not hold the manager up.
    ros::NodeHandle nh = getNodeHandle();
    replay_start_ = nh.createWallTimer(
        kReplaySettle,
        [this](const ros::WallTimerEvent&) {
          replay_->startClock();
          driver_->start();
        },
        true);
    replay_watch_ = nh.createWallTimer(ros::WallDuration(0.05), [this](const ros::WallTimerEvent&) {
      if (!replay_->finished()) return;
      replay_watch_.stop();
      driver_->updateDiagnostics();
      NODELET_INFO("%s; the replay is over, the nodelet stays loaded", replay_->summary().c_str());
    });
  }

  static inline const ros::WallDuration kReplaySettle{
      std::chrono::duration<double>(core::kReplaySettle).count()};
  // Declared first, destroyed last: the driver's links read from the replay's ports.
  std::unique_ptr<BagReplay> replay_;
  std::unique_ptr<DriverNode> driver_;
  ros::WallTimer replay_start_, replay_watch_;
};

}  // namespace serial_robot_driver::ros_layer

PLUGINLIB_EXPORT_CLASS(serial_robot_driver::ros_layer::DriverNodelet, nodelet::Nodelet)
