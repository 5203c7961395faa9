#pragma once
// ROS 2's conventions on DDS, as rmw_cyclonedds and rmw_dds_common implement them (Jazzy):
// topic names, QoS depths, USER_DATA strings, the domain id and the discovery configuration.

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace serial_robot_driver {
namespace dds {

/// A ROS 2 GID: the 16-byte DDS GUID of a participant, reader or writer (rmw_cyclonedds copies the
/// entity's GUID; rmw_dds_common/Gid carries it in ros_discovery_info).
using Gid = std::array<uint8_t, 16>;

/// rclcpp's default history depth, and tf's (tf2_ros' TransformBroadcaster uses 100).
constexpr int kDefaultHistoryDepth = 10;
constexpr int kTfHistoryDepth = 100;

/// The discovery topic rmw_dds_common publishes each participant's nodes on: no "rt/" prefix
/// (avoid_ros_namespace_conventions), reliable, transient-local, keep-last 1.
constexpr const char* kDiscoveryInfoTopic = "ros_discovery_info";

/// The enclave rmw writes in the participant's USER_DATA ("enclave=/;" for the default one).
constexpr const char* kDefaultEnclave = "/";

/// "/" or "/a/b": a leading slash, no trailing slash, no empty segments.
std::string normalizedNamespace(const std::string& node_namespace);

/// The fully qualified ROS name of `name` seen from `node_namespace`: "/ns/name", or `name` itself
/// when it starts with "/" (as "/tf", "/diagnostics").
std::string fullyQualifiedName(const std::string& node_namespace, const std::string& name);

/// The DDS topic of a ROS 2 topic: "rt" + the fully qualified name ("rt/robot1/joint_states").
std::string ros2TopicName(const std::string& node_namespace, const std::string& name);

/// kTfHistoryDepth for tf (relative or absolute), kDefaultHistoryDepth otherwise.
int defaultHistoryDepth(const std::string& name);

/// An endpoint's USER_DATA: "typehash=RIHS01_<hex>;".
std::string typeHashUserData(const std::string& type_hash);

/// A participant's USER_DATA: "enclave=<enclave>;".
std::string enclaveUserData(const std::string& enclave = kDefaultEnclave);

/// The domain a configured id means: 0..232 as is; -1: $ROS_DOMAIN_ID (`ros_domain_id_env`, may be
/// null) or 0 when unset or empty. Throws std::invalid_argument for anything else.
int resolveDomainId(int configured, const char* ros_domain_id_env);

/// True for addresses in 127.0.0.0/8 and "localhost".
bool isLoopbackAddress(const std::string& address);

/// Cyclone DDS configuration (XML) for unicast discovery with `peers` besides the defaults, as
/// rmw_cyclonedds writes it for static peers (fixed participant indices so peers find each other's
/// ports); when every peer is a loopback address, on the loopback interface only and without
/// multicast. "" when there are no peers (Cyclone's defaults: multicast discovery).
std::string discoveryConfigXml(const std::vector<std::string>& peers);

}  // namespace dds
}  // namespace serial_robot_driver
