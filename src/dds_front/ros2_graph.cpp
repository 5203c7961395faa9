#include "serial_robot_driver/dds_front/ros2_graph.h"

#if defined(SRD_WITH_DDS) && SRD_WITH_DDS
#include <cstdlib>
#include <stdexcept>

#include "serial_robot_driver/dds/ros_conventions.h"
#include "serial_robot_driver/dds_front/dds_node.h"
#endif

namespace serial_robot_driver::dds_front {

#if defined(SRD_WITH_DDS) && SRD_WITH_DDS

struct Ros2Graph::Node {
  DdsNode dds;
};

void requireRos2Support(const params::DriverParams& params) {
  if (!params.ros2.enabled) return;
  try {  // -1: $ROS_DOMAIN_ID, which must then be a domain too
    dds::resolveDomainId(params.ros2.domain_id, std::getenv("ROS_DOMAIN_ID"));
  } catch (const std::invalid_argument& e) {
    throw params::ParameterError("ros2/domain_id", e.what());
  }
}

Ros2Graph::Ros2Graph(const params::DriverParams& params, const std::string& node_name,
                     core::DriverCore& core) {
  if (!params.ros2.enabled) return;
  const std::size_t slash = node_name.rfind('/');
  const std::string node_namespace = slash == 0 ? "/" : node_name.substr(0, slash);
  try {
    node_.reset(new Node{DdsNode(
        params, nodeOptions(params.ros2, node_name.substr(slash + 1), node_namespace), core)});
  } catch (const params::ParameterError&) {
    throw;
  } catch (const std::exception& e) {  // DDS refused the participant, a bad $ROS_DOMAIN_ID
    throw params::ParameterError("ros2/enabled",
                                 std::string("cannot join the ROS 2 graph: ") + e.what());
  }
}

void Ros2Graph::start() {
  if (node_) node_->dds.start();
}

void Ros2Graph::shutdown() {
  if (node_) node_->dds.shutdown();
}

#else

struct Ros2Graph::Node {};

void requireRos2Support(const params::DriverParams& params) {
  params::require(!params.ros2.enabled, "ros2/enabled",
                  "this build has no ROS 2 (DDS) front end: install cyclonedds-dev, "
                  "cyclonedds-tools and libssl-dev (scripts/install_deps.sh) and rebuild");
}

Ros2Graph::Ros2Graph(const params::DriverParams& params, const std::string& /*node_name*/,
                     core::DriverCore& /*core*/) {
  requireRos2Support(params);
}

void Ros2Graph::start() {}
void Ros2Graph::shutdown() {}

#endif

Ros2Graph::~Ros2Graph() = default;

}  // namespace serial_robot_driver::dds_front
