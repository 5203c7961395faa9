// libFuzzer target: the decoder of every frame family of the registered devices
// (registered_families.h, FrameFamily::decodes), on raw bytes and, for the families this file
// knows how to fix up, on bytes whose integrity fields were fixed so that malformed payloads get
// past the XOR / sum / CRC / tail and reach the field parsing. A new device's families are fuzzed
// as soon as it is registered.
//
// Input layout:
//   byte 0  family = byte % F (F registered families, in registration order), mode = (byte / F) %
//   3:
//           0 raw, 1 fix the checksum, 2 fix header/length/tail/checksum (fuzz_support::
//           decoderSelector). Built with SRD_FUZZ_FAMILY="name", the target fuzzes that family only
//           (one libFuzzer target per family: fuzz_base, fuzz_telemetry, ...), so coverage feedback
//           stays per decoder; byte 0 then only gives the mode.
//   byte 1  the probe's and decoder's argument, modulo 64 (the telemetry's servo count, so also
//           beyond the legal 57)
//   rest    the frame, passed to the decoder in an exact-size heap buffer (ASan sees over-reads)
//
// Aborts when a family's decoder refuses what its probe framed (the framer hands a decoder exactly
// what the probe framed), when a decoded frame does not re-encode to the same bytes
// (telemetry, servo response, sync write, ...), when decoded sizes contradict the input, or on any
// sanitizer report.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <optional>
#include <vector>

#include "registered_families.h"
#include "serial_robot_driver/devices/base/base_codec.h"
#include "serial_robot_driver/devices/body/body_codec.h"
#include "serial_robot_driver/devices/servo_bus/servo_bus_codec.h"
#include "serial_robot_driver/devices/servo_bus/servo_commands.h"
#include "serial_robot_driver/devices/servo_bus/servo_params.h"
#include "serial_robot_driver/protocol/byte_order.h"
#include "serial_robot_driver/protocol/wire_fields.h"

