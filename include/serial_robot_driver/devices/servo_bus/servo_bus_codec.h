// UART bus servo protocol (docs/protocols.md, section 3).
//
//   request  12 4C | CMD | N | CONTENT (N) | SUM
//   response 05 1C | CMD | N | CONTENT (N) | SUM
// SUM = sum of all preceding bytes mod 256. Each command's CONTENT is one field list in
// src/devices/servo_bus/servo_layouts.h; the functions below encode and decode with those lists.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "serial_robot_driver/devices/servo_bus/servo_params.h"
#include "serial_robot_driver/protocol/decode_result.h"
#include "serial_robot_driver/protocol/frame_family.h"

namespace serial_robot_driver::devices::servo_bus {

constexpr uint8_t kRequestHeader0 = 0x12;
constexpr uint8_t kRequestHeader1 = 0x4C;
constexpr uint8_t kResponseHeader0 = 0x05;
constexpr uint8_t kResponseHeader1 = 0x1C;
constexpr std::size_t kOverhead = 5;  ///< header (2), CMD, N, SUM
/// Longest CONTENT of any command, the user block with its id (servo_commands.cpp checks it).
constexpr uint8_t kMaxContent = 1 + kUserBlockSize;
constexpr std::size_t kMaxFrameSize = kMaxContent + kOverhead;
constexpr uint8_t kBroadcastId = 255;
constexpr uint8_t kMaxServoId = 254;

enum class Command : uint8_t {
  kPing = 1,
  kResetUserData = 2,
  kReadData = 3,
  kWriteData = 4,
  kReadBatchData = 5,
  kWriteBatchData = 6,
  kSpin = 7,
  kRotate = 8,
  kDamping = 9,
  kReadAngle = 10,
  // The newer firmware's motion set, as the vendor SDK packs it.
  kMoveByInterval = 11,
  kMoveByVelocity = 12,
  kMultiTurnMove = 13,
  kMultiTurnMoveByInterval = 14,
  kMultiTurnMoveByVelocity = 15,
  kReadMultiTurnAngle = 16,
};
constexpr uint8_t kMinCommand = 1;
constexpr uint8_t kMaxCommand = 16;
/// Whether a CMD byte names a command of this protocol.
constexpr bool isKnownCommand(uint8_t cmd) { return cmd >= kMinCommand && cmd <= kMaxCommand; }

uint8_t byteSum(const uint8_t* data, std::size_t size);

/// SPIN's mode (the method byte's low bits, servo_layouts.h).
enum class SpinMode : uint8_t { kStop = 0, kContinuous = 1, kTurns = 2, kDurationMs = 3 };
uint8_t spinMethod(bool clockwise, SpinMode mode);

std::vector<uint8_t> encodePing(uint8_t id);
std::vector<uint8_t> encodeResetUserData(uint8_t id);
std::vector<uint8_t> encodeReadData(uint8_t id, uint8_t data_id);
/// `value` must have passed checkWrite for `param`.
std::vector<uint8_t> encodeWriteData(uint8_t id, const ParamInfo& param, int64_t value);
std::vector<uint8_t> encodeReadBatchData(uint8_t id);
std::vector<uint8_t> encodeWriteBatchData(uint8_t id,
                                          const std::array<uint8_t, kUserBlockSize>& block);
std::vector<uint8_t> encodeSpin(uint8_t id, bool clockwise, SpinMode mode, uint16_t speed_dps,
                                uint16_t value);
std::vector<uint8_t> encodeRotate(uint8_t id, int16_t angle_decidegrees, uint16_t interval_ms,
                                  uint16_t power_mw);
std::vector<uint8_t> encodeDamping(uint8_t id, uint16_t power_mw);
std::vector<uint8_t> encodeReadAngle(uint8_t id);

/// Ramps and power of the CMD 11/12/14/15 moves.
struct MoveRamps {
  uint16_t accel_ms = 0;
  uint16_t decel_ms = 0;
  uint16_t power_mw = 0;  ///< 0: the servo's default limit
};
std::vector<uint8_t> encodeMoveByInterval(uint8_t id, int16_t angle_decidegrees,
                                          uint16_t interval_ms, const MoveRamps& ramps);
std::vector<uint8_t> encodeMoveByVelocity(uint8_t id, int16_t angle_decidegrees,
                                          uint16_t velocity_decidegrees_per_s,
                                          const MoveRamps& ramps);
std::vector<uint8_t> encodeMultiTurnMove(uint8_t id, int32_t angle_decidegrees,
                                         uint32_t interval_ms, uint16_t power_mw);
std::vector<uint8_t> encodeMultiTurnMoveByInterval(uint8_t id, int32_t angle_decidegrees,
                                                   uint32_t interval_ms, const MoveRamps& ramps);
std::vector<uint8_t> encodeMultiTurnMoveByVelocity(uint8_t id, int32_t angle_decidegrees,
                                                   uint16_t velocity_decidegrees_per_s,
                                                   const MoveRamps& ramps);
std::vector<uint8_t> encodeReadMultiTurnAngle(uint8_t id);

/// The content of a CMD 16 answer.
struct MultiTurnAngle {
  uint8_t id = 0;
  int32_t angle_decidegrees = 0;
  int16_t turns = 0;
};
/// Decodes the CONTENT of a CMD 16 answer (kBadLength unless exactly its layout's size).
protocol::Decoded<MultiTurnAngle> decodeMultiTurnAngle(const uint8_t* content, std::size_t size);
/// The CONTENT of a CMD 16 answer (simulator side).
std::vector<uint8_t> multiTurnAngleContent(const MultiTurnAngle& angle);

/// A request or response packet after header/length/sum checks.
struct Packet {
  uint8_t cmd = 0;
  uint8_t content_size = 0;
  std::array<uint8_t, kMaxContent> content{};
  uint8_t id() const { return content_size > 0 ? content[0] : 0; }
};

/// Probe for a complete response (05 1C) or request (12 4C): header, CMD (kUnknownCommand),
/// N (kBadLength), sum (kBadChecksum).
protocol::Probe probeResponse(const uint8_t* data, std::size_t available);
protocol::Probe probeRequest(const uint8_t* data, std::size_t available);
/// Responses (servo -> host): "servo_response".
extern const protocol::FrameFamily kResponseFrames;
/// Requests (host -> servo: the half-duplex echo, or what the simulated bus reads):
/// "servo_request".
extern const protocol::FrameFamily kRequestFrames;

/// Decodes one complete response (05 1C ...) or request (12 4C ..., for the simulator and for
/// recognising the half-duplex echo of our own request).
protocol::Decoded<Packet> decodeResponse(const uint8_t* data, std::size_t size);
protocol::Decoded<Packet> decodeRequest(const uint8_t* data, std::size_t size);

/// Builds a response packet (simulator side).
std::vector<uint8_t> encodeResponse(Command cmd, const std::vector<uint8_t>& content);

// --- Typed requests and answers: the simulator encodes answers and decodes requests with the
// same functions the client uses the other way round. Sizes and result bytes: servo_commands.h.

/// The answer of PING, and of the commands whose answer reports a result (simulator side; the
/// client finds the result byte through commandInfo(cmd).result_index).
std::vector<uint8_t> pingAnswerContent(uint8_t id);
std::vector<uint8_t> resultAnswerContent(uint8_t id, bool ok);
std::vector<uint8_t> writeDataAnswerContent(uint8_t id, uint8_t data_id, bool ok);

/// A READ_ANGLE answer.
struct AngleAnswer {
  uint8_t id = 0;
  int16_t angle_decidegrees = 0;
};
std::vector<uint8_t> angleAnswerContent(const AngleAnswer& answer);
protocol::Decoded<AngleAnswer> decodeAngleAnswer(const Packet& answer);
/// A CMD 16 answer packet.
protocol::Decoded<MultiTurnAngle> decodeMultiTurnAngle(const Packet& answer);
/// A READ_DATA answer: its fields, then the value as `param`'s type lays it out.
std::vector<uint8_t> readDataAnswerContent(uint8_t id, const ParamInfo& param, int64_t value);
protocol::Decoded<int64_t> decodeReadDataAnswer(const Packet& answer, const ParamInfo& param);

/// A READ_DATA / WRITE_DATA request or READ_DATA answer: the parameter's data_id and the value
/// bytes that follow it (none in a READ_DATA request), still in the parameter's type.
struct DataContent {
  uint8_t id = 0;
  uint8_t data_id = 0;
  std::array<uint8_t, largestTypeSize()> value{};
  std::size_t value_size = 0;
};
/// kBadLength when the content is shorter than its fields or the value longer than any type.
protocol::Decoded<DataContent> decodeDataContent(const Packet& packet);

/// A READ_BATCH_DATA answer (simulator side) and the user block of it or of a WRITE_BATCH_DATA
/// request (kBadLength unless the packet is that long).
std::vector<uint8_t> userBlockAnswerContent(uint8_t id,
                                            const std::array<uint8_t, kUserBlockSize>& block);
protocol::Decoded<std::array<uint8_t, kUserBlockSize>> decodeUserBlock(const Packet& packet);

/// Any of the motions CMD 8 (ROTATE) and 11..15, as its request carries it.
struct MoveCommand {
  Command cmd = Command::kRotate;
  uint8_t id = 0;
  int32_t angle_decidegrees = 0;
  uint32_t interval_ms = 0;                 ///< the by-interval moves (8, 11, 13, 14)
  uint16_t velocity_decidegrees_per_s = 0;  ///< the by-velocity moves (12, 15)
  MoveRamps ramps;                          ///< power_mw always; accel/decel for 11, 12, 14, 15
};
/// Whether `cmd` is one of the moves MoveCommand describes.
bool isMove(Command cmd);
bool isMultiTurn(Command cmd);
bool isByVelocity(Command cmd);
bool hasRamps(Command cmd);
/// The request of `move.cmd` (fields the command does not carry are ignored).
std::vector<uint8_t> encodeMove(const MoveCommand& move);
protocol::Decoded<MoveCommand> decodeMove(const Packet& request);

/// A SPIN request.
struct SpinCommand {
  uint8_t id = 0;
  bool clockwise = false;
  SpinMode mode = SpinMode::kStop;
  uint16_t speed_dps = 0;
  uint16_t value = 0;
};
std::vector<uint8_t> encodeSpin(const SpinCommand& spin);
protocol::Decoded<SpinCommand> decodeSpin(const Packet& request);

/// The power of a DAMPING request.
protocol::Decoded<uint16_t> decodeDamping(const Packet& request);

}  // namespace serial_robot_driver::devices::servo_bus
