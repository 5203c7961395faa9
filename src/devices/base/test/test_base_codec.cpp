// AP1 wheeled base codec: golden vectors from docs/protocols.md, section 1, written out by hand.
#include <gtest/gtest.h>

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "serial_robot_driver/devices/base/base_codec.h"
#include "support/golden_frames.h"
#include "support/probe_expectations.h"

namespace serial_robot_driver::devices::base {
namespace {

using Bytes = std::vector<uint8_t>;

struct HostFrameCase {
  std::string name;
  std::function<Bytes()> encode;
  Bytes expected;
  uint8_t seq;
  uint8_t msg_id;
  Bytes params;
};

// Every host -> base vector of docs/protocols.md, plus two that exercise signed values and a high
// SEQ. XOR of the last two computed by hand: 55^AA^09^00^01^FF^FB^01^2C = DE.
// clang-format off
const HostFrameCase kHostFrames[] = {
    {"Reset_Seq02", [] { return encodeReset(0x02); },
     golden::base::kResetSeq2, 0x02, 0x05, {0x00}},
    {"BatteryRequest_Seq01", [] { return encodeBatteryRequest(0x01); },
     golden::base::kBatteryRequestSeq1, 0x01, 0x02, {0x00}},
    {"ClearEncoders_Seq03", [] { return encodeClearEncoders(0x03); },
     golden::base::kClearEncodersSeq3, 0x03, 0x06, {0x00}},
    {"Left4Right0", [] { return encodeWheelSpeed(0x00, 4, 0); },
     {0x55, 0xAA, 0x09, 0x00, 0x01, 0x00, 0x04, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0xF3}, 0x00,
     0x01, {0x00, 0x04, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00}},
    {"Left0Right4", [] { return encodeWheelSpeed(0x00, 0, 4); },
     {0x55, 0xAA, 0x09, 0x00, 0x01, 0x00, 0x00, 0x00, 0x04, 0x00, 0x00, 0x00, 0x00, 0xF3}, 0x00,
     0x01, {0x00, 0x00, 0x00, 0x04, 0x00, 0x00, 0x00, 0x00}},
    {"Both4", [] { return encodeWheelSpeed(0x00, 4, 4); },
     {0x55, 0xAA, 0x09, 0x00, 0x01, 0x00, 0x04, 0x00, 0x04, 0x00, 0x00, 0x00, 0x00, 0xF7}, 0x00,
     0x01, {0x00, 0x04, 0x00, 0x04, 0x00, 0x00, 0x00, 0x00}},
    {"BothMinus6", [] { return encodeWheelSpeed(0x00, -6, -6); },
     {0x55, 0xAA, 0x09, 0x00, 0x01, 0xFF, 0xFA, 0xFF, 0xFA, 0x00, 0x00, 0x00, 0x00, 0xF7}, 0x00,
     0x01, {0xFF, 0xFA, 0xFF, 0xFA, 0x00, 0x00, 0x00, 0x00}},
    {"LeftMinus5Right300", [] { return encodeWheelSpeed(0x00, -5, 300); },
     {0x55, 0xAA, 0x09, 0x00, 0x01, 0xFF, 0xFB, 0x01, 0x2C, 0x00, 0x00, 0x00, 0x00, 0xDE}, 0x00,
     0x01, {0xFF, 0xFB, 0x01, 0x2C, 0x00, 0x00, 0x00, 0x00}},
};
// clang-format on

class BaseCodecHostFrame : public ::testing::TestWithParam<HostFrameCase> {};

TEST_P(BaseCodecHostFrame, EncoderReproducesGoldenBytes) {
  EXPECT_EQ(GetParam().encode(), GetParam().expected);
}

TEST_P(BaseCodecHostFrame, DecoderReadsGoldenBytes) {
  const HostFrameCase& c = GetParam();
  const protocol::Decoded<Frame> frame = decodeFrame(c.expected.data(), c.expected.size());
  ASSERT_TRUE(frame.ok()) << protocol::toString(frame.error());
  EXPECT_EQ(frame->seq, c.seq);
  EXPECT_EQ(frame->msg_id, c.msg_id);
  ASSERT_EQ(frame->param_count, c.params.size());
  EXPECT_EQ(Bytes(frame->params.begin(), frame->params.begin() + frame->param_count), c.params);
}

TEST_P(BaseCodecHostFrame, ChecksumCoversEveryPrecedingByte) {
  const Bytes& bytes = GetParam().expected;
  EXPECT_EQ(xorChecksum(bytes.data(), bytes.size() - 1), bytes.back());
}

INSTANTIATE_TEST_SUITE_P(BaseCodecGolden, BaseCodecHostFrame, ::testing::ValuesIn(kHostFrames),
                         [](const auto& info) { return info.param.name; });

struct WheelSpeedCase {
  std::string name;
  Bytes frame;
  int16_t left;
  int16_t right;
};

// clang-format off
const WheelSpeedCase kWheelSpeeds[] = {
    {"Left4Right0",
     {0x55, 0xAA, 0x09, 0x00, 0x01, 0x00, 0x04, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0xF3}, 4, 0},
    {"Left0Right4",
     {0x55, 0xAA, 0x09, 0x00, 0x01, 0x00, 0x00, 0x00, 0x04, 0x00, 0x00, 0x00, 0x00, 0xF3}, 0, 4},
    {"BothMinus6",
     {0x55, 0xAA, 0x09, 0x00, 0x01, 0xFF, 0xFA, 0xFF, 0xFA, 0x00, 0x00, 0x00, 0x00, 0xF7}, -6, -6},
    {"LeftMinus5Right300",
     {0x55, 0xAA, 0x09, 0x00, 0x01, 0xFF, 0xFB, 0x01, 0x2C, 0x00, 0x00, 0x00, 0x00, 0xDE}, -5, 300},
};
// clang-format on

class BaseCodecWheelSpeed : public ::testing::TestWithParam<WheelSpeedCase> {};

TEST_P(BaseCodecWheelSpeed, BigEndianSignedTicks) {
  const WheelSpeedCase& c = GetParam();
  const protocol::Decoded<Frame> frame = decodeFrame(c.frame.data(), c.frame.size());
  ASSERT_TRUE(frame.ok());
  const protocol::Decoded<WheelSpeed> speed = interpretWheelSpeed(*frame);
  ASSERT_TRUE(speed.ok());
  EXPECT_EQ(speed->left_ticks, c.left);
  EXPECT_EQ(speed->right_ticks, c.right);
}

INSTANTIATE_TEST_SUITE_P(BaseCodecGolden, BaseCodecWheelSpeed, ::testing::ValuesIn(kWheelSpeeds),
                         [](const auto& info) { return info.param.name; });

TEST(BaseCodec, WheelSpeedOfOtherMessageIsUnexpected) {
  const Bytes& reset = golden::base::kResetSeq2;
  const protocol::Decoded<Frame> frame = decodeFrame(reset.data(), reset.size());
  ASSERT_TRUE(frame.ok());
  const protocol::Decoded<WheelSpeed> speed = interpretWheelSpeed(*frame);
  ASSERT_FALSE(speed.ok());
  EXPECT_EQ(speed.error(), protocol::DecodeError::kUnexpectedContent);
}

// --- base -> host replies ----------------------------------------------------------------------

TEST(BaseCodec, ErrorStatusEncoding) {
  // 55^AA^02^07^FF^00 = 05
  EXPECT_EQ(encodeErrorStatus(0x07), (Bytes{0x55, 0xAA, 0x02, 0x07, 0xFF, 0x00, 0x05}));
}

TEST(BaseCodec, BatteryReplyEncoding) {
  // 57 % = 0x39; 55^AA^02^09^02^39 = CF
  EXPECT_EQ(encodeBatteryReply(0x09, 57), (Bytes{0x55, 0xAA, 0x02, 0x09, 0x02, 0x39, 0xCF}));
}

struct ReplyCase {
  std::string name;
  Bytes frame;
  Reply::Kind kind;
  uint8_t battery_percent;
};

// clang-format off
const ReplyCase kReplies[] = {
    {"TimeoutError", {0x55, 0xAA, 0x02, 0x07, 0xFF, 0x00, 0x05}, Reply::Kind::kTimeoutError, 0},
    {"Battery57", {0x55, 0xAA, 0x02, 0x09, 0x02, 0x39, 0xCF}, Reply::Kind::kBattery, 57},
    // 200 % is nonsense from the base; it is clamped. XOR: 55^AA^02^00^02^C8 = 37
    {"Battery200Clamped", {0x55, 0xAA, 0x02, 0x00, 0x02, 0xC8, 0x37}, Reply::Kind::kBattery, 100},
    // MSGID 33 is not in the vendor table. XOR: 55^AA^03^05^33^01^02 = C9
    {"UnknownMsgId", {0x55, 0xAA, 0x03, 0x05, 0x33, 0x01, 0x02, 0xC9}, Reply::Kind::kUnknown, 0},
};
// clang-format on

class BaseCodecReply : public ::testing::TestWithParam<ReplyCase> {};

TEST_P(BaseCodecReply, Interpreted) {
  const ReplyCase& c = GetParam();
  const protocol::Decoded<Frame> frame = decodeFrame(c.frame.data(), c.frame.size());
  ASSERT_TRUE(frame.ok()) << protocol::toString(frame.error());
  const protocol::Decoded<Reply> reply = interpretReply(*frame);
  ASSERT_TRUE(reply.ok());
  EXPECT_EQ(reply->kind, c.kind);
  if (c.kind == Reply::Kind::kBattery) {
    EXPECT_EQ(reply->battery_percent, c.battery_percent);
  }
  EXPECT_EQ(reply->frame.msg_id, c.frame[4]);
}

INSTANTIATE_TEST_SUITE_P(BaseCodecGolden, BaseCodecReply, ::testing::ValuesIn(kReplies),
                         [](const auto& info) { return info.param.name; });

TEST(BaseCodec, UnknownReplyKeepsRawFrame) {
  const Bytes bytes = {0x55, 0xAA, 0x03, 0x05, 0x33, 0x01, 0x02, 0xC9};
  const protocol::Decoded<Frame> frame = decodeFrame(bytes.data(), bytes.size());
  ASSERT_TRUE(frame.ok());
  const protocol::Decoded<Reply> reply = interpretReply(*frame);
  ASSERT_TRUE(reply.ok());
  EXPECT_EQ(reply->frame.seq, 0x05);
  ASSERT_EQ(reply->frame.param_count, 2);
  EXPECT_EQ(reply->frame.params[0], 0x01);
  EXPECT_EQ(reply->frame.params[1], 0x02);
}

TEST(BaseCodec, BatteryReplyWithoutParamIsUnexpected) {
  // LEN 1: MSGID only. XOR: 55^AA^01^00^02 = FC
  const Bytes bytes = {0x55, 0xAA, 0x01, 0x00, 0x02, 0xFC};
  const protocol::Decoded<Frame> frame = decodeFrame(bytes.data(), bytes.size());
  ASSERT_TRUE(frame.ok());
  const protocol::Decoded<Reply> reply = interpretReply(*frame);
  ASSERT_FALSE(reply.ok());
  EXPECT_EQ(reply.error(), protocol::DecodeError::kUnexpectedContent);
}

// --- malformed frames ----------------------------------------------------------------------------

struct MalformedCase {
  std::string name;
  Bytes frame;
  protocol::DecodeError error;
};

// clang-format off
const MalformedCase kMalformed[] = {
    {"BadChecksum", {0x55, 0xAA, 0x02, 0x02, 0x05, 0x00, 0xFB}, protocol::DecodeError::kBadChecksum},
    {"BadHeader", {0x55, 0xAB, 0x02, 0x02, 0x05, 0x00, 0xFA}, protocol::DecodeError::kBadHeader},
    {"SwappedHeader", {0xAA, 0x55, 0x02, 0x02, 0x05, 0x00, 0xFA}, protocol::DecodeError::kBadHeader},
    {"Truncated", {0x55, 0xAA, 0x09, 0x00, 0x01, 0x00, 0x04, 0x00}, protocol::DecodeError::kTooShort},
    {"OnlyHeader", {0x55, 0xAA}, protocol::DecodeError::kTooShort},
    {"Empty", {}, protocol::DecodeError::kTooShort},
    {"LenZero", {0x55, 0xAA, 0x00, 0x02, 0x05, 0x00, 0xFA}, protocol::DecodeError::kBadLength},
    {"Len255", {0x55, 0xAA, 0xFF, 0x02, 0x05, 0x00, 0xFA}, protocol::DecodeError::kBadLength},
    {"LenAboveMax", {0x55, 0xAA, 0x21, 0x02, 0x05, 0x00, 0xFA}, protocol::DecodeError::kBadLength},
    // LEN 2 says 7 bytes, 8 were given.
    {"LenTooSmallForSize", {0x55, 0xAA, 0x02, 0x02, 0x05, 0x00, 0x00, 0xFA},
     protocol::DecodeError::kBadLength},
};
// clang-format on

class BaseCodecMalformed : public ::testing::TestWithParam<MalformedCase> {};

TEST_P(BaseCodecMalformed, Rejected) {
  const MalformedCase& c = GetParam();
  const protocol::Decoded<Frame> frame = decodeFrame(c.frame.data(), c.frame.size());
  ASSERT_FALSE(frame.ok());
  EXPECT_EQ(frame.error(), c.error) << protocol::toString(frame.error());
}

INSTANTIATE_TEST_SUITE_P(BaseCodecErrors, BaseCodecMalformed, ::testing::ValuesIn(kMalformed),
                         [](const auto& info) { return info.param.name; });

TEST(BaseCodec, LenOneIsSmallestFrame) {
  // LEN 1, MSGID 05. XOR: 55^AA^01^00^05 = FB
  const Bytes bytes = {0x55, 0xAA, 0x01, 0x00, 0x05, 0xFB};
  const protocol::Decoded<Frame> frame = decodeFrame(bytes.data(), bytes.size());
  ASSERT_TRUE(frame.ok());
  EXPECT_EQ(frame->msg_id, 0x05);
  EXPECT_EQ(frame->param_count, 0);
}

TEST(BaseCodec, FrameSizeCountsOverhead) {
  EXPECT_EQ(frameSize(2), 7u);
  EXPECT_EQ(frameSize(9), 14u);
}

// --- sequence counter ----------------------------------------------------------------------------

TEST(BaseCodec, SequenceCounterWrapsFrom255To0) {
  SequenceCounter counter;
  EXPECT_EQ(counter.next(), 0);
  EXPECT_EQ(counter.next(), 1);
  counter.reset(254);
  EXPECT_EQ(counter.next(), 254);
  EXPECT_EQ(counter.next(), 255);
  EXPECT_EQ(counter.next(), 0);
  EXPECT_EQ(counter.peek(), 1);
}

TEST(BaseCodec, SequenceNumberAfterWrapIsEncoded) {
  SequenceCounter counter;
  counter.reset(255);
  // SEQ FF: 55^AA^02^FF^05^00 = 07; then SEQ 00: 55^AA^02^00^05^00 = F8
  EXPECT_EQ(encodeReset(counter.next()), (Bytes{0x55, 0xAA, 0x02, 0xFF, 0x05, 0x00, 0x07}));
  EXPECT_EQ(encodeReset(counter.next()), golden::base::kResetSeq0);
}

// --- probe (what the stream framer asks) -------------------------------------------------------

using test_support::expectProbeFindsFrame;
using test_support::expectProbeRejects;

// Reset, SEQ 00: 55^AA^01^00^05 = FB.
const Bytes kProbeReset = {0x55, 0xAA, 0x01, 0x00, 0x05, 0xFB};

TEST(BaseCodecProbe, FindsGoldenFrameAndNeedsMoreAtEveryTruncation) {
  expectProbeFindsFrame(probeFrame, kProbeReset);
}

TEST(BaseCodecProbe, SaysWhyACandidateIsInvalid) {
  expectProbeRejects(probeFrame, {0x55, 0xAA, 0x01, 0x00, 0x05, 0xFA},
                     protocol::DecodeError::kBadChecksum);
  expectProbeRejects(probeFrame, {0x55, 0xAA, 0x00, 0x00, 0x05, 0xFA},
                     protocol::DecodeError::kBadLength);
  expectProbeRejects(probeFrame, {0x55, 0xAA, 0x21},
                     protocol::DecodeError::kBadLength);  // LEN 33 > 32
  expectProbeRejects(probeFrame, {0x55, 0xAB}, protocol::DecodeError::kBadHeader);
  expectProbeRejects(probeFrame, {0xAA}, protocol::DecodeError::kBadHeader);
}

}  // namespace
}  // namespace serial_robot_driver::devices::base
