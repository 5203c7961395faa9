// The echo device's frames, written out by hand from the rules in echo_codec.h, through its codec
// and through the driver's framer next to the other devices' families; its parameter rows.
#include <gtest/gtest.h>

#include <set>
#include <string>
#include <vector>

#include "serial_robot_driver/core/device_module.h"
#include "serial_robot_driver/devices/echo/echo_codec.h"
#include "serial_robot_driver/devices/echo/echo_params.h"
#include "serial_robot_driver/params/driver_params.h"
#include "support/framer_configs.h"
#include "support/golden_frames.h"
#include "support/test_helpers.h"

namespace serial_robot_driver::devices::echo {
namespace {

using Bytes = std::vector<uint8_t>;

// XOR of every byte before the check, by hand: E5^01^03^01^02^03 = E7, E5^02^03^01^02^03 = E4.
const Bytes kRequest123 = {0xE5, 0x01, 0x03, 0x01, 0x02, 0x03, 0xE7};
const Bytes kAnswer123 = {0xE5, 0x02, 0x03, 0x01, 0x02, 0x03, 0xE4};
const Bytes kEmptyRequest = {0xE5, 0x01, 0x00, 0xE4};
const Bytes kEmptyAnswer = {0xE5, 0x02, 0x00, 0xE7};

/// Every frame a framer configured with `config` hands out, in order, with its family's name.
struct Collected {
  std::vector<std::pair<std::string, Bytes>> frames;
  protocol::FramerStats stats;
};
Collected frame(const protocol::FramerConfig& config, const std::vector<Bytes>& chunks) {
  Collected out;
  protocol::StreamFramer framer(
      config, [&out](const protocol::FrameFamily& family, const uint8_t* data, std::size_t size) {
        out.frames.emplace_back(family.name, Bytes(data, data + size));
      });
  for (const Bytes& chunk : chunks) framer.feed(chunk.data(), chunk.size());
  out.stats = framer.stats();
  return out;
}
protocol::FramerConfig driverSide() { return test_support::driverFramer({"echo"}); }

TEST(EchoCodec, EncodesTheGoldenFrames) {
  EXPECT_EQ(encodeRequest({1, 2, 3}), kRequest123);
  EXPECT_EQ(encodeAnswer({1, 2, 3}), kAnswer123);
  EXPECT_EQ(encodeRequest({}), kEmptyRequest);
  EXPECT_EQ(encodeAnswer({}), kEmptyAnswer);
  EXPECT_TRUE(encodeRequest(Bytes(kMaxPayload + 1, 0)).empty());
  EXPECT_EQ(encodeRequest(Bytes(kMaxPayload, 0)).size(), kMaxPayload + kOverhead);
}

TEST(EchoCodec, DecodesOnlyItsOwnDirection) {
  const auto payload = decode(kAnswerType, kAnswer123.data(), kAnswer123.size());
  ASSERT_TRUE(payload.ok());
  EXPECT_EQ(*payload, (Bytes{1, 2, 3}));
  EXPECT_EQ(decode(kRequestType, kAnswer123.data(), kAnswer123.size()).error(),
            protocol::DecodeError::kBadHeader);
  const Bytes bad = test_support::withByte(kAnswer123, 6, 0xE5);
  EXPECT_EQ(decode(kAnswerType, bad.data(), bad.size()).error(),
            protocol::DecodeError::kBadChecksum);
  EXPECT_EQ(decode(kAnswerType, kAnswer123.data(), 5).error(), protocol::DecodeError::kTooShort);
}

TEST(EchoFramer, FindsAnswersWholeSplitAndBehindJunk) {
  Collected whole = frame(driverSide(), {kAnswer123});
  ASSERT_EQ(whole.frames.size(), 1u);
  EXPECT_EQ(whole.frames[0], std::make_pair(std::string("echo_answer"), kAnswer123));

  // Split across reads, at every point.
  for (std::size_t cut = 1; cut < kAnswer123.size(); ++cut) {
    const Collected split =
        frame(driverSide(), {Bytes(kAnswer123.begin(), kAnswer123.begin() + cut),
                             Bytes(kAnswer123.begin() + cut, kAnswer123.end())});
    ASSERT_EQ(split.frames.size(), 1u) << cut;
    EXPECT_EQ(split.frames[0].second, kAnswer123) << cut;
  }

  // Junk (a lone header among it) before the frame is skipped.
  const Collected junk = frame(driverSide(), {{0x00, 0xE5, 0x7F, 0x13}, kEmptyAnswer});
  ASSERT_EQ(junk.frames.size(), 1u);
  EXPECT_EQ(junk.frames[0].second, kEmptyAnswer);
  EXPECT_EQ(junk.stats.bytes_skipped, 4u);
}

TEST(EchoFramer, RejectsBrokenAnswersAndFindsTheFrameBehind) {
  // Bad checksum: counted, and the good frame behind it still comes out.
  const Collected bad_check =
      frame(driverSide(), {test_support::withByte(kAnswer123, 6, 0x00), kEmptyAnswer});
  ASSERT_EQ(bad_check.frames.size(), 1u);
  EXPECT_EQ(bad_check.frames[0].second, kEmptyAnswer);
  EXPECT_EQ(bad_check.stats.checksum_errors, 1u);

  // Absurd length (LEN 0xFF > 32): not waited for.
  const Collected absurd = frame(driverSide(), {{0xE5, 0x02, 0xFF, 0x01}, kEmptyAnswer});
  ASSERT_EQ(absurd.frames.size(), 1u);
  EXPECT_EQ(absurd.frames[0].second, kEmptyAnswer);
  EXPECT_EQ(absurd.stats.bad_lengths, 1u);

  // Truncated: nothing handed out until the rest comes.
  const Collected truncated =
      frame(driverSide(), {Bytes(kAnswer123.begin(), kAnswer123.end() - 1)});
  EXPECT_TRUE(truncated.frames.empty());
  EXPECT_EQ(truncated.stats.checksum_errors + truncated.stats.bad_lengths, 0u);

  // A request is the other direction's: the driver's framer skips it without an error.
  const Collected request = frame(driverSide(), {kRequest123, kAnswer123});
  ASSERT_EQ(request.frames.size(), 1u);
  EXPECT_EQ(request.frames[0].second, kAnswer123);
  EXPECT_EQ(request.stats.checksum_errors + request.stats.bad_lengths, 0u);
}

TEST(EchoFramer, SharesAPortWithEveryOtherDevice) {
  // A servo bus ping and its answer (docs/protocols.md section 3, as in support/sim_host.h).
  const Bytes servo_ping1 = {0x12, 0x4C, 0x01, 0x01, 0x01, 0x61};
  const Bytes servo_ping1_reply = {0x05, 0x1C, 0x01, 0x01, 0x01, 0x24};
  const protocol::FramerConfig shared =
      test_support::driverFramer({"base", "body", "servo_bus", "echo"}, 2);
  const Collected mixed = frame(
      shared, {::golden::base::kBattery64ReplySeq0, kAnswer123, servo_ping1_reply, kEmptyAnswer});
  std::vector<std::string> names;
  for (const auto& found : mixed.frames) names.push_back(found.first);
  EXPECT_EQ(names,
            (std::vector<std::string>{"base", "echo_answer", "servo_response", "echo_answer"}));
  EXPECT_EQ(mixed.stats.bytes_skipped, 0u);

  // The simulator's framer reads the requests, next to the other devices' requests.
  const Collected simulator =
      frame(test_support::simulatorFramer(), {kRequest123, servo_ping1, kEmptyRequest});
  ASSERT_EQ(simulator.frames.size(), 3u);
  EXPECT_EQ(simulator.frames[0].first, std::string("echo_request"));
  EXPECT_EQ(simulator.frames[2].second, kEmptyRequest);
}

TEST(EchoParameters, TheTableHasItsRowsAndItIsOffByDefault) {
  std::set<std::string> keys;
  for (const params::ParamSpec& spec : params::parameterTable()) {
    if (spec.device == "echo") keys.insert(spec.key);
  }
  EXPECT_EQ(keys,
            (std::set<std::string>{"echo/enabled", "echo/port", "echo/baud", "echo/timeout"}));
  params::DriverParams defaults;
  EXPECT_FALSE(defaults.enabled("echo"));
  EXPECT_NO_THROW(defaults.validate());

  params::DriverParams on;
  params::specFor("echo/enabled").set(on, true);
  params::specFor("echo/timeout").set(on, 50);
  EXPECT_TRUE(on.enabled("echo"));
  EXPECT_EQ(on.section(kEchoSection).timeout_ms, 50);
  EXPECT_NO_THROW(on.validate());
  // 1 ms cannot carry a whole answer at 9600 baud.
  params::specFor("echo/baud").set(on, 9600);
  params::specFor("echo/timeout").set(on, 1);
  EXPECT_THROW(on.validate(), params::ParameterError);
  params::specFor("echo/timeout").set(on, 0);
  EXPECT_THROW(on.validate(), params::ParameterError);
}

}  // namespace
}  // namespace serial_robot_driver::devices::echo
