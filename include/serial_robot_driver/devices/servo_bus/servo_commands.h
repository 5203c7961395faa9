// The bus servo commands (docs/protocols.md, section 3): each one's name, the size of its request
// and answer CONTENT and when a servo answers it. The sizes and result bytes are derived from the
// field lists the codec encodes with (src/devices/servo_bus/servo_layouts.h). The client, the
// simulator and the fuzzers read this table; a new command is its field lists, one row here and its
// encode/decode pair in servo_bus_codec.h.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

#include "serial_robot_driver/devices/servo_bus/servo_bus_codec.h"

namespace serial_robot_driver::devices::servo_bus {

/// When a servo answers a command. Nobody answers the broadcast id.
enum class Answers : uint8_t {
  kAlways,              ///< every request addressed to one servo
  kWhenResponseSwitch,  ///< motions: only while the servo's response_switch is 1 (on completion)
};

/// A CONTENT size: exactly `min` bytes, or any size in min..max (a parameter value of 1..4 bytes).
struct ContentSize {
  uint8_t min = 0;
  uint8_t max = 0;
  constexpr bool fits(std::size_t size) const { return size >= min && size <= max; }
  constexpr bool fixed() const { return min == max; }
};

struct CommandInfo {
  Command cmd;
  const char* name;     ///< as messages name it
  ContentSize request;  ///< id first
  ContentSize answer;   ///< id first
  Answers answers;
  /// Where the answer's result byte (1 ok, 0 failed) is, for the commands that have one.
  int result_index;
};

constexpr int kNoResult = -1;

/// One row per command, in CMD order (kMinCommand .. kMaxCommand).
const std::array<CommandInfo, kMaxCommand>& commandTable();
/// A known command's row in commandTable(), and in every table kept in its order (the
/// simulator's handlers).
constexpr std::size_t commandRow(Command cmd) {
  return static_cast<std::size_t>(cmd) - kMinCommand;
}
/// The row of a known command.
const CommandInfo& commandInfo(Command cmd);

}  // namespace serial_robot_driver::devices::servo_bus
