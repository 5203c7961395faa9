// The REP-2011 type descriptions of every ROS 2 type the DDS layer speaks, from the ROS 2 Jazzy
// .msg files (common_interfaces, rcl_interfaces/builtin_interfaces, rmw_dds_common), in their field
// order. Mapping of .msg types: float64 -> double, float32 -> float, bool -> boolean, byte -> byte,
// char -> uint8 (rosidl maps msg char to uint8), T[N] -> array (capacity N), T[] -> unbounded
// sequence, string<=N -> bounded string (string_capacity N). Constants are not part of a type
// description. The same types are in dds/idl/ for idlc.
#include <algorithm>

#include "serial_robot_driver/dds/type_description.h"

namespace serial_robot_driver {
namespace dds {

namespace {

using namespace field_type;

Field plain(const char* name, uint8_t type_id) { return {name, {type_id, 0, 0, ""}}; }

Field nested(const char* name, const char* type_name) { return {name, {kNested, 0, 0, type_name}}; }

Field array(const char* name, uint8_t element_id, uint64_t size) {
  return {name, {static_cast<uint8_t>(element_id + kArray), size, 0, ""}};
}

Field sequence(const char* name, uint8_t element_id) {
  return {name, {static_cast<uint8_t>(element_id + kUnboundedSequence), 0, 0, ""}};
}

Field nestedSequence(const char* name, const char* type_name) {
  return {name, {kNested + kUnboundedSequence, 0, 0, type_name}};
}

std::vector<Field> xyz() { return {plain("x", kDouble), plain("y", kDouble), plain("z", kDouble)}; }

std::vector<Field> secondsAndNanoseconds() {
  return {plain("sec", kInt32), plain("nanosec", kUint32)};
}

std::vector<TypeDescription> stdAndGeometryTypes() {
  return {
      {"builtin_interfaces/msg/Time", secondsAndNanoseconds()},
      {"builtin_interfaces/msg/Duration", secondsAndNanoseconds()},
      {"std_msgs/msg/Header",
       {nested("stamp", "builtin_interfaces/msg/Time"), plain("frame_id", kString)}},
      {"std_msgs/msg/Bool", {plain("data", kBoolean)}},
      {"geometry_msgs/msg/Vector3", xyz()},
      {"geometry_msgs/msg/Point", xyz()},
      {"geometry_msgs/msg/Quaternion",
       {plain("x", kDouble), plain("y", kDouble), plain("z", kDouble), plain("w", kDouble)}},
      {"geometry_msgs/msg/Pose",
       {nested("position", "geometry_msgs/msg/Point"),
        nested("orientation", "geometry_msgs/msg/Quaternion")}},
      {"geometry_msgs/msg/PoseWithCovariance",
       {nested("pose", "geometry_msgs/msg/Pose"), array("covariance", kDouble, 36)}},
      {"geometry_msgs/msg/Twist",
       {nested("linear", "geometry_msgs/msg/Vector3"),
        nested("angular", "geometry_msgs/msg/Vector3")}},
      {"geometry_msgs/msg/TwistWithCovariance",
       {nested("twist", "geometry_msgs/msg/Twist"), array("covariance", kDouble, 36)}},
      {"geometry_msgs/msg/TwistStamped",
       {nested("header", "std_msgs/msg/Header"), nested("twist", "geometry_msgs/msg/Twist")}},
      {"geometry_msgs/msg/Transform",
       {nested("translation", "geometry_msgs/msg/Vector3"),
        nested("rotation", "geometry_msgs/msg/Quaternion")}},
      {"geometry_msgs/msg/TransformStamped",
       {nested("header", "std_msgs/msg/Header"), plain("child_frame_id", kString),
        nested("transform", "geometry_msgs/msg/Transform")}},
  };
}

TypeDescription batteryState() {
  std::vector<Field> fields{nested("header", "std_msgs/msg/Header")};
  for (const char* name : {"voltage", "temperature", "current", "charge", "capacity",
                           "design_capacity", "percentage"}) {
    fields.push_back(plain(name, kFloat));
  }
  for (const char* name :
       {"power_supply_status", "power_supply_health", "power_supply_technology"}) {
    fields.push_back(plain(name, kUint8));
  }
  fields.push_back(plain("present", kBoolean));
  fields.push_back(sequence("cell_voltage", kFloat));
  fields.push_back(sequence("cell_temperature", kFloat));
  fields.push_back(plain("location", kString));
  fields.push_back(plain("serial_number", kString));
  return {"sensor_msgs/msg/BatteryState", fields};
}

std::vector<TypeDescription> sensorAndNavigationTypes() {
  return {
      {"sensor_msgs/msg/JointState",
       {nested("header", "std_msgs/msg/Header"), sequence("name", kString),
        sequence("position", kDouble), sequence("velocity", kDouble), sequence("effort", kDouble)}},
      {"sensor_msgs/msg/Imu",
       {nested("header", "std_msgs/msg/Header"),
        nested("orientation", "geometry_msgs/msg/Quaternion"),
        array("orientation_covariance", kDouble, 9),
        nested("angular_velocity", "geometry_msgs/msg/Vector3"),
        array("angular_velocity_covariance", kDouble, 9),
        nested("linear_acceleration", "geometry_msgs/msg/Vector3"),
        array("linear_acceleration_covariance", kDouble, 9)}},
      batteryState(),
      {"nav_msgs/msg/Odometry",
       {nested("header", "std_msgs/msg/Header"), plain("child_frame_id", kString),
        nested("pose", "geometry_msgs/msg/PoseWithCovariance"),
        nested("twist", "geometry_msgs/msg/TwistWithCovariance")}},
      {"tf2_msgs/msg/TFMessage",
       {nestedSequence("transforms", "geometry_msgs/msg/TransformStamped")}},
  };
}

std::vector<TypeDescription> diagnosticTrajectoryAndDiscoveryTypes() {
  return {
      {"diagnostic_msgs/msg/KeyValue", {plain("key", kString), plain("value", kString)}},
      {"diagnostic_msgs/msg/DiagnosticStatus",
       {plain("level", kByte), plain("name", kString), plain("message", kString),
        plain("hardware_id", kString), nestedSequence("values", "diagnostic_msgs/msg/KeyValue")}},
      {"diagnostic_msgs/msg/DiagnosticArray",
       {nested("header", "std_msgs/msg/Header"),
        nestedSequence("status", "diagnostic_msgs/msg/DiagnosticStatus")}},
      {"trajectory_msgs/msg/JointTrajectoryPoint",
       {sequence("positions", kDouble), sequence("velocities", kDouble),
        sequence("accelerations", kDouble), sequence("effort", kDouble),
        nested("time_from_start", "builtin_interfaces/msg/Duration")}},
      {"trajectory_msgs/msg/JointTrajectory",
       {nested("header", "std_msgs/msg/Header"), sequence("joint_names", kString),
        nestedSequence("points", "trajectory_msgs/msg/JointTrajectoryPoint")}},
      {"rmw_dds_common/msg/Gid", {array("data", kUint8, 16)}},
      {"rmw_dds_common/msg/NodeEntitiesInfo",
       {{"node_namespace", {kBoundedString, 0, 256, ""}},
        {"node_name", {kBoundedString, 0, 256, ""}},
        nestedSequence("reader_gid_seq", "rmw_dds_common/msg/Gid"),
        nestedSequence("writer_gid_seq", "rmw_dds_common/msg/Gid")}},
      {"rmw_dds_common/msg/ParticipantEntitiesInfo",
       {nested("gid", "rmw_dds_common/msg/Gid"),
        nestedSequence("node_entities_info_seq", "rmw_dds_common/msg/NodeEntitiesInfo")}},
  };
}

std::vector<TypeDescription> allTypes() {
  std::vector<TypeDescription> types = stdAndGeometryTypes();
  for (auto&& more : {sensorAndNavigationTypes(), diagnosticTrajectoryAndDiscoveryTypes()}) {
    types.insert(types.end(), more.begin(), more.end());
  }
  return types;
}

}  // namespace

const std::vector<TypeDescription>& typeDescriptions() {
  static const std::vector<TypeDescription> types = allTypes();
  return types;
}

const TypeDescription* findTypeDescription(const std::string& type_name) {
  const auto& types = typeDescriptions();
  auto found = std::find_if(types.begin(), types.end(), [&](const TypeDescription& type) {
    return type.type_name == type_name;
  });
  return found == types.end() ? nullptr : &*found;
}

}  // namespace dds
}  // namespace serial_robot_driver
