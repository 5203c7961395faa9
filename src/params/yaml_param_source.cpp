#include "serial_robot_driver/params/yaml_param_source.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <stdexcept>

namespace serial_robot_driver::params {

namespace {

/// The node at a "a/b/c" path below `root`; an undefined node when any step is missing.
YAML::Node find(const YAML::Node& root, const std::string& key) {
  // Nodes are references: reset() moves `node` along without writing into the document.
  YAML::Node node;
  node.reset(root);
  std::size_t start = 0;
  while (start <= key.size()) {
    const std::size_t slash = std::min(key.find('/', start), key.size());
    const std::string step = key.substr(start, slash - start);
    if (!node.IsMap()) return YAML::Node(YAML::NodeType::Undefined);
    const YAML::Node& map = node;
    const YAML::Node next = map[step];  // const lookup: inserts nothing
    if (!next.IsDefined()) return YAML::Node(YAML::NodeType::Undefined);
    node.reset(next);
    start = slash + 1;
  }
  return node;
}

template <typename T>
bool readScalar(const YAML::Node& node, T* out) {
  if (!node.IsScalar()) return false;
  *out = node.as<T>();
  return true;
}

template <typename T>
bool readList(const YAML::Node& node, std::vector<T>* out) {
  if (!node.IsSequence()) return false;
  std::vector<T> values;
  for (const auto& item : node) {
    T value;
    if (!readScalar(item, &value)) return false;
    values.push_back(value);
  }
  *out = std::move(values);
  return true;
}

void collectKeys(const YAML::Node& node, const std::string& prefix,
                 std::vector<std::string>* keys) {
  for (const auto& entry : node) {
    const std::string key = prefix + entry.first.as<std::string>();
    if (entry.second.IsMap()) {
      collectKeys(entry.second, key + "/", keys);
    } else {
      keys->push_back(key);
    }
  }
}

}  // namespace

YamlParamSource::YamlParamSource(const std::string& path) {
  try {
    root_ = std::make_unique<YAML::Node>(YAML::LoadFile(path));
  } catch (const YAML::Exception& e) {
    throw std::runtime_error("cannot read the parameter file " + path + ": " + e.what());
  }
  // An empty file is an empty set of parameters, as for rosparam.
  if (!root_->IsMap() && !root_->IsNull()) {
    throw std::runtime_error("the parameter file " + path + " is not a YAML mapping of parameters");
  }
}

YamlParamSource::~YamlParamSource() = default;

bool YamlParamSource::has(const std::string& key) const { return find(*root_, key).IsDefined(); }

bool YamlParamSource::get(const std::string& key, ParamValue* value) const {
  const YAML::Node node = find(*root_, key);
  try {
    return std::visit(
        [&node](auto& typed) {
          using T = std::decay_t<decltype(typed)>;
          if constexpr (std::is_same_v<T, std::vector<int>> ||
                        std::is_same_v<T, std::vector<double>> ||
                        std::is_same_v<T, std::vector<std::string>>) {
            return readList(node, &typed);
          } else {
            return readScalar(node, &typed);
          }
        },
        *value);
  } catch (const YAML::Exception&) {
    return false;  // e.g. "0.5" where an integer belongs
  }
}

std::vector<std::string> YamlParamSource::keys() const {
  std::vector<std::string> keys;
  if (root_->IsMap()) collectKeys(*root_, "", &keys);
  return keys;
}

DriverParams loadParamsFile(const std::string& path, std::vector<std::string>* unknown_keys) {
  const YamlParamSource source(path);
  DriverParams params = loadParams(source, unknown_keys);
  // ~tf_prefix: a file holds only the private namespace, so there is nothing to search upward.
  if (source.has("tf_prefix")) {
    ParamValue prefix = std::string();
    if (!source.get("tf_prefix", &prefix)) throw ParameterError("tf_prefix", "must be a string");
    params.tf_prefix = std::get<std::string>(prefix);
  }
  params.resolveFrames();
  return params;
}

}  // namespace serial_robot_driver::params
