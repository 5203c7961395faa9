// Servo controller board codec: golden vectors from docs/protocols.md, section 2, by hand.
#include <gtest/gtest.h>

#include <cstdint>
#include <string>
#include <vector>

#include "serial_robot_driver/devices/body/body_codec.h"
#include "support/body_telemetry_fixture.h"
#include "support/golden_frames.h"
#include "support/probe_expectations.h"
#include "support/test_helpers.h"

namespace serial_robot_driver::devices::body {
namespace {

using test_support::Bytes;
using test_support::withByte;

// --- sync write ----------------------------------------------------------------------------------

struct SyncWriteCase {
  std::string name;
  std::vector<ServoTarget> targets;
  Bytes expected;
};

// The CRCs of the docs/protocols.md vector come from the document; the others were checked
// against an independent bitwise CRC-16/BUYPASS, never against the code under test.
// clang-format off
const SyncWriteCase kSyncWrites[] = {
    {"Id2To2048Id3To1024",
     {{2, 2048}, {3, 1024}},
     {0xFF, 0xFF, 0xFD, 0x00, 0xFE, 0x0D, 0x00, 0x83, 0x74, 0x00, 0x02, 0x00,
      0x02, 0x00, 0x08, 0x03, 0x00, 0x04, 0x79, 0x68}},
    {"Id1To512",
     {{1, 512}},
     {0xFF, 0xFF, 0xFD, 0x00, 0xFE, 0x0A, 0x00, 0x83, 0x74, 0x00, 0x02, 0x00,
      0x01, 0x00, 0x02, 0x3A, 0x8E}},
    {"NoServos",
     {},
     {0xFF, 0xFF, 0xFD, 0x00, 0xFE, 0x07, 0x00, 0x83, 0x74, 0x00, 0x02, 0x00, 0x6D, 0x0F}},
};
// clang-format on

class BodyCodecSyncWrite : public ::testing::TestWithParam<SyncWriteCase> {};

TEST_P(BodyCodecSyncWrite, EncoderReproducesGoldenBytes) {
  EXPECT_EQ(encodeSyncWrite(GetParam().targets), GetParam().expected);
}

TEST_P(BodyCodecSyncWrite, DecoderReadsGoldenBytes) {
  const SyncWriteCase& c = GetParam();
  const auto targets = decodeSyncWrite(c.expected.data(), c.expected.size());
  ASSERT_TRUE(targets.ok()) << protocol::toString(targets.error());
  ASSERT_EQ(targets->size(), c.targets.size());
  for (std::size_t i = 0; i < c.targets.size(); ++i) {
    EXPECT_EQ((*targets)[i].id, c.targets[i].id);
    EXPECT_EQ((*targets)[i].position, c.targets[i].position);
  }
}

TEST_P(BodyCodecSyncWrite, CrcIsLittleEndianOverAllPrecedingBytes) {
  const Bytes& bytes = GetParam().expected;
  const uint16_t crc = dynamixelCrc(bytes.data(), bytes.size() - 2);
  EXPECT_EQ(crc & 0xFF, bytes[bytes.size() - 2]);
  EXPECT_EQ(crc >> 8, bytes[bytes.size() - 1]);
}

INSTANTIATE_TEST_SUITE_P(BodyCodecGolden, BodyCodecSyncWrite, ::testing::ValuesIn(kSyncWrites),
                         [](const auto& info) { return info.param.name; });

TEST(BodyCodec, DynamixelReferencePingCrc) {
  // Dynamixel 2.0 reference: PING to ID 1 ends in CRC 19 4E (0x4E19).
  const Bytes ping = {0xFF, 0xFF, 0xFD, 0x00, 0x01, 0x03, 0x00, 0x01, 0x19, 0x4E};
  EXPECT_EQ(dynamixelCrc(ping.data(), ping.size() - 2), 0x4E19);
}

TEST(BodyCodec, SyncWriteLenFormula) {
  EXPECT_EQ(syncWriteLen(0), 7u);
  EXPECT_EQ(syncWriteLen(2), 13u);
}

TEST(BodyCodec, SyncWriteWithTooManyServosIsNotBuilt) {
  EXPECT_TRUE(encodeSyncWrite(std::vector<ServoTarget>(kMaxSyncWriteServos + 1)).empty());
}

struct MalformedCase {
  std::string name;
  Bytes frame;
  protocol::DecodeError error;
};

// clang-format off
const MalformedCase kMalformedSyncWrites[] = {
    // The vendor's misprint "03 00 40" under the CRC of the correct "03 00 04".
    {"VendorErratumBytes",
     {0xFF, 0xFF, 0xFD, 0x00, 0xFE, 0x0D, 0x00, 0x83, 0x74, 0x00, 0x02, 0x00,
      0x02, 0x00, 0x08, 0x03, 0x00, 0x40, 0x79, 0x68},
     protocol::DecodeError::kBadChecksum},
    {"CrcBytesSwapped",
     {0xFF, 0xFF, 0xFD, 0x00, 0xFE, 0x0D, 0x00, 0x83, 0x74, 0x00, 0x02, 0x00,
      0x02, 0x00, 0x08, 0x03, 0x00, 0x04, 0x68, 0x79},
     protocol::DecodeError::kBadChecksum},
    {"BadHeader",
     {0xFF, 0xFF, 0xFD, 0x01, 0xFE, 0x0D, 0x00, 0x83, 0x74, 0x00, 0x02, 0x00,
      0x02, 0x00, 0x08, 0x03, 0x00, 0x04, 0x79, 0x68},
     protocol::DecodeError::kBadHeader},
    {"Truncated",
     {0xFF, 0xFF, 0xFD, 0x00, 0xFE, 0x0D, 0x00, 0x83, 0x74, 0x00, 0x02, 0x00, 0x02, 0x00},
     protocol::DecodeError::kTooShort},
    {"OnlyHeader", {0xFF, 0xFF, 0xFD, 0x00}, protocol::DecodeError::kTooShort},
    // LEN 14 is not 7 + 3N.
    {"LenNotSevenPlusThreeN",
     {0xFF, 0xFF, 0xFD, 0x00, 0xFE, 0x0E, 0x00, 0x83, 0x74, 0x00, 0x02, 0x00,
      0x02, 0x00, 0x08, 0x03, 0x00, 0x04, 0x79, 0x68},
     protocol::DecodeError::kBadLength},
    // LEN 10 (N = 1) but the bytes of N = 2.
    {"LenInconsistentWithSize",
     {0xFF, 0xFF, 0xFD, 0x00, 0xFE, 0x0A, 0x00, 0x83, 0x74, 0x00, 0x02, 0x00,
      0x02, 0x00, 0x08, 0x03, 0x00, 0x04, 0x79, 0x68},
     protocol::DecodeError::kBadLength},
    {"LenFFFF",
     {0xFF, 0xFF, 0xFD, 0x00, 0xFE, 0xFF, 0xFF, 0x83, 0x74, 0x00, 0x02, 0x00,
      0x02, 0x00, 0x08, 0x03, 0x00, 0x04, 0x79, 0x68},
     protocol::DecodeError::kBadLength},
    // A valid Dynamixel PING is not a sync write: LEN 3 is below 7.
    {"DynamixelPing", {0xFF, 0xFF, 0xFD, 0x00, 0x01, 0x03, 0x00, 0x01, 0x19, 0x4E},
     protocol::DecodeError::kBadLength},
    // Same layout addressed to ID 1 instead of broadcast, with its own valid CRC (0x42D2).
    {"NotBroadcast",
     {0xFF, 0xFF, 0xFD, 0x00, 0x01, 0x0A, 0x00, 0x83, 0x74, 0x00, 0x02, 0x00,
      0x01, 0x00, 0x02, 0xD2, 0x42},
     protocol::DecodeError::kUnexpectedContent},
};
// clang-format on

class BodyCodecMalformedSyncWrite : public ::testing::TestWithParam<MalformedCase> {};

TEST_P(BodyCodecMalformedSyncWrite, Rejected) {
  const MalformedCase& c = GetParam();
  const auto targets = decodeSyncWrite(c.frame.data(), c.frame.size());
  ASSERT_FALSE(targets.ok());
  EXPECT_EQ(targets.error(), c.error) << protocol::toString(targets.error());
}

INSTANTIATE_TEST_SUITE_P(BodyCodecErrors, BodyCodecMalformedSyncWrite,
                         ::testing::ValuesIn(kMalformedSyncWrites),
                         [](const auto& info) { return info.param.name; });

// --- telemetry -----------------------------------------------------------------------------------

using test_support::goldenBodyTelemetry;

// Section 2b golden frame, N = 2, no foot data, LEN 32 (test/support/golden_frames.h).
const Bytes& kGoldenTelemetry = golden::body::kTelemetryTwoServos;

// Hand-made frame WITH the foot block, N = 1, LEN = 40 + 4 = 44 = 0x2C.
// SUM = LEN 44 + servo (01+2C+FF+FE = 1+44+255+254) + imu (01+02+FF+FF = 513)
//     + foot (01+00+00+01+34+12+FF+FF+E8+03 = 817) = 44+554+513+817 = 1928 = 7*256 + 136 -> 0x88
// clang-format off
const Bytes kFootTelemetry = {
    0x12, 0x34, 0x2C,                                // header, LEN 44
    0x01, 0x2C, 0xFF, 0xFE,                          // servo 0: 300, speed -2
    0x01, 0x02, 0x00, 0x00, 0x00, 0x00,              // accel 258, 0, 0
    0x00, 0x00, 0x00, 0x00, 0x00, 0x00,              // gyro 0, 0, 0
    0x00, 0x00, 0x00, 0x00, 0xFF, 0xFF,              // angles 0, 0, -1
    0x01, 0x00, 0x00, 0x01, 0x34, 0x12, 0xFF, 0xFF,  // foot 1, 256, 0x1234, 65535 (little-endian)
    0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0xE8, 0x03,  // foot 0, 0, 0, 1000
    0x88, 0x1F, 0x2F};                               // SUM, tail
// clang-format on

Telemetry footTelemetry() {
  Telemetry t;
  t.servo_count = 1;
  t.servos[0] = {300, -2};
  t.imu = {258, 0, 0, 0, 0, 0, 0, 0, -1};
  t.has_foot = true;
  t.foot = {1, 256, 0x1234, 65535, 0, 0, 0, 1000};
  return t;
}

void expectSameTelemetry(const Telemetry& actual, const Telemetry& expected) {
  ASSERT_EQ(actual.servo_count, expected.servo_count);
  for (std::size_t i = 0; i < expected.servo_count; ++i) {
    EXPECT_EQ(actual.servos[i].position, expected.servos[i].position) << "servo " << i;
    EXPECT_EQ(actual.servos[i].speed, expected.servos[i].speed) << "servo " << i;
  }
  EXPECT_EQ(actual.imu, expected.imu);
  EXPECT_EQ(actual.has_foot, expected.has_foot);
  if (expected.has_foot) {
    EXPECT_EQ(actual.foot, expected.foot);
  }
}

struct TelemetryCase {
  std::string name;
  Bytes frame;
  Telemetry telemetry;
};

class BodyCodecTelemetry : public ::testing::TestWithParam<TelemetryCase> {};

TEST_P(BodyCodecTelemetry, DecoderReadsHandWrittenFrame) {
  const TelemetryCase& c = GetParam();
  const auto decoded = decodeTelemetry(c.frame.data(), c.frame.size(), c.telemetry.servo_count);
  ASSERT_TRUE(decoded.ok()) << protocol::toString(decoded.error());
  expectSameTelemetry(*decoded, c.telemetry);
}

TEST_P(BodyCodecTelemetry, EncoderReproducesHandWrittenFrame) {
  EXPECT_EQ(encodeTelemetry(GetParam().telemetry), GetParam().frame);
}

TEST_P(BodyCodecTelemetry, SumCoversLenAndContent) {
  const Bytes& frame = GetParam().frame;
  EXPECT_EQ(telemetrySum(frame.data(), frame.size()), frame[frame.size() - 3]);
}

INSTANTIATE_TEST_SUITE_P(
    BodyCodecGolden, BodyCodecTelemetry,
    ::testing::Values(TelemetryCase{"TwoServosNoFoot", kGoldenTelemetry, goldenBodyTelemetry()},
                      TelemetryCase{"OneServoWithFoot", kFootTelemetry, footTelemetry()}),
    [](const auto& info) { return info.param.name; });

TEST(BodyCodec, TelemetryLenFormula) {
  EXPECT_EQ(telemetryLen(2, false), 32u);
  EXPECT_EQ(telemetryLen(1, true), 44u);
}

TEST(BodyCodec, ServoCountDecidesBetweenFootAndMoreServos) {
  // LEN 44 is N = 1 with foot data, or N = 5 without: only the configuration can tell.
  const auto as_five = decodeTelemetry(kFootTelemetry.data(), kFootTelemetry.size(), 5);
  ASSERT_TRUE(as_five.ok());
  EXPECT_EQ(as_five->servo_count, 5u);
  EXPECT_FALSE(as_five->has_foot);
  EXPECT_EQ(as_five->servos[1].position, 258);  // the first IMU value read as a position
  EXPECT_EQ(as_five->imu[1], 256);              // the first foot value 01 00 read big-endian
}

TEST(BodyCodec, EncodeRefusesFramesLongerThan255) {
  Telemetry too_many;
  too_many.servo_count = kMaxTelemetryServos;
  too_many.has_foot = true;  // 40 + 4*57 = 268 bytes
  EXPECT_TRUE(encodeTelemetry(too_many).empty());
  too_many.has_foot = false;  // 24 + 4*57 = 252 bytes
  EXPECT_EQ(encodeTelemetry(too_many).size(), 252u);
}

struct MalformedTelemetryCase {
  std::string name;
  Bytes frame;
  std::size_t servo_count;
  protocol::DecodeError error;
};

const MalformedTelemetryCase kMalformedTelemetry[] = {
    {"BadSum", withByte(kGoldenTelemetry, 29, 0x94), 2, protocol::DecodeError::kBadChecksum},
    {"CorruptedContent", withByte(kGoldenTelemetry, 10, 0xFA), 2,
     protocol::DecodeError::kBadChecksum},
    {"BadTail", withByte(kGoldenTelemetry, 31, 0x2E), 2, protocol::DecodeError::kBadTail},
    {"BadHeader", withByte(kGoldenTelemetry, 1, 0x35), 2, protocol::DecodeError::kBadHeader},
    {"Truncated", Bytes(kGoldenTelemetry.begin(), kGoldenTelemetry.begin() + 20), 2,
     protocol::DecodeError::kTooShort},
    {"OnlyHeader", {0x12, 0x34}, 2, protocol::DecodeError::kTooShort},
    {"Empty", {}, 2, protocol::DecodeError::kTooShort},
    {"LenZero", withByte(kGoldenTelemetry, 2, 0x00), 2, protocol::DecodeError::kBadLength},
    {"LenOne", withByte(kGoldenTelemetry, 2, 0x01), 2, protocol::DecodeError::kBadLength},
    {"Len255", withByte(kGoldenTelemetry, 2, 0xFF), 2, protocol::DecodeError::kBadLength},
    // LEN 32 is right for N = 2 but not for N = 3 (36 or 52) or N = 1 (28 or 44).
    {"LenInconsistentWithThreeServos", kGoldenTelemetry, 3, protocol::DecodeError::kBadLength},
    {"LenInconsistentWithOneServo", kGoldenTelemetry, 1, protocol::DecodeError::kBadLength},
    // LEN 36 would be valid for N = 3, but only 32 bytes are there.
    {"LenBeyondSize", withByte(kGoldenTelemetry, 2, 0x24), 3, protocol::DecodeError::kTooShort},
    {"ServoCountAboveMax", kGoldenTelemetry, kMaxTelemetryServos + 1,
     protocol::DecodeError::kBadLength},
};

class BodyCodecMalformedTelemetry : public ::testing::TestWithParam<MalformedTelemetryCase> {};

TEST_P(BodyCodecMalformedTelemetry, Rejected) {
  const MalformedTelemetryCase& c = GetParam();
  const auto decoded = decodeTelemetry(c.frame.data(), c.frame.size(), c.servo_count);
  ASSERT_FALSE(decoded.ok());
  EXPECT_EQ(decoded.error(), c.error) << protocol::toString(decoded.error());
}

INSTANTIATE_TEST_SUITE_P(BodyCodecErrors, BodyCodecMalformedTelemetry,
                         ::testing::ValuesIn(kMalformedTelemetry),
                         [](const auto& info) { return info.param.name; });

TEST(BodyCodec, TrailingByteAfterFrameIsBadLength) {
  Bytes frame = kGoldenTelemetry;
  frame.push_back(0x12);
  const auto decoded = decodeTelemetry(frame.data(), frame.size(), 2);
  ASSERT_FALSE(decoded.ok());
  EXPECT_EQ(decoded.error(), protocol::DecodeError::kBadLength);
}

// --- probe (what the stream framer asks) -------------------------------------------------------

using test_support::expectProbeFindsFrame;
using test_support::expectProbeRejects;

// No servos, no foot block: LEN 24 = 0x18, IMU all zero, SUM = 0x18 (LEN only).
// clang-format off
const Bytes kProbeTelemetryNoServos = {
    0x12, 0x34, 0x18,
    0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00,
    0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00,
    0x18, 0x1F, 0x2F};
// Sync write of servo 1 to 512 (docs/protocols.md layout, CRC 8E3A checked independently).
const Bytes kProbeSyncWrite = {0xFF, 0xFF, 0xFD, 0x00, 0xFE, 0x0A, 0x00, 0x83, 0x74, 0x00,
                               0x02, 0x00, 0x01, 0x00, 0x02, 0x3A, 0x8E};
// clang-format on

protocol::Probe probeTelemetryOfNoServos(const uint8_t* data, std::size_t available) {
  return probeTelemetry(data, available, 0);
}

TEST(BodyCodecProbe, TelemetryFrameFoundAndNeedsMoreAtEveryTruncation) {
  expectProbeFindsFrame(probeTelemetryOfNoServos, kProbeTelemetryNoServos);
}

TEST(BodyCodecProbe, TelemetryInvalidReasons) {
  expectProbeRejects(probeTelemetryOfNoServos, withByte(kProbeTelemetryNoServos, 21, 0x19),
                     protocol::DecodeError::kBadChecksum);
  expectProbeRejects(probeTelemetryOfNoServos, withByte(kProbeTelemetryNoServos, 23, 0x2E),
                     protocol::DecodeError::kBadTail);
  // LEN 28 is a frame of one servo: wrong for the configured zero.
  expectProbeRejects(probeTelemetryOfNoServos, withByte(kProbeTelemetryNoServos, 2, 0x1C),
                     protocol::DecodeError::kBadLength);
  expectProbeRejects(probeTelemetryOfNoServos, {0x12, 0x4C}, protocol::DecodeError::kBadHeader);
}

TEST(BodyCodecProbe, TelemetryLenFollowsTheConfiguredServoCount) {
  // The same bytes with LEN 0x1C (24 + 4) are one servo's length, 0x2C (40 + 4) one with foot.
  const Bytes one_servo_len = {0x12, 0x34, 0x1C};
  EXPECT_EQ(probeTelemetry(one_servo_len.data(), 3, 1).status, protocol::Probe::Status::kNeedMore);
  const Bytes one_servo_foot_len = {0x12, 0x34, 0x2C};
  EXPECT_EQ(probeTelemetry(one_servo_foot_len.data(), 3, 1).status,
            protocol::Probe::Status::kNeedMore);
  EXPECT_EQ(probeTelemetry(one_servo_len.data(), 3, 2).status, protocol::Probe::Status::kInvalid);
}

TEST(BodyCodecProbe, SyncWriteFrameFoundAndNeedsMoreAtEveryTruncation) {
  expectProbeFindsFrame(probeSyncWrite, kProbeSyncWrite);
}

TEST(BodyCodecProbe, SyncWriteInvalidReasons) {
  expectProbeRejects(probeSyncWrite, withByte(kProbeSyncWrite, 16, 0x8F),
                     protocol::DecodeError::kBadChecksum);
  // LEN 0x0B is not 7 + 3N.
  expectProbeRejects(probeSyncWrite, withByte(kProbeSyncWrite, 5, 0x0B),
                     protocol::DecodeError::kBadLength);
  // 7 + 3 * 65 = 202 = 0xCA: one servo more than the 64 accepted.
  expectProbeRejects(probeSyncWrite, withByte(kProbeSyncWrite, 5, 0xCA),
                     protocol::DecodeError::kBadLength);
  expectProbeRejects(probeSyncWrite, withByte(kProbeSyncWrite, 4, 0x01),
                     protocol::DecodeError::kBadHeader);
  expectProbeRejects(probeSyncWrite, withByte(kProbeSyncWrite, 7, 0x82),
                     protocol::DecodeError::kBadHeader);
}

}  // namespace
}  // namespace serial_robot_driver::devices::body
