// Sentences and checks shared by the servo transactions and operations. Internal to
// srd_core: not installed.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "serial_robot_driver/devices/servo_bus/servo_commands.h"
#include "serial_robot_driver/devices/servo_bus/servo_transactions.h"

namespace serial_robot_driver::devices::servo_bus::servo_text {

constexpr double kDecidegreesPerDegree = 10.0;
constexpr uint8_t kResultFailed = 0;

std::string formatNumber(double value);
std::string formatMs(double ms);
std::string attemptsText(int attempts);
/// "servo 3", or "all servos (broadcast id 255)".
std::string servoName(uint8_t id);
/// Quotes a name for a message; a caller's absurdly long string is cut, not echoed in full.
std::string quoted(std::string_view name);
inline const char* commandName(Command cmd) { return commandInfo(cmd).name; }

inline ServoStatus ok(std::string message) { return {ServoError::kOk, std::move(message)}; }
inline ServoStatus fail(ServoError error, std::string message) {
  return {error, std::move(message)};
}
ServoStatus notConnected();
/// Commands that need one servo's answer cannot go to the broadcast id: every servo would answer
/// at once and the answers would collide on the bus.
std::optional<ServoStatus> rejectBroadcast(uint8_t id, Command cmd);
/// Whether an answer that passed the client's checks reports failure (result 0).
bool refused(const Packet& answer);

}  // namespace serial_robot_driver::devices::servo_bus::servo_text
