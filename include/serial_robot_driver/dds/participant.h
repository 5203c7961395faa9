#pragma once
// A ROS 2 node on DDS, without ROS 2: one DDS participant (USER_DATA "enclave=/;") in the ROS 2
// domain, its entry in ros_discovery_info, and the dispatch thread of its subscriptions
// (dispatch_thread.h states the threading model). Publisher<T> and Subscription<T>
// (publisher.h, subscription.h) are its topics.

#include <dds/dds.h>

#include <memory>
#include <string>
#include <vector>

#include "serial_robot_driver/dds/discovery_info.h"
#include "serial_robot_driver/dds/dispatch_thread.h"
#include "serial_robot_driver/dds/domain_lease.h"
#include "serial_robot_driver/dds/ros_conventions.h"

namespace serial_robot_driver {
namespace dds {

struct NodeOptions {
  std::string name = "driver_node";
  std::string node_namespace = "/";
  /// -1: $ROS_DOMAIN_ID, or 0 when unset; 0..232: that domain.
  int domain_id = -1;
  /// Unicast discovery peers (addresses or host names) besides the multicast defaults; when all
  /// are in 127.0.0.0/8, the loopback interface only.
  std::vector<std::string> peers;
};

/// Outlives its publishers and subscriptions (they hold a reference to it).
class Participant {
 public:
  /// Throws std::invalid_argument (domain id) or std::runtime_error (DDS refused something).
  explicit Participant(const NodeOptions& options);
  ~Participant();
  Participant(const Participant&) = delete;
  Participant& operator=(const Participant&) = delete;

  dds_entity_t handle() const { return participant_; }
  int domainId() const { return domain_id_; }
  const Gid& gid() const { return gid_; }
  const std::string& nodeName() const { return node_name_; }
  const std::string& nodeNamespace() const { return node_namespace_; }
  /// The DDS topic of a ROS 2 topic name relative to the node's namespace ("rt/...").
  std::string topicName(const std::string& name) const;

  /// For Publisher/Subscription: their readers and writers in ros_discovery_info, their callbacks.
  DiscoveryInfo& discoveryInfo() { return *discovery_info_; }
  DispatchThread& dispatchThread() { return *dispatch_thread_; }

 private:
  int domain_id_;
  std::string node_name_;
  std::string node_namespace_;
  DomainLease domain_;
  dds_entity_t participant_ = 0;
  Gid gid_{};
  std::unique_ptr<DiscoveryInfo> discovery_info_;
  std::unique_ptr<DispatchThread> dispatch_thread_;
};

/// The GID of a participant, reader or writer (its DDS GUID, as rmw_cyclonedds takes it).
Gid entityGid(dds_entity_t entity);

}  // namespace dds
}  // namespace serial_robot_driver
