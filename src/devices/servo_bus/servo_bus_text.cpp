#include "servo_bus_text.h"

#include <cstdio>

namespace serial_robot_driver::devices::servo_bus::servo_text {

std::string formatNumber(double value) {
  char text[32];
  std::snprintf(text, sizeof(text), "%g", value);
  return text;
}

std::string servoName(uint8_t id) {
  if (id == kBroadcastId) return "all servos (broadcast id 255)";
  return "servo " + std::to_string(id);
}

/// Quotes a name for a message; a caller's absurdly long string is cut, not echoed in full.
std::string quoted(std::string_view name) {
  constexpr std::size_t kMaxShown = 40;
  if (name.size() <= kMaxShown) return "'" + std::string(name) + "'";
  return "'" + std::string(name.substr(0, kMaxShown)) + "...' (" + std::to_string(name.size()) +
         " characters)";
}

std::string formatMs(double ms) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.1f ms", ms);
  return text;
}

std::string attemptsText(int attempts) {
  return std::to_string(attempts) + (attempts == 1 ? " attempt" : " attempts");
}

ServoStatus notConnected() {
  return fail(ServoError::kNotConnected, "servo bus port is not connected");
}

std::optional<ServoStatus> rejectBroadcast(uint8_t id, Command cmd) {
  if (id != kBroadcastId) return std::nullopt;
  return fail(ServoError::kInvalidArgument, std::string("id 255 is the broadcast address; ") +
                                                commandName(cmd) +
                                                " needs the answer of one servo (ids 0..254)");
}

bool refused(const Packet& answer) {
  const int index = commandInfo(static_cast<Command>(answer.cmd)).result_index;
  return index != kNoResult && index < answer.content_size &&
         answer.content[index] == kResultFailed;
}

}  // namespace serial_robot_driver::devices::servo_bus::servo_text