namespace {

namespace base = serial_robot_driver::devices::base;
namespace body = serial_robot_driver::devices::body;
namespace servo_bus = serial_robot_driver::devices::servo_bus;
namespace wire = serial_robot_driver::protocol::wire;
using serial_robot_driver::protocol::FrameFamily;
using serial_robot_driver::protocol::Probe;
using serial_robot_driver::protocol::writeLE16;

enum class Mode { kRaw, kFixChecksum, kFixEverything };
static_assert(fuzz_support::kDecoderModes == 3, "one mode per fix-up level");

void check(bool condition) {
  if (!condition) std::abort();
}

bool sameBytes(const std::vector<uint8_t>& encoded, const uint8_t* data, std::size_t size) {
  return encoded.size() == size && std::memcmp(encoded.data(), data, size) == 0;
}

// --- fix-ups (the codec's own checksum functions compute the value to write) ------------------

void fixBase(uint8_t* d, std::size_t n, Mode mode) {
  if (mode == Mode::kFixEverything && n >= base::kOverhead) {
    d[0] = base::kHeader0;
    d[1] = base::kHeader1;
    d[2] = static_cast<uint8_t>(n - base::kOverhead);
  }
  if (n >= 1) d[n - 1] = base::xorChecksum(d, n - 1);
}

void fixTelemetry(uint8_t* d, std::size_t n, Mode mode) {
  if (n < 3) return;
  if (mode == Mode::kFixEverything && n >= 5) {
    d[0] = body::kTelemetryHeader0;
    d[1] = body::kTelemetryHeader1;
    d[2] = static_cast<uint8_t>(n);
    d[n - 2] = body::kTelemetryTail0;
    d[n - 1] = body::kTelemetryTail1;
  }
  d[n - 3] = body::telemetrySum(d, n);
}

void fixServo(uint8_t* d, std::size_t n, Mode mode, uint8_t header0, uint8_t header1) {
  if (mode == Mode::kFixEverything && n >= servo_bus::kOverhead) {
    d[0] = header0;
    d[1] = header1;
    d[3] = static_cast<uint8_t>(n - servo_bus::kOverhead);
  }
  if (n >= 1) d[n - 1] = servo_bus::byteSum(d, n - 1);
}

void fixSyncWrite(uint8_t* d, std::size_t n, Mode mode) {
  // header, id, LEN, then the command fields LEN counts first
  constexpr auto kCommand = wire::listOf(body::kSyncWriteCommandFields);
  constexpr std::size_t kHeaderSize = body::kSyncWriteHeader.size();
  if (mode == Mode::kFixEverything &&
      n >= body::kSyncWritePrefix + kCommand.size() + body::kCrcSize) {
    std::memcpy(d, body::kSyncWriteHeader.data(), kHeaderSize);
    d[kHeaderSize] = body::kBroadcastId;
    writeLE16(d + kHeaderSize + 1, static_cast<uint16_t>(n - body::kSyncWritePrefix));
    wire::encodeFields(kCommand, body::SyncWriteCommand{}, d + body::kSyncWritePrefix);
  }
  if (n >= body::kCrcSize) {
    writeLE16(d + n - body::kCrcSize, body::dynamixelCrc(d, n - body::kCrcSize));
  }
}

// --- decoders --------------------------------------------------------------------------------

void runBase(const uint8_t* d, std::size_t n) {
  const auto frame = base::decodeFrame(d, n);
  if (!frame.ok()) return;
  check(frame->param_count + 1u == d[2] && n == base::frameSize(d[2]));
  const auto reply = base::interpretReply(*frame);
  if (reply.ok() && reply->kind == base::Reply::Kind::kBattery) {
    check(reply->battery_percent <= 100);
  }
  (void)base::interpretWheelSpeed(*frame);
}

void runTelemetry(const uint8_t* d, std::size_t n, std::size_t servo_count) {
  const auto telemetry = body::decodeTelemetry(d, n, servo_count);
  if (!telemetry.ok()) return;
  check(telemetry->servo_count == servo_count);
  check(sameBytes(body::encodeTelemetry(*telemetry), d, n));
}

void runServoParams(const servo_bus::Packet& packet) {
  const auto cmd = static_cast<servo_bus::Command>(packet.cmd);
  if (cmd == servo_bus::Command::kReadData) {
    const auto data = servo_bus::decodeDataContent(packet);
    const servo_bus::ParamInfo* param =
        data.ok() ? servo_bus::findParamById(data->data_id) : nullptr;
    if (param != nullptr) (void)servo_bus::readValue(*param, data->value.data(), data->value_size);
  }
  if (cmd == servo_bus::Command::kReadBatchData) {
    const auto block = servo_bus::decodeUserBlock(packet);
    if (!block.ok()) return;
    // The user parameters cover every byte of the block: unpacked and packed again, it is the same.
    const auto values = servo_bus::unpackUserBlock(*block);
    const auto value_of = [&](const servo_bus::ParamInfo& param) {
      for (const auto& [unpacked, value] : values) {
        if (unpacked == &param) return value;
      }
      std::abort();
    };
    check(servo_bus::packUserBlock(value_of) == *block);
  }
}

void runServoResponse(const uint8_t* d, std::size_t n) {
  const auto packet = servo_bus::decodeResponse(d, n);
  if (!packet.ok()) return;
  const std::vector<uint8_t> content(packet->content.begin(),
                                     packet->content.begin() + packet->content_size);
  check(sameBytes(servo_bus::encodeResponse(static_cast<servo_bus::Command>(packet->cmd), content),
                  d, n));
  runServoParams(*packet);
  // The typed answers of the command table: an answer of the size its row says decodes and
  // re-encodes to the same CONTENT.
  const auto cmd = static_cast<servo_bus::Command>(packet->cmd);
  const servo_bus::CommandInfo& info = servo_bus::commandInfo(cmd);
  if (!info.answer.fits(packet->content_size)) return;
  if (info.result_index != servo_bus::kNoResult) check(info.result_index < packet->content_size);
  if (cmd == servo_bus::Command::kReadAngle) {
    const auto angle = servo_bus::decodeAngleAnswer(*packet);
    check(angle.ok() && servo_bus::angleAnswerContent(*angle) == content);
  }
  if (cmd == servo_bus::Command::kReadMultiTurnAngle) {
    const auto angle = servo_bus::decodeMultiTurnAngle(*packet);
    check(angle.ok() && servo_bus::multiTurnAngleContent(*angle) == content);
  }
  if (cmd == servo_bus::Command::kPing)
    check(servo_bus::pingAnswerContent(packet->id()) == content);
  // The answers that are an id and a result byte re-encode when that byte is 0 or 1.
  if (info.result_index != servo_bus::kNoResult && cmd != servo_bus::Command::kWriteData &&
      content[info.result_index] <= 1) {
    const bool ok = content[info.result_index] == 1;
    check(servo_bus::resultAnswerContent(packet->id(), ok) == content);
  }
  if (cmd == servo_bus::Command::kReadData) check(servo_bus::decodeDataContent(*packet).ok());
  if (cmd == servo_bus::Command::kReadBatchData) {
    const auto block = servo_bus::decodeUserBlock(*packet);
    check(block.ok() && servo_bus::userBlockAnswerContent(packet->id(), *block) == content);
  }
}

void runServoRequest(const uint8_t* d, std::size_t n) {
  const auto packet = servo_bus::decodeRequest(d, n);
  if (!packet.ok()) return;
  check(packet->content_size + servo_bus::kOverhead == n);
  check(packet->cmd >= servo_bus::kMinCommand && packet->cmd <= servo_bus::kMaxCommand);
  // The typed requests of the command table (what the simulator reads): a request of the size
  // its row says decodes, and the moves and SPIN re-encode to the same bytes.
  const auto cmd = static_cast<servo_bus::Command>(packet->cmd);
  if (!servo_bus::commandInfo(cmd).request.fits(packet->content_size)) return;
  if (servo_bus::isMove(cmd)) {
    const auto move = servo_bus::decodeMove(*packet);
    check(move.ok() && sameBytes(servo_bus::encodeMove(*move), d, n));
  }
  if (cmd == servo_bus::Command::kReadData || cmd == servo_bus::Command::kWriteData) {
    const auto data = servo_bus::decodeDataContent(*packet);
    check(data.ok());
    const servo_bus::ParamInfo* param = servo_bus::findParamById(data->data_id);
    const auto value = param != nullptr
                           ? servo_bus::readValue(*param, data->value.data(), data->value_size)
                           : std::nullopt;
    if (cmd == servo_bus::Command::kWriteData && value) {
      check(sameBytes(servo_bus::encodeWriteData(data->id, *param, *value), d, n));
    }
  }
  if (cmd == servo_bus::Command::kDamping) {
    const auto power = servo_bus::decodeDamping(*packet);
    check(power.ok() && sameBytes(servo_bus::encodeDamping(packet->id(), *power), d, n));
  }
  if (cmd == servo_bus::Command::kWriteBatchData) {
    const auto block = servo_bus::decodeUserBlock(*packet);
    check(block.ok() && sameBytes(servo_bus::encodeWriteBatchData(packet->id(), *block), d, n));
  }
  if (cmd == servo_bus::Command::kSpin) {
    const auto spin = servo_bus::decodeSpin(*packet);
    check(spin.ok());
    // Bits 6..2 of the method byte are not part of SPIN: only the frames without them re-encode.
    if ((packet->content[1] & 0x7C) == 0) check(sameBytes(servo_bus::encodeSpin(*spin), d, n));
  }
}

void runSyncWrite(const uint8_t* d, std::size_t n) {
  const auto targets = body::decodeSyncWrite(d, n);
  if (!targets.ok()) return;
  check(targets->size() <= body::kMaxSyncWriteServos);
  check(sameBytes(body::encodeSyncWrite(*targets), d, n));
}

void fixServoResponse(uint8_t* d, std::size_t n, Mode mode) {
  fixServo(d, n, mode, servo_bus::kResponseHeader0, servo_bus::kResponseHeader1);
}

void fixServoRequest(uint8_t* d, std::size_t n, Mode mode) {
  fixServo(d, n, mode, servo_bus::kRequestHeader0, servo_bus::kRequestHeader1);
}

// --- what every family gets, and what some get beyond it -----------------------------------------

/// The family's probe and decoder agree: what the probe frames (within the bytes it was given) the
/// decoder takes. Not the other way round: a decoder may take a frame the probe passes over (the
/// sync write's decoder reads any Dynamixel frame; the probe finds only the driver's own).
void runFamily(const FrameFamily& family, const uint8_t* d, std::size_t n, std::size_t expected) {
  const Probe probe = family.probe(d, n, expected);
  const bool decodes = family.decodes(d, n, expected);
  if (probe.status != Probe::Status::kFrame) return;
  check(probe.size > 0 && probe.size <= n);
  if (probe.size == n) check(decodes);
}

/// A family's fix-ups and deeper checks (re-encoding, typed contents), by its name. A family with
/// none is fuzzed raw with runFamily's checks only.
struct KnownFamily {
  const char* name;
  void (*fix)(uint8_t* d, std::size_t n, Mode mode);
  void (*run)(const uint8_t* d, std::size_t n, std::size_t expected);
};

const KnownFamily kKnownFamilies[] = {
    {"base", fixBase, [](const uint8_t* d, std::size_t n, std::size_t) { runBase(d, n); }},
    {"telemetry", fixTelemetry, runTelemetry},
    {"sync_write", fixSyncWrite,
     [](const uint8_t* d, std::size_t n, std::size_t) { runSyncWrite(d, n); }},
    {"servo_response", fixServoResponse,
     [](const uint8_t* d, std::size_t n, std::size_t) { runServoResponse(d, n); }},
    {"servo_request", fixServoRequest,
     [](const uint8_t* d, std::size_t n, std::size_t) { runServoRequest(d, n); }},
};

const KnownFamily* knownFamily(const FrameFamily& family) {
  for (const KnownFamily& known : kKnownFamilies) {
    if (std::strcmp(known.name, family.name) == 0) return &known;
  }
  return nullptr;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* input, std::size_t input_size) {
  constexpr std::size_t kPrefix = 2;
  if (input_size < kPrefix) return 0;
  const auto& families = fuzz_support::registeredFamilies();
#ifdef SRD_FUZZ_FAMILY
  static const std::size_t kOnly = fuzz_support::familyIndex(SRD_FUZZ_FAMILY);
  const FrameFamily& family = families[kOnly];
#else
  const FrameFamily& family = families[input[0] % families.size()];
#endif
  const auto mode = static_cast<Mode>((input[0] / families.size()) % fuzz_support::kDecoderModes);
  const std::size_t expected = input[1] % 64;
  const std::size_t n = input_size - kPrefix;
  std::unique_ptr<uint8_t[]> frame(new uint8_t[n]);  // n == 0: any access is an overflow
  if (n > 0) std::memcpy(frame.get(), input + kPrefix, n);
  uint8_t* d = frame.get();

  const KnownFamily* known = knownFamily(family);
  if (known != nullptr && mode != Mode::kRaw) known->fix(d, n, mode);
  runFamily(family, d, n, expected);
  if (known != nullptr) known->run(d, n, expected);
  return 0;
}
