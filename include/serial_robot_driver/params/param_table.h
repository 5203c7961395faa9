// The parameter table: one row per ~parameter, the only place its key is spelled. A row binds the
// key straight to the field it sets (the default is that field's initial value) and carries its
// range check; loading, the unknown-key warning, validate()'s single-value checks, runtime tuning
// and the documentation test all walk the table. Each device adds its own rows
// (device/device_module.h); no ROS in here, so another front end can load the same table.
#pragma once

#include <functional>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <variant>
#include <vector>

namespace serial_robot_driver::params {

struct DriverParams;

class ParameterError : public std::runtime_error {
 public:
  ParameterError(const std::string& name, const std::string& problem)
      : std::runtime_error("parameter ~" + name + ": " + problem), name_(name) {}
  const std::string& name() const { return name_; }

 private:
  std::string name_;
};

/// One parameter's value; the alternative held says the parameter's type.
using ParamValue = std::variant<bool, int, double, std::string, std::vector<int>,
                                std::vector<std::string>, std::vector<double>>;

/// How a parameter's expected type reads in an error message ("a number").
std::string typeName(const ParamValue& value);
/// A parameter value as text for a log line: 0.5, true, 20, "odom", [1, 2].
std::string toText(const ParamValue& value);

/// One row of the table: the key under ~ and how it reaches its DriverParams field.
struct ParamSpec {
  std::string key;
  /// The device whose parameter this is (its name), or empty for a node-wide one: a device's
  /// values are range-checked only while the device is enabled.
  std::string device;
  std::function<ParamValue(const DriverParams&)> get;
  /// Throws ParameterError(key, ...) for a value a converted row refuses as written
  /// (makeConvertedRow); a plain row takes any value of its type and leaves it to `check`.
  std::function<void(DriverParams&, const ParamValue&)> set;
  /// Throws ParameterError(key, ...) when the field's value is out of range.
  std::function<void(const DriverParams&)> check;
};

// --- range checks: each throws ParameterError naming `key` ---------------------------------------

void require(bool ok, const std::string& key, const std::string& problem);

template <typename T>
using Rule = std::function<void(const T& value, const std::string& key)>;

void positiveNumber(const double& value, const std::string& key);
void positiveInteger(const int& value, const std::string& key);
void nonNegativeNumber(const double& value, const std::string& key);
void finiteNumber(const double& value, const std::string& key);
void percent(const int& value, const std::string& key);
/// 1 or -1 (a wheel's or a joint's sign).
void direction(const int& value, const std::string& key);
void directionList(const std::vector<int>& values, const std::string& key);
/// A tf frame name: not empty, no spaces.
void frameId(const std::string& value, const std::string& key);
/// Names that are not empty and not listed twice.
void uniqueNames(const std::vector<std::string>& names, const std::string& key);
/// Network hosts: each an IPv4 address (a.b.c.d) or a host name (RFC 1123 labels), none twice.
void networkHosts(const std::vector<std::string>& hosts, const std::string& key);
/// A port: a device path, or a tcp:// URL that parses (transport::parseTcpUrl); `portOrInherit`
/// also takes "" (the node-wide ~port).
void portPath(const std::string& value, const std::string& key);
void portOrInherit(const std::string& value, const std::string& key);
/// A baud rate the serial port supports; `baudOrInherit` also takes 0 (the node-wide ~baud).
void baudRate(const int& value, const std::string& key);
void baudOrInherit(const int& value, const std::string& key);
/// An integer within [low, high], `unit` for the message ("ms").
Rule<int> integerWithin(int low, int high, const std::string& unit = "");
/// A finite number within [low, high].
Rule<double> numberWithin(double low, double high, const std::string& unit = "");

// --- rows
// ------------------------------------------------------------------------------------------

template <typename T>
struct NoDeduce {
  using type = T;
};

/// A row whose field `access` reaches (a lambda DriverParams& -> T&).
template <typename T, typename Access>
ParamSpec makeRow(std::string key, std::string device, Access access, Rule<T> rule) {
  ParamSpec spec;
  spec.key = std::move(key);
  spec.device = std::move(device);
  spec.get = [access](const DriverParams& p) {
    return ParamValue(access(const_cast<DriverParams&>(p)));
  };
  spec.set = [access](DriverParams& p, const ParamValue& value) { access(p) = std::get<T>(value); };
  spec.check = [access, rule, name = spec.key](const DriverParams& p) {
    if (rule) rule(access(const_cast<DriverParams&>(p)), name);
  };
  return spec;
}

/// Whether the single-value checks of `device`'s rows apply to `p`: always for a node-wide row
/// (empty `device`), for a device's only while it is enabled.
bool isChecked(const DriverParams& p, const std::string& device);

/// A row whose field (`access`: DriverParams& -> Core&) has another type than the parameter
/// (`Param`): `to_core` converts a set value, `to_param` reads the field back. The check sees the
/// value as the user wrote it, before the conversion (which may lose what makes it bad: -0.0004 s
/// is 0 ms, "halt" is no shutdown action): setting a value the check refuses throws its
/// ParameterError and leaves the field as it was. validate() checks the value read back, which
/// catches a field set in code. `to_core` must take any value (a disabled device's values are
/// not checked).
template <typename Param, typename Access, typename ToCore, typename ToParam>
ParamSpec makeConvertedRow(std::string key, std::string device, Access access, ToCore to_core,
                           ToParam to_param, Rule<Param> rule) {
  ParamSpec spec;
  spec.key = std::move(key);
  spec.device = std::move(device);
  spec.get = [access, to_param](const DriverParams& p) {
    return ParamValue(Param(to_param(access(const_cast<DriverParams&>(p)))));
  };
  spec.set = [access, to_core, rule, name = spec.key, owner = spec.device](
                 DriverParams& p, const ParamValue& value) {
    const Param& given = std::get<Param>(value);
    if (rule && isChecked(p, owner)) rule(given, name);
    access(p) = to_core(given);
  };
  spec.check = [access, to_param, rule, name = spec.key](const DriverParams& p) {
    if (rule) rule(Param(to_param(access(const_cast<DriverParams&>(p)))), name);
  };
  return spec;
}

/// A row of one section of DriverParams: `key` is "<prefix>/<name>" and `field` reaches the value
/// inside the section (`&BaseParams::publish_tf`, or a lambda Section& -> T& for a nested field of
/// a core configuration).
template <typename Section>
class SectionRows {
 public:
  SectionRows(std::vector<ParamSpec>& table, std::string device, std::string prefix,
              std::function<Section&(DriverParams&)> section)
      : table_(table),
        device_(std::move(device)),
        prefix_(std::move(prefix)),
        section_(std::move(section)) {}

