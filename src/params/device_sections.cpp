#include "serial_robot_driver/params/device_sections.h"

#include <stdexcept>

namespace serial_robot_driver::params {

void DeviceSections::add(const AnySectionKey& key) {
  if (!sections_.emplace(key.name(), Entry{&key, key.makeDefaults()}).second) {
    throw std::logic_error(std::string("parameter section '") + key.name() + "' declared twice");
  }
}

DeviceSections::Entry& DeviceSections::find(const std::string& name, const std::type_info& type) {
  const auto found = sections_.find(name);
  if (found == sections_.end()) {
    throw std::logic_error("no parameter section '" + name + "': no registered device declares it");
  }
  if (!found->second.value.holdsType(type)) {
    throw std::logic_error("parameter section '" + name + "' asked for with another type's key");
  }
  return found->second;
}

const DeviceSections::Entry& DeviceSections::find(const std::string& name,
                                                  const std::type_info& type) const {
  return const_cast<DeviceSections&>(*this).find(name, type);
}

DevicePortParams& DeviceSections::portParams(const std::string& name) {
  const auto found = sections_.find(name);
  DevicePortParams* ports =
      found == sections_.end() ? nullptr : found->second.key->portParams(found->second.value);
  if (ports == nullptr) {
    throw std::logic_error("device '" + name + "' has no section with its port parameters");
  }
  return *ports;
}

const DevicePortParams& DeviceSections::portParams(const std::string& name) const {
  return const_cast<DeviceSections&>(*this).portParams(name);
}

}  // namespace serial_robot_driver::params
