#include "serial_robot_driver/sim/sim_option_builders.h"

#include <cerrno>
#include <cmath>
#include <cstdlib>

namespace serial_robot_driver::sim {

bool parseDouble(const std::string& text, double* value) {
  char* end = nullptr;
  errno = 0;
  const double parsed = std::strtod(text.c_str(), &end);
  if (text.empty() || *end != '\0' || errno != 0 || !std::isfinite(parsed)) return false;
  *value = parsed;
  return true;
}

bool parseUnsigned(const std::string& text, uint64_t max, uint64_t* value) {
  if (text.empty() || text.find_first_not_of("0123456789") != std::string::npos) return false;
  errno = 0;
  const unsigned long long parsed = std::strtoull(text.c_str(), nullptr, 10);
  if (errno != 0 || parsed > max) return false;
  *value = parsed;
  return true;
}

bool parseIdList(const std::string& text, std::vector<uint8_t>* ids) {
  ids->clear();
  std::stringstream stream(text);
  std::string item;
  while (std::getline(stream, item, ',')) {
    uint64_t id = 0;
    if (!parseUnsigned(item, 254, &id)) return false;
    ids->push_back(static_cast<uint8_t>(id));
  }
  return true;
}

std::string badValue(const std::string& flag, const std::string& value) {
  return "bad value for " + flag + ": '" + value + "'";
}

std::string showDefault(double value) {
  std::ostringstream out;
  out << value;
  return out.str();
}

std::string showDefault(const std::vector<uint8_t>& ids) {
  std::string text;
  for (uint8_t id : ids) text += (text.empty() ? "" : ",") + std::to_string(id);
  return text;
}

namespace option_detail {

std::string applyNumber(const std::string& flag, const std::string& value, double min, double max,
                        double* field) {
  double parsed = 0;
  if (!parseDouble(value, &parsed) || parsed < min || parsed > max) return badValue(flag, value);
  *field = parsed;
  return "";
}

std::string applyWhole(const std::string& flag, const std::string& value, uint64_t max,
                       uint64_t* parsed) {
  return parseUnsigned(value, max, parsed) ? "" : badValue(flag, value);
}

std::string applyIdList(const std::string& flag, const std::string& value, std::size_t max_count,
                        const std::string& limit, std::vector<uint8_t>* ids) {
  if (!parseIdList(value, ids)) return badValue(flag, value) + " (comma-separated ids 0..254)";
  if (ids->size() > max_count) {
    return "too many " + flag + " (at most " + std::to_string(max_count) + " " + limit + ")";
  }
  return "";
}

std::string applyHeldValue(const std::string& flag, const std::string& value,
                           std::map<uint8_t, int64_t>* values) {
  const std::size_t colon = value.find(':');
  std::vector<uint8_t> ids;
  double number = 0;
  if (colon == std::string::npos || !parseIdList(value.substr(0, colon), &ids) || ids.size() != 1 ||
      !parseDouble(value.substr(colon + 1), &number) || number < 0 || number > 65535) {
    return badValue(flag, value) + " (ID:VALUE, id 0..254, value 0..65535)";
  }
  (*values)[ids.front()] = static_cast<int64_t>(number);
  return "";
}

}  // namespace option_detail

}  // namespace serial_robot_driver::sim
