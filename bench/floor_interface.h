// The rest of driver_node's ROS interface, offered by floor_node's ~same_interface as minimally as
// any node offering it can: what a node doing driver_node's job spends on its interface alone,
// whoever listens. Benchmark only.
#pragma once

#include <actionlib/server/action_server.h>
#include <dynamic_reconfigure/server.h>
#include <ros/ros.h>

#include <memory>
#include <vector>

#include "serial_robot_driver/FollowJointTrajectoryAction.h"
#include "serial_robot_driver/TrajectoryTuningConfig.h"

namespace floor_bench {

/// driver_node's publications, subscriptions, dynamic_reconfigure servers and action server
/// beyond the floor's own topics, each doing nothing but exist: roscpp's poll thread walks every
/// publication's queue each time it wakes, the action server publishes its status at 5 Hz, and a
/// subscription costs its callback only when a message comes. Services are left out: they add no
/// work until called (roscpp serves them from the one listening socket).
class FloorInterface {
 public:
  FloorInterface(ros::NodeHandle& nh, ros::NodeHandle& pnh);

 private:
  using TuningServer = dynamic_reconfigure::Server<serial_robot_driver::TrajectoryTuningConfig>;
  using ActionServer = actionlib::ActionServer<serial_robot_driver::FollowJointTrajectoryAction>;

  std::vector<ros::Publisher> publishers_;
  std::vector<ros::Subscriber> subscribers_;
  std::vector<std::unique_ptr<TuningServer>> tuning_;
  std::unique_ptr<ActionServer> action_;
};

}  // namespace floor_bench
