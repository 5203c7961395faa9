#include "serial_robot_driver/dds/ros_conventions.h"

#include <algorithm>
#include <cstdlib>
#include <sstream>
#include <stdexcept>

namespace serial_robot_driver {
namespace dds {

namespace {

// The largest domain id whose RTPS ports (7400 + 250 * id + ...) stay below 65536, as in ROS 2.
constexpr int kMaxDomainId = 232;

std::vector<std::string> segments(const std::string& path) {
  std::vector<std::string> parts;
  std::stringstream stream(path);
  std::string part;
  while (std::getline(stream, part, '/')) {
    if (!part.empty()) parts.push_back(part);
  }
  return parts;
}

int parseDomainId(const std::string& text) {
  size_t used = 0;
  int value = -1;
  try {
    value = std::stoi(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used != text.size()) throw std::invalid_argument("ROS_DOMAIN_ID is not a number: " + text);
  return value;
}

}  // namespace

std::string normalizedNamespace(const std::string& node_namespace) {
  std::string normalized;
  for (const std::string& part : segments(node_namespace)) normalized += "/" + part;
  return normalized.empty() ? "/" : normalized;
}

std::string fullyQualifiedName(const std::string& node_namespace, const std::string& name) {
  if (!name.empty() && name.front() == '/') return normalizedNamespace(name);
  const std::string ns = normalizedNamespace(node_namespace);
  return (ns == "/" ? "" : ns) + normalizedNamespace(name);
}

std::string ros2TopicName(const std::string& node_namespace, const std::string& name) {
  return "rt" + fullyQualifiedName(node_namespace, name);
}

int defaultHistoryDepth(const std::string& name) {
  return normalizedNamespace(name) == "/tf" ? kTfHistoryDepth : kDefaultHistoryDepth;
}

std::string typeHashUserData(const std::string& type_hash) { return "typehash=" + type_hash + ";"; }

std::string enclaveUserData(const std::string& enclave) { return "enclave=" + enclave + ";"; }

int resolveDomainId(int configured, const char* ros_domain_id_env) {
  int domain = configured;
  if (configured == -1) {
    const std::string env = ros_domain_id_env ? ros_domain_id_env : "";
    domain = env.empty() ? 0 : parseDomainId(env);
  }
  if (domain < 0 || domain > kMaxDomainId) {
    throw std::invalid_argument("ROS 2 domain id " + std::to_string(domain) + " is outside 0.." +
                                std::to_string(kMaxDomainId));
  }
  return domain;
}

bool isLoopbackAddress(const std::string& address) {
  return address == "localhost" || address.rfind("127.", 0) == 0;
}

std::string discoveryConfigXml(const std::vector<std::string>& peers) {
  if (peers.empty()) return "";
  const bool loopback_only = std::all_of(peers.begin(), peers.end(), isLoopbackAddress);
  std::string xml = "<CycloneDDS><Domain><General>";
  if (loopback_only) {
    // Multicast does not work on lo; the peers are all this machine.
    xml +=
        "<Interfaces><NetworkInterface address=\"127.0.0.1\"/></Interfaces>"
        "<AllowMulticast>false</AllowMulticast>";
  }
  xml +=
      "</General><Discovery><ParticipantIndex>auto</ParticipantIndex>"
      "<MaxAutoParticipantIndex>32</MaxAutoParticipantIndex><Peers>";
  for (const std::string& peer : peers) xml += "<Peer address=\"" + peer + "\"/>";
  return xml + "</Peers></Discovery></Domain></CycloneDDS>";
}

}  // namespace dds
}  // namespace serial_robot_driver
