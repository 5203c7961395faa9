// The ROS 2 side of a process that hosts the core for another graph (driver_node, ~ros2/enabled):
// the DDS front end (dds_node.h) on that process's core, named like its ROS 1 node, so one process
// serves both graphs. ROS-free, and built with or without Cyclone DDS (srd_ros compiles it): a
// build without it has no graph to join, and ~ros2/enabled true is then a parameter error.
#pragma once

#include <memory>
#include <string>

#include "serial_robot_driver/core/driver_core.h"
#include "serial_robot_driver/params/driver_params.h"

namespace serial_robot_driver::dds_front {

/// With ~ros2/enabled: throws params::ParameterError naming ~ros2/enabled in a build without DDS,
/// ~ros2/domain_id when it is -1 and $ROS_DOMAIN_ID is no domain.
void requireRos2Support(const params::DriverParams& params);

class Ros2Graph {
 public:
  /// Joins the ROS 2 graph as `node_name` ("/robot1/driver_node": its namespace and name) when
  /// ~ros2/enabled, attaching to `core`'s devices (before core.start()); nothing otherwise.
  /// Throws params::ParameterError (~ros2/...) when the graph cannot be joined.
  Ros2Graph(const params::DriverParams& params, const std::string& node_name,
            core::DriverCore& core);
  ~Ros2Graph();
  /// After core.start().
  void start();
  /// Before core.shutdown(): no input from the ROS 2 graph from then on. Idempotent.
  void shutdown();

 private:
  struct Node;
  std::unique_ptr<Node> node_;  // null without ~ros2/enabled
};

}  // namespace serial_robot_driver::dds_front
