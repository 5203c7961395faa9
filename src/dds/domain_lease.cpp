// DomainLease: the process-wide table of the domains this process created.
#include "serial_robot_driver/dds/domain_lease.h"

#include <cstdlib>
#include <map>
#include <mutex>
#include <stdexcept>

namespace serial_robot_driver {
namespace dds {

namespace {

struct CreatedDomain {
  dds_entity_t handle = 0;  // 0: Cyclone's implicit domain (no configuration of ours)
  std::string config;
  int leases = 0;
};

std::mutex& domainsMutex() {
  static std::mutex mutex;
  return mutex;
}

std::map<dds_domainid_t, CreatedDomain>& domains() {
  static std::map<dds_domainid_t, CreatedDomain> table;
  return table;
}

// Ours first, then $CYCLONEDDS_URI (Cyclone reads it only when given no configuration at all).
std::string withEnvironmentConfig(const std::string& config) {
  const char* from_environment = std::getenv("CYCLONEDDS_URI");
  return config + "," + (from_environment ? from_environment : "");
}

}  // namespace

DomainLease::DomainLease(dds_domainid_t domain_id, const std::string& config)
    : domain_id_(domain_id) {
  std::lock_guard<std::mutex> lock(domainsMutex());
  CreatedDomain& domain = domains()[domain_id];
  if (domain.leases > 0 && domain.config != config) {
    throw std::runtime_error("DDS domain " + std::to_string(domain_id) +
                             " is already in use in this process with other discovery settings");
  }
  if (domain.leases == 0 && !config.empty()) {
    const dds_entity_t handle = dds_create_domain(domain_id, withEnvironmentConfig(config).c_str());
    if (handle < 0) {
      domains().erase(domain_id);
      throw std::runtime_error("Cyclone DDS refused the configuration of domain " +
                               std::to_string(domain_id) + ": " + dds_strretcode(handle));
    }
    domain.handle = handle;
  }
  domain.config = config;
  ++domain.leases;
}

DomainLease::~DomainLease() {
  std::lock_guard<std::mutex> lock(domainsMutex());
  CreatedDomain& domain = domains()[domain_id_];
  if (--domain.leases > 0) return;
  if (domain.handle > 0) dds_delete(domain.handle);
  domains().erase(domain_id_);
}

}  // namespace dds
}  // namespace serial_robot_driver
