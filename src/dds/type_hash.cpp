// REP-2011 type hashes: the hashable JSON of a type description and its SHA-256 (libcrypto).
#include <openssl/evp.h>

#include <set>
#include <stdexcept>

#include "serial_robot_driver/dds/type_description.h"

namespace serial_robot_driver {
namespace dds {

namespace {

// Python's json.dumps(ensure_ascii=True) of the identifiers and type names these tables hold.
std::string jsonString(const std::string& text) {
  std::string quoted = "\"";
  for (char c : text) {
    if (c == '"' || c == '\\') quoted += '\\';
    quoted += c;
  }
  return quoted + "\"";
}

std::string fieldJson(const Field& field) {
  const FieldType& type = field.type;
  return "{\"name\": " + jsonString(field.name) +
         ", \"type\": {\"type_id\": " + std::to_string(type.type_id) +
         ", \"capacity\": " + std::to_string(type.capacity) +
         ", \"string_capacity\": " + std::to_string(type.string_capacity) +
         ", \"nested_type_name\": " + jsonString(type.nested_type_name) + "}}";
}

std::string individualJson(const TypeDescription& type) {
  std::string json = "{\"type_name\": " + jsonString(type.type_name) + ", \"fields\": [";
  for (size_t i = 0; i < type.fields.size(); ++i) {
    json += (i ? ", " : "") + fieldJson(type.fields[i]);
  }
  return json + "]}";
}

const TypeDescription& describedType(const std::string& type_name) {
  const TypeDescription* type = findTypeDescription(type_name);
  if (!type) throw std::invalid_argument("no ROS 2 type description for " + type_name);
  return *type;
}

// Every type nested in `type`, transitively; std::set sorts them as Python's sorted() does.
std::set<std::string> referencedTypeNames(const TypeDescription& type) {
  std::set<std::string> found;
  std::vector<const TypeDescription*> to_visit{&type};
  while (!to_visit.empty()) {
    const TypeDescription* visiting = to_visit.back();
    to_visit.pop_back();
    for (const Field& field : visiting->fields) {
      const std::string& nested = field.type.nested_type_name;
      if (!nested.empty() && found.insert(nested).second) {
        to_visit.push_back(&describedType(nested));
      }
    }
  }
  return found;
}

}  // namespace

std::string hashableTypeDescriptionJson(const std::string& type_name) {
  const TypeDescription& type = describedType(type_name);
  std::string json =
      "{\"type_description\": " + individualJson(type) + ", \"referenced_type_descriptions\": [";
  bool first = true;
  for (const std::string& referenced : referencedTypeNames(type)) {
    json += (first ? "" : ", ") + individualJson(describedType(referenced));
    first = false;
  }
  return json + "]}";
}

std::string rihs01(const std::string& json) {
  unsigned char digest[EVP_MAX_MD_SIZE];
  unsigned int digest_size = 0;
  if (EVP_Digest(json.data(), json.size(), digest, &digest_size, EVP_sha256(), nullptr) != 1) {
    throw std::runtime_error("SHA-256 failed (libcrypto)");
  }
  static const char kHex[] = "0123456789abcdef";
  std::string hash = "RIHS01_";
  for (unsigned int i = 0; i < digest_size; ++i) {
    hash += kHex[digest[i] >> 4];
    hash += kHex[digest[i] & 0x0f];
  }
  return hash;
}

std::string typeHash(const std::string& type_name) {
  return rihs01(hashableTypeDescriptionJson(type_name));
}

}  // namespace dds
}  // namespace serial_robot_driver
