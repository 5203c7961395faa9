// UART bus servo codec: golden vectors from docs/protocols.md, section 3, written out by hand.
#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "serial_robot_driver/devices/servo_bus/servo_bus_codec.h"
#include "serial_robot_driver/protocol/byte_order.h"
#include "support/golden_frames.h"
#include "support/probe_expectations.h"

namespace serial_robot_driver::devices::servo_bus {
namespace {

using Bytes = std::vector<uint8_t>;

const ParamInfo& param(const char* name) {
  const ParamInfo* info = findParam(name);
  EXPECT_NE(info, nullptr) << name;
  return *info;
}

const std::array<uint8_t, kUserBlockSize> kCountingBlock = {
    0x01, 0x02, 0x03, 0x04, 0x05, 0x06, 0x07, 0x08, 0x09, 0x0A, 0x0B, 0x0C, 0x0D, 0x0E, 0x0F, 0x10,
    0x11, 0x12, 0x13, 0x14, 0x15, 0x16, 0x17, 0x18, 0x19, 0x1A, 0x1B, 0x1C, 0x1D, 0x1E, 0x1F, 0x20};

struct RequestCase {
  std::string name;
  std::function<Bytes()> encode;
  Bytes expected;
  uint8_t cmd;
};

// All request vectors of docs/protocols.md, then vectors for the other commands, computed by hand
// from the format rules (SUM = sum of every preceding byte mod 256; 12 + 4C = 5E).
// clang-format off
const RequestCase kRequests[] = {
    {"PingId3", [] { return encodePing(3); }, {0x12, 0x4C, 0x01, 0x01, 0x03, 0x63}, 1},
    {"RotateId2To90DegIn500ms", [] { return encodeRotate(2, 900, 500, 0); },
     {0x12, 0x4C, 0x08, 0x07, 0x02, 0x84, 0x03, 0xF4, 0x01, 0x00, 0x00, 0xEB}, 8},
    {"ReadAngleId0", [] { return encodeReadAngle(0); }, {0x12, 0x4C, 0x0A, 0x01, 0x00, 0x69}, 10},
    {"SpinId0CcwContinuous", [] { return encodeSpin(0, false, SpinMode::kContinuous, 100, 0); },
     {0x12, 0x4C, 0x07, 0x06, 0x00, 0x01, 0x64, 0x00, 0x00, 0x00, 0xD0}, 7},
    {"SpinId0Stop", [] { return encodeSpin(0, false, SpinMode::kStop, 100, 0); },
     {0x12, 0x4C, 0x07, 0x06, 0x00, 0x00, 0x64, 0x00, 0x00, 0x00, 0xCF}, 7},
    {"SpinId0Cw5Turns", [] { return encodeSpin(0, true, SpinMode::kTurns, 100, 5); },
     {0x12, 0x4C, 0x07, 0x06, 0x00, 0x82, 0x64, 0x00, 0x05, 0x00, 0x56}, 7},
    {"SpinId0Cw1000ms", [] { return encodeSpin(0, true, SpinMode::kDurationMs, 100, 1000); },
     {0x12, 0x4C, 0x07, 0x06, 0x00, 0x83, 0x64, 0x00, 0xE8, 0x03, 0x3D}, 7},
    {"DampingId0500mW", [] { return encodeDamping(0, 500); },
     {0x12, 0x4C, 0x09, 0x03, 0x00, 0xF4, 0x01, 0x5F}, 9},
    // 5E + 02 + 01 + 07 = 68
    {"ResetUserDataId7", [] { return encodeResetUserData(7); },
     {0x12, 0x4C, 0x02, 0x01, 0x07, 0x68}, 2},
    // voltage is data_id 1. 5E + 03 + 02 + 01 + 01 = 65
    {"ReadDataId1Voltage", [] { return encodeReadData(1, 1); },
     {0x12, 0x4C, 0x03, 0x02, 0x01, 0x01, 0x65}, 3},
    // u8: response_switch (33 = 0x21) := 1. 5E + 04 + 03 + 05 + 21 + 01 = 8C
    {"WriteDataU8", [] { return encodeWriteData(5, param("response_switch"), 1); },
     {0x12, 0x4C, 0x04, 0x03, 0x05, 0x21, 0x01, 0x8C}, 4},
    // u16: soft_start_time (50 = 0x32) := 1000 = 0x03E8 -> E8 03.
    // 5E + 04 + 04 + 01 + 32 + E8 + 03 = 0x184 -> 84
    {"WriteDataU16", [] { return encodeWriteData(1, param("soft_start_time"), 1000); },
     {0x12, 0x4C, 0x04, 0x04, 0x01, 0x32, 0xE8, 0x03, 0x84}, 4},
    // i16: angle_limit_low (52 = 0x34) := -900 = 0x10000 - 900 = 0xFC7C -> 7C FC.
    // 5E + 04 + 04 + 00 + 34 + 7C + FC = 0x212 -> 12
    {"WriteDataI16", [] { return encodeWriteData(0, param("angle_limit_low"), -900); },
     {0x12, 0x4C, 0x04, 0x04, 0x00, 0x34, 0x7C, 0xFC, 0x12}, 4},
    // 5E + 05 + 01 + 00 = 64
    {"ReadBatchDataId0", [] { return encodeReadBatchData(0); },
     {0x12, 0x4C, 0x05, 0x01, 0x00, 0x64}, 5},
    // N = 33 = 0x21, block bytes 01..20 (so their order shows).
    // 5E + 06 + 21 + 01 + (1 + 2 + ... + 32 = 528 = 0x210) = 0x296 -> 96
    {"WriteBatchDataId1", [] { return encodeWriteBatchData(1, kCountingBlock); },
     {0x12, 0x4C, 0x06, 0x21, 0x01,
      0x01, 0x02, 0x03, 0x04, 0x05, 0x06, 0x07, 0x08,
      0x09, 0x0A, 0x0B, 0x0C, 0x0D, 0x0E, 0x0F, 0x10,
      0x11, 0x12, 0x13, 0x14, 0x15, 0x16, 0x17, 0x18,
      0x19, 0x1A, 0x1B, 0x1C, 0x1D, 0x1E, 0x1F, 0x20,
      0x96},
     6},
    // Negative angle: -900 -> 7C FC; interval 0, power 1000 (E8 03).
    // 5E + 08 + 07 + 01 + 7C + FC + E8 + 03 = 0x2D1 -> D1
    {"RotateId1ToMinus90Deg", [] { return encodeRotate(1, -900, 0, 1000); },
     {0x12, 0x4C, 0x08, 0x07, 0x01, 0x7C, 0xFC, 0x00, 0x00, 0xE8, 0x03, 0xD1}, 8},
    // The newer motion set (CMD 11..16); the bytes and their sums are in golden_frames.h.
    {"MoveByIntervalId1To90", [] { return encodeMoveByInterval(1, 900, 1000, {100, 100, 0}); },
     golden::servo::kMoveByInterval1To90, 11},
    {"MoveByVelocityId1ToMinus90",
     [] { return encodeMoveByVelocity(1, -900, 3600, {100, 100, 0}); },
     golden::servo::kMoveByVelocity1ToMinus90, 12},
    {"MultiTurnMoveId1To720", [] { return encodeMultiTurnMove(1, 7200, 2000, 0); },
     golden::servo::kMultiTurnMove1To720, 13},
    {"MultiTurnMoveByIntervalId1ToMinus360",
     [] { return encodeMultiTurnMoveByInterval(1, -3600, 1000, {200, 200, 0}); },
     golden::servo::kMultiTurnMoveByInterval1ToMinus360, 14},
    {"MultiTurnMoveByVelocityId1To3600",
     [] { return encodeMultiTurnMoveByVelocity(1, 36000, 3600, {100, 100, 0}); },
     golden::servo::kMultiTurnMoveByVelocity1To3600, 15},
    {"ReadMultiTurnAngleId1", [] { return encodeReadMultiTurnAngle(1); },
     golden::servo::kReadMultiTurn1, 16},
    // Power is the last field: CMD 11 id 2 -> 0 deg, 500 ms (F4 01), ramps 20 (14), 1000 mW (E8 03).
    // 5E+0B+0B+02+F4+01+14+14+E8+03 = 0x27E -> 7E
    {"MoveByIntervalPowerLast", [] { return encodeMoveByInterval(2, 0, 500, {20, 20, 1000}); },
     {0x12, 0x4C, 0x0B, 0x0B, 0x02, 0x00, 0x00, 0xF4, 0x01, 0x14, 0x00, 0x14, 0x00, 0xE8, 0x03,
      0x7E}, 11},
    // CMD 13 power: id 0 -> -0.1 deg (FF FF FF FF), 0 ms, 500 mW (F4 01).
    // 5E+0D+0B+00+FF*4+F4+01 = 0x567 -> 67
    {"MultiTurnMovePowerLast", [] { return encodeMultiTurnMove(0, -1, 0, 500); },
     {0x12, 0x4C, 0x0D, 0x0B, 0x00, 0xFF, 0xFF, 0xFF, 0xFF, 0x00, 0x00, 0x00, 0x00, 0xF4, 0x01,
      0x67}, 13},
};
// clang-format on

class ServoBusCodecRequest : public ::testing::TestWithParam<RequestCase> {};

TEST_P(ServoBusCodecRequest, EncoderReproducesGoldenBytes) {
  EXPECT_EQ(GetParam().encode(), GetParam().expected);
}

TEST_P(ServoBusCodecRequest, DecoderReadsGoldenBytes) {
  const RequestCase& c = GetParam();
  const protocol::Decoded<Packet> packet = decodeRequest(c.expected.data(), c.expected.size());
  ASSERT_TRUE(packet.ok()) << protocol::toString(packet.error());
  EXPECT_EQ(packet->cmd, c.cmd);
  ASSERT_EQ(packet->content_size, c.expected[3]);
  EXPECT_EQ(Bytes(packet->content.begin(), packet->content.begin() + packet->content_size),
            Bytes(c.expected.begin() + 4, c.expected.end() - 1));
  EXPECT_EQ(packet->id(), c.expected[4]);
}

TEST_P(ServoBusCodecRequest, RequestIsNotAResponse) {
  const Bytes& bytes = GetParam().expected;
  const protocol::Decoded<Packet> packet = decodeResponse(bytes.data(), bytes.size());
  ASSERT_FALSE(packet.ok());
  EXPECT_EQ(packet.error(), protocol::DecodeError::kBadHeader);
}

INSTANTIATE_TEST_SUITE_P(ServoBusCodecGolden, ServoBusCodecRequest, ::testing::ValuesIn(kRequests),
                         [](const auto& info) { return info.param.name; });

struct ResponseCase {
  std::string name;
  Command cmd;
  Bytes content;
  Bytes expected;
};

// clang-format off
const ResponseCase kResponses[] = {
    // The vendor text prints the checksum as 0x38; 05+1C+01+01+03 = 38 decimal = 0x26.
    {"PingReplyId3", Command::kPing, {0x03}, {0x05, 0x1C, 0x01, 0x01, 0x03, 0x26}},
    // 90.2 deg = 902 = 0x0386 -> 86 03
    {"ReadAngleReplyId0", Command::kReadAngle, {0x00, 0x86, 0x03},
     {0x05, 0x1C, 0x0A, 0x03, 0x00, 0x86, 0x03, 0xB7}},
    {"ReadMultiTurnReply720", Command::kReadMultiTurnAngle,
     {0x01, 0x20, 0x1C, 0x00, 0x00, 0x02, 0x00}, golden::servo::kReadMultiTurn1Reply720},
};
// clang-format on

class ServoBusCodecResponse : public ::testing::TestWithParam<ResponseCase> {};

TEST_P(ServoBusCodecResponse, EncoderReproducesGoldenBytes) {
  EXPECT_EQ(encodeResponse(GetParam().cmd, GetParam().content), GetParam().expected);
}

TEST_P(ServoBusCodecResponse, DecoderReadsGoldenBytes) {
  const ResponseCase& c = GetParam();
  const protocol::Decoded<Packet> packet = decodeResponse(c.expected.data(), c.expected.size());
  ASSERT_TRUE(packet.ok()) << protocol::toString(packet.error());
  EXPECT_EQ(packet->cmd, static_cast<uint8_t>(c.cmd));
  EXPECT_EQ(Bytes(packet->content.begin(), packet->content.begin() + packet->content_size),
            c.content);
}

INSTANTIATE_TEST_SUITE_P(ServoBusCodecGolden, ServoBusCodecResponse,
                         ::testing::ValuesIn(kResponses),
                         [](const auto& info) { return info.param.name; });

TEST(ServoBusCodec, PingReplyVendorChecksumErratumIsRejected) {
  const Bytes vendor_text = {0x05, 0x1C, 0x01, 0x01, 0x03, 0x38};
  const protocol::Decoded<Packet> packet = decodeResponse(vendor_text.data(), vendor_text.size());
  ASSERT_FALSE(packet.ok());
  EXPECT_EQ(packet.error(), protocol::DecodeError::kBadChecksum);
}

TEST(ServoBusCodec, ReadAngleReplyIs90Point2Degrees) {
  const Bytes reply = {0x05, 0x1C, 0x0A, 0x03, 0x00, 0x86, 0x03, 0xB7};
  const protocol::Decoded<Packet> packet = decodeResponse(reply.data(), reply.size());
  ASSERT_TRUE(packet.ok());
  EXPECT_EQ(packet->id(), 0);
  EXPECT_EQ(protocol::readLE16Signed(&packet->content[1]), 902);
}

TEST(ServoBusCodec, MultiTurnAngleAnswerIsDecoded) {
  const Bytes& reply = golden::servo::kReadMultiTurn1Reply720;
  const protocol::Decoded<Packet> packet = decodeResponse(reply.data(), reply.size());
  ASSERT_TRUE(packet.ok());
  const protocol::Decoded<MultiTurnAngle> angle =
      decodeMultiTurnAngle(packet->content.data(), packet->content_size);
  ASSERT_TRUE(angle.ok());
  EXPECT_EQ(angle->id, 1);
  EXPECT_EQ(angle->angle_decidegrees, 7200);
  EXPECT_EQ(angle->turns, 2);
}

TEST(ServoBusCodec, NegativeMultiTurnAngleAndTurnsAreSigned) {
  const Bytes& reply = golden::servo::kReadMultiTurn1ReplyMinus1234p5;
  const protocol::Decoded<Packet> packet = decodeResponse(reply.data(), reply.size());
  ASSERT_TRUE(packet.ok());
  const protocol::Decoded<MultiTurnAngle> angle =
      decodeMultiTurnAngle(packet->content.data(), packet->content_size);
  ASSERT_TRUE(angle.ok());
  EXPECT_EQ(angle->angle_decidegrees, -12345);
  EXPECT_EQ(angle->turns, -3);
  EXPECT_EQ(multiTurnAngleContent(*angle), Bytes(reply.begin() + 4, reply.end() - 1));
}

TEST(ServoBusCodec, MultiTurnAngleAnswerOfWrongSizeIsRejected) {
  const Bytes& reply = golden::servo::kReadMultiTurn1Reply720;
  const uint8_t* content = reply.data() + 4;
  for (std::size_t size : {std::size_t{0}, std::size_t{3}, std::size_t{6}, std::size_t{8}}) {
    const protocol::Decoded<MultiTurnAngle> angle = decodeMultiTurnAngle(content, size);
    ASSERT_FALSE(angle.ok()) << size;
    EXPECT_EQ(angle.error(), protocol::DecodeError::kBadLength);
  }
}

TEST(ServoBusCodec, SpinMethodByte) {
  EXPECT_EQ(spinMethod(false, SpinMode::kStop), 0x00);
  EXPECT_EQ(spinMethod(false, SpinMode::kContinuous), 0x01);
  EXPECT_EQ(spinMethod(true, SpinMode::kTurns), 0x82);
  EXPECT_EQ(spinMethod(true, SpinMode::kDurationMs), 0x83);
}

TEST(ServoBusCodec, ResponseLongerThanMaxContentIsNotBuilt) {
  EXPECT_TRUE(encodeResponse(Command::kReadBatchData, Bytes(kMaxContent + 1)).empty());
  EXPECT_EQ(encodeResponse(Command::kReadBatchData, Bytes(kMaxContent)).size(), kMaxFrameSize);
}

struct MalformedCase {
  std::string name;
  Bytes packet;
  protocol::DecodeError error;
};

// clang-format off
const MalformedCase kMalformedResponses[] = {
    {"BadChecksum", {0x05, 0x1C, 0x01, 0x01, 0x03, 0x27}, protocol::DecodeError::kBadChecksum},
    {"BadHeader", {0x05, 0x1D, 0x01, 0x01, 0x03, 0x26}, protocol::DecodeError::kBadHeader},
    {"Truncated", {0x05, 0x1C, 0x0A, 0x03, 0x00, 0x86}, protocol::DecodeError::kTooShort},
    {"OnlyHeader", {0x05, 0x1C}, protocol::DecodeError::kTooShort},
    {"Empty", {}, protocol::DecodeError::kTooShort},
    // N = 0 says 5 bytes, 6 were given.
    {"LenZeroInconsistent", {0x05, 0x1C, 0x01, 0x00, 0x03, 0x26}, protocol::DecodeError::kBadLength},
    // N = 1 says 6 bytes, 7 were given.
    {"LenOneInconsistent", {0x05, 0x1C, 0x0A, 0x01, 0x00, 0x86, 0x03, 0xB7},
     protocol::DecodeError::kBadLength},
    // N = 34 is above the longest content (id + 32-byte block).
    {"LenAboveMax", {0x05, 0x1C, 0x05, 0x22, 0x00, 0x00}, protocol::DecodeError::kBadLength},
    {"Len255", {0x05, 0x1C, 0x05, 0xFF, 0x00, 0x00}, protocol::DecodeError::kBadLength},
    // CMD 0 and 17 with correct sums (05+1C+00+01+03 = 25, 05+1C+11+01+03 = 36).
    {"CmdZero", {0x05, 0x1C, 0x00, 0x01, 0x03, 0x25}, protocol::DecodeError::kUnknownCommand},
    {"CmdSeventeen", {0x05, 0x1C, 0x11, 0x01, 0x03, 0x36}, protocol::DecodeError::kUnknownCommand},
};
// clang-format on

class ServoBusCodecMalformed : public ::testing::TestWithParam<MalformedCase> {};

TEST_P(ServoBusCodecMalformed, Rejected) {
  const MalformedCase& c = GetParam();
  const protocol::Decoded<Packet> packet = decodeResponse(c.packet.data(), c.packet.size());
  ASSERT_FALSE(packet.ok());
  EXPECT_EQ(packet.error(), c.error) << protocol::toString(packet.error());
}

INSTANTIATE_TEST_SUITE_P(ServoBusCodecErrors, ServoBusCodecMalformed,
                         ::testing::ValuesIn(kMalformedResponses),
                         [](const auto& info) { return info.param.name; });

TEST(ServoBusCodec, RequestDecoderChecksSum) {
  const Bytes ping = {0x12, 0x4C, 0x01, 0x01, 0x03, 0x64};
  const protocol::Decoded<Packet> packet = decodeRequest(ping.data(), ping.size());
  ASSERT_FALSE(packet.ok());
  EXPECT_EQ(packet.error(), protocol::DecodeError::kBadChecksum);
}

// --- probe (what the stream framer asks) -------------------------------------------------------

using test_support::expectProbeFindsFrame;
using test_support::expectProbeRejects;

// PING id 3: 12+4C+01+01+03 = 63; reply 05+1C+01+01+03 = 26.
const Bytes kProbePingRequest = {0x12, 0x4C, 0x01, 0x01, 0x03, 0x63};
const Bytes kProbePingResponse = {0x05, 0x1C, 0x01, 0x01, 0x03, 0x26};

TEST(ServoBusCodecProbe, FindsGoldenFramesAndNeedsMoreAtEveryTruncation) {
  expectProbeFindsFrame(probeRequest, kProbePingRequest);
  expectProbeFindsFrame(probeResponse, kProbePingResponse);
}

TEST(ServoBusCodecProbe, SaysWhyACandidateIsInvalid) {
  expectProbeRejects(probeResponse, {0x05, 0x1C, 0x01, 0x01, 0x03, 0x27},
                     protocol::DecodeError::kBadChecksum);
  expectProbeRejects(probeRequest, {0x12, 0x4C, 0x01, 0x01, 0x03, 0x64},
                     protocol::DecodeError::kBadChecksum);
  // N = 34 exceeds the longest content (id + 32 bytes).
  expectProbeRejects(probeResponse, {0x05, 0x1C, 0x05, 0x22}, protocol::DecodeError::kBadLength);
  // CMD 17 does not exist; it has its own reason, not a bad length.
  expectProbeRejects(probeRequest, {0x12, 0x4C, 0x11, 0x01},
                     protocol::DecodeError::kUnknownCommand);
  expectProbeRejects(probeResponse, {0x05, 0x1C, 0x00, 0x01},
                     protocol::DecodeError::kUnknownCommand);
  // The request header is not a response's, and the reverse.
  expectProbeRejects(probeResponse, kProbePingRequest, protocol::DecodeError::kBadHeader);
  expectProbeRejects(probeRequest, kProbePingResponse, protocol::DecodeError::kBadHeader);
}

}  // namespace
}  // namespace serial_robot_driver::devices::servo_bus
