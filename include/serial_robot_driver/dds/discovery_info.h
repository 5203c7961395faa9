#pragma once
// The node's entry in ROS 2's graph: rmw_dds_common/ParticipantEntitiesInfo on
// `ros_discovery_info` (reliable, transient-local, keep-last 1, no "rt/" prefix), naming the
// participant's GID and its node (name, namespace) with the GIDs of the node's readers and
// writers. `ros2 node list` and `ros2 topic info` read it; it is published again on every change,
// as rmw_dds_common's GraphCache does.

#include <dds/dds.h>

#include <mutex>
#include <string>
#include <vector>

#include "serial_robot_driver/dds/ros_conventions.h"

namespace serial_robot_driver {
namespace dds {

class DiscoveryInfo {
 public:
  /// Creates the writer and publishes the node without endpoints. Throws std::runtime_error.
  DiscoveryInfo(dds_entity_t participant, const Gid& participant_gid, std::string node_name,
                std::string node_namespace);
  ~DiscoveryInfo();
  DiscoveryInfo(const DiscoveryInfo&) = delete;
  DiscoveryInfo& operator=(const DiscoveryInfo&) = delete;

  enum class Kind { kReader, kWriter };
  void addEndpoint(const Gid& gid, Kind kind);
  void removeEndpoint(const Gid& gid);

 private:
  void publishLocked();

  dds_entity_t writer_ = 0;
  Gid participant_gid_;
  std::string node_name_;
  std::string node_namespace_;
  std::mutex mutex_;
  std::vector<Gid> readers_;
  std::vector<Gid> writers_;
};

}  // namespace dds
}  // namespace serial_robot_driver