  template <typename T, typename Owner>
  SectionRows& add(const char* name, T Owner::*field, typename NoDeduce<Rule<T>>::type rule = {}) {
    static_assert(std::is_base_of_v<Owner, Section>, "the field must belong to the section");
    auto section = section_;
    table_.push_back(makeRow<T>(
        prefix_ + "/" + name, device_,
        [section, field](DriverParams& p) -> T& { return static_cast<Owner&>(section(p)).*field; },
        rule));
    return *this;
  }

  /// A field reached by `access` (Section& -> T&), e.g. a value inside a nested core config.
  template <typename T, typename Access>
  SectionRows& addNested(const char* name, Access access,
                         typename NoDeduce<Rule<T>>::type rule = {}) {
    auto section = section_;
    table_.push_back(makeRow<T>(
        prefix_ + "/" + name, device_,
        [section, access](DriverParams& p) -> T& { return access(section(p)); }, rule));
    return *this;
  }

  /// A field reached by `access` (Section& -> Core&) whose type differs from the parameter's
  /// `Param` (see makeConvertedRow), e.g. a whole number of ticks the core keeps as a double, or
  /// seconds it keeps as milliseconds.
  template <typename Param, typename Access, typename ToCore, typename ToParam>
  SectionRows& addConverted(const char* name, Access access, ToCore to_core, ToParam to_param,
                            typename NoDeduce<Rule<Param>>::type rule = {}) {
    auto section = section_;
    table_.push_back(makeConvertedRow<Param>(
        prefix_ + "/" + name, device_,
        [section, access](DriverParams& p) -> decltype(auto) { return access(section(p)); },
        to_core, to_param, rule));
    return *this;
  }

 private:
  std::vector<ParamSpec>& table_;
  std::string device_;
  std::string prefix_;
  std::function<Section&(DriverParams&)> section_;
};

/// Every row: the node-wide ones, then each registered device's, in registration order. Built once.
const std::vector<ParamSpec>& parameterTable();
/// The row of `key`; throws std::invalid_argument when there is none.
const ParamSpec& specFor(const std::string& key);

/// Where loadParams reads from: the parameter server in the ROS layer, a map in tests.
class ParamSource {
 public:
  virtual ~ParamSource() = default;
  virtual bool has(const std::string& key) const = 0;
  /// Overwrites `value` (keeping its alternative) with the stored value of `key`; false when the
  /// stored value has another type.
  virtual bool get(const std::string& key, ParamValue* value) const = 0;
  /// Every key the source holds (relative to ~).
  virtual std::vector<std::string> keys() const = 0;
};

}  // namespace serial_robot_driver::params
