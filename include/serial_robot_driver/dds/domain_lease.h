#pragma once
// One process-wide Cyclone domain per domain id, shared by the participants on it: the first lease
// creates it with its discovery configuration, the last one deletes it (Cyclone allows one
// configuration per domain id and process, as rmw_cyclonedds does).

#include <dds/dds.h>

#include <string>

namespace serial_robot_driver {
namespace dds {

class DomainLease {
 public:
  /// `config`: Cyclone XML ("" for Cyclone's defaults; $CYCLONEDDS_URI is added either way).
  /// Throws std::runtime_error when Cyclone refuses the configuration, or when the domain is
  /// already in use in this process with another configuration.
  DomainLease(dds_domainid_t domain_id, const std::string& config);
  ~DomainLease();
  DomainLease(const DomainLease&) = delete;
  DomainLease& operator=(const DomainLease&) = delete;

 private:
  dds_domainid_t domain_id_;
};

}  // namespace dds
}  // namespace serial_robot_driver
