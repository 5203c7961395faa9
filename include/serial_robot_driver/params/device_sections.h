// Every device's parameter section, typed and reached the same way: a device declares a key for
// each of its sections (`SectionKey<BaseParams> kBaseSection{"base"}`, in its module), lists the
// keys in its DeviceModule, and DriverParams holds one of each with its defaults
// (params.section(kBaseSection)). No device is named here, and a new device's section is no
// second-class citizen. Copies copy every section (device::TypedValue); asking with a key whose
// type is not the stored section's, or for a section no registered device declared, is a
// programming error (std::logic_error).
#pragma once

#include <map>
#include <string>
#include <type_traits>
#include <typeinfo>

#include "serial_robot_driver/core/typed_value.h"
#include "serial_robot_driver/params/port_params.h"

namespace serial_robot_driver::params {

/// A section's name and what DeviceSections needs without its type: its defaults and its port
/// parameters (what a DeviceModule lists). Constant-initialised, so a key is usable from any
/// static initialiser.
class AnySectionKey {
 public:
  /// The section's parameter prefix ("base", "imu"): also its name in DeviceSections.
  const char* name() const { return name_; }
  core::TypedValue makeDefaults() const { return make_defaults_(); }
  /// The port parameters inside `section` (a value of this key's type) when its struct has
  /// them (a device's own section), else null.
  DevicePortParams* portParams(core::TypedValue& section) const { return port_params_(section); }

 protected:
  constexpr AnySectionKey(const char* name, core::TypedValue (*make_defaults)(),
                          DevicePortParams* (*port_params)(core::TypedValue&))
      : name_(name), make_defaults_(make_defaults), port_params_(port_params) {}

 private:
  const char* name_;
  core::TypedValue (*make_defaults_)();
  DevicePortParams* (*port_params_)(core::TypedValue&);
};

/// The typed key of a section of type `Section`, declared once by the device that owns it.
template <typename Section>
class SectionKey final : public AnySectionKey {
 public:
  constexpr explicit SectionKey(const char* name)
      : AnySectionKey(name, &makeSection, &portParamsOf) {}

 private:
  static core::TypedValue makeSection() { return Section{}; }
  static DevicePortParams* portParamsOf(core::TypedValue& section) {
    if constexpr (std::is_base_of_v<DevicePortParams, Section>) {
      return &section.as<Section>();
    } else {
      return nullptr;
    }
  }
};

/// The sections of the registered devices, by name.
class DeviceSections {
 public:
  /// Adds the section of `key` with its defaults; throws std::logic_error when its name is taken.
  void add(const AnySectionKey& key);

  template <typename Section>
  Section& get(const SectionKey<Section>& key) {
    return find(key.name(), typeid(Section)).value.template as<Section>();
  }
  template <typename Section>
  const Section& get(const SectionKey<Section>& key) const {
    return find(key.name(), typeid(Section)).value.template as<Section>();
  }

  /// The port parameters of the section called `name` (a device's own section); throws
  /// std::logic_error when there is none or it has no port parameters.
  DevicePortParams& portParams(const std::string& name);
  const DevicePortParams& portParams(const std::string& name) const;

 private:
  struct Entry {
    const AnySectionKey* key;
    core::TypedValue value;  ///< of the key's type
  };
  /// The section called `name`; throws std::logic_error when there is none or it is no `type`.
  Entry& find(const std::string& name, const std::type_info& type);
  const Entry& find(const std::string& name, const std::type_info& type) const;

  std::map<std::string, Entry> sections_;
};

}  // namespace serial_robot_driver::params
