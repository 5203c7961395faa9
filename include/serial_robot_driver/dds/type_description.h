#pragma once
// REP-2011 type descriptions and type hashes (RIHS01) of the ROS 2 types the DDS layer speaks.
// ROS 2 (Jazzy and later) puts `typehash=RIHS01_<hex>;` in each endpoint's USER_DATA; a peer that
// computes a different hash for the same type name reports a type mismatch.
//
// The hash is the SHA-256 of the type description in the one JSON form that
// rosidl_generator_type_description hashes:
//   {"type_description": T, "referenced_type_descriptions": [T, ...]}
// with every T as {"type_name": ..., "fields": [{"name": ..., "type": {"type_id": ...,
// "capacity": ..., "string_capacity": ..., "nested_type_name": ...}}, ...]}, the referenced types
// (every nested type, transitively) sorted by name, separators ", " and ": ", no default values.

#include <cstdint>
#include <string>
#include <vector>

namespace serial_robot_driver {
namespace dds {

/// type_description_interfaces/msg/FieldType ids (the ones these types use).
namespace field_type {
constexpr uint8_t kNested = 1;
constexpr uint8_t kUint8 = 3;
constexpr uint8_t kInt32 = 6;
constexpr uint8_t kUint32 = 7;
constexpr uint8_t kFloat = 10;
constexpr uint8_t kDouble = 11;
constexpr uint8_t kBoolean = 15;
constexpr uint8_t kByte = 16;
constexpr uint8_t kString = 17;
constexpr uint8_t kBoundedString = 21;
/// Added to the element's id: T[N], T[] (unbounded sequence).
constexpr uint8_t kArray = 48;
constexpr uint8_t kUnboundedSequence = 144;
}  // namespace field_type

struct FieldType {
  uint8_t type_id = 0;
  uint64_t capacity = 0;         ///< array size (T[N]) or sequence bound
  uint64_t string_capacity = 0;  ///< string<=N
  std::string nested_type_name;  ///< "pkg/msg/Type" for nested types, else ""
};

struct Field {
  std::string name;
  FieldType type;
};

/// One type: type_description_interfaces/msg/IndividualTypeDescription without default values.
struct TypeDescription {
  std::string type_name;  ///< "sensor_msgs/msg/JointState"
  std::vector<Field> fields;
};

/// Every type of the DDS layer, in one table (src/dds/type_descriptions.cpp).
const std::vector<TypeDescription>& typeDescriptions();

/// nullptr when the table has no such type.
const TypeDescription* findTypeDescription(const std::string& type_name);

/// The JSON that is hashed (see above). Throws std::invalid_argument for a type (or nested type)
/// not in the table.
std::string hashableTypeDescriptionJson(const std::string& type_name);

/// "RIHS01_" + the lower-case hex SHA-256 of `json`.
std::string rihs01(const std::string& json);

/// The type hash of a type of the table ("RIHS01_<64 hex>"); throws std::invalid_argument if
/// unknown.
std::string typeHash(const std::string& type_name);

}  // namespace dds
}  // namespace serial_robot_driver
