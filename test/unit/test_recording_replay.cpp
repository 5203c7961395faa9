// core::RecordingReplay and the checks of a recording (core/recording_replay.h), without a bag:
// which topic is serial_raw, the one clear message for each way a recording cannot be replayed,
// the ports it stands in for, and a replay fed through the streams it makes.
#include <gtest/gtest.h>

#include <limits>
#include <string>
#include <vector>

#include "serial_robot_driver/core/recording_replay.h"
#include "serial_robot_driver/devices/body/body_params.h"

namespace serial_robot_driver::core {
namespace {

using transport::RecordedStamp;

template <typename Call>
std::string errorOf(Call call) {
  try {
    call();
  } catch (const ReplayError& e) {
    return e.what();
  }
  return "no error";
}

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

Recording recordingOf(const std::string& port, std::vector<transport::RecordedChunk> chunks) {
  Recording recording;
  recording.topic = "/serial_raw";
  recording.end = RecordedStamp(3000);
  recording.ports[port] = std::move(chunks);
  return recording;
}

TEST(RecordingReplay, InboundChunksAreKeptPerPortInOrderAndWritesOnlyCounted) {
  Recording recording;
  recording.end = RecordedStamp(5);
  addRecordedChunk(recording, "/dev/a", false, RecordedStamp(10), {0x01});
  addRecordedChunk(recording, "/dev/a", true, RecordedStamp(99), {0x02});
  addRecordedChunk(recording, "/dev/b", false, RecordedStamp(20), {});
  addRecordedChunk(recording, "/dev/a", false, RecordedStamp(std::numeric_limits<int64_t>::min()),
                   std::vector<uint8_t>(100000, 0xFF));
  EXPECT_EQ(recording.outbound_chunks, 1u);
  ASSERT_EQ(recording.ports.size(), 2u);
  ASSERT_EQ(recording.ports["/dev/a"].size(), 2u);
  EXPECT_EQ(recording.ports["/dev/a"][0].data, std::vector<uint8_t>{0x01});
  EXPECT_EQ(recording.ports["/dev/a"][1].data.size(), 100000u);
  EXPECT_TRUE(recording.ports["/dev/b"][0].data.empty()) << "a reopen mark";
  EXPECT_EQ(recording.end, RecordedStamp(20)) << "the latest inbound stamp; writes do not count";
}

TEST(RecordingReplay, SerialRawIsFoundByItsLastName) {
  EXPECT_TRUE(isSerialRawTopic("serial_raw"));
  EXPECT_TRUE(isSerialRawTopic("/robot1/serial_raw"));
  EXPECT_FALSE(isSerialRawTopic("/serial_raw_old"));
  EXPECT_FALSE(isSerialRawTopic("/serial_raw/x"));
  EXPECT_FALSE(isSerialRawTopic(""));
  EXPECT_EQ(serialRawTopic("a.bag", {"/rosout", "/robot1/serial_raw"}), "/robot1/serial_raw");
}

TEST(RecordingReplay, ARecordingWithoutSerialRawListsItsTopics) {
  const std::string none = errorOf([] { serialRawTopic("a.bag", {"/rosout", "/odom"}); });
  EXPECT_TRUE(contains(none, "replay bag a.bag has no serial_raw topic")) << none;
  EXPECT_TRUE(contains(none, "its topics: /odom, /rosout")) << none;
  const std::string empty = errorOf([] { serialRawTopic("", {}); });
  EXPECT_TRUE(contains(empty, "its topics: none")) << empty;
}

TEST(RecordingReplay, SerialRawOfSeveralDriversIsAmbiguous) {
  const std::string error = errorOf([] {
    serialRawTopic("a.bag", {"/r1/serial_raw", "/r2/serial_raw"});
  });
  EXPECT_TRUE(contains(error, "several drivers (/r1/serial_raw, /r2/serial_raw)")) << error;
}

TEST(RecordingReplay, ARecordingWithoutAnInboundChunkHasNothingToReplay) {
  Recording recording;
  recording.topic = "/serial_raw";
  EXPECT_TRUE(contains(errorOf([&] { requireInboundChunks("a.bag", recording); }),
                       "/serial_raw holds no inbound chunk"));
  recording.ports["/dev/ttyUSB0"] = {};  // a port named, but no chunk of it
  params::DriverParams params;
  EXPECT_TRUE(contains(errorOf([&] { RecordingReplay replay("a.bag", recording, params); }),
                       "holds no inbound chunk"));
}

TEST(RecordingReplay, AChunkOfAPortTheConfigurationLacksIsNamed) {
  params::DriverParams params;  // every device on /dev/ttyUSB0
  const Recording recording = recordingOf("/dev/ttyACM7", {{RecordedStamp(1000), {0x02}}});
  const std::string error = errorOf([&] { RecordingReplay replay("a.bag", recording, params); });
  EXPECT_TRUE(contains(error, "has chunks of port /dev/ttyACM7")) << error;
  EXPECT_TRUE(contains(error, "(configured: /dev/ttyUSB0)")) << error;
  params.section(devices::body::kBodySection).port = "/dev/ttyACM7";
  EXPECT_EQ(errorOf([&] { RecordingReplay replay("a.bag", recording, params); }), "no error");
}

TEST(RecordingReplay, StandsInForThePortsAndFeedsTheirChunksToTheEnd) {
  params::DriverParams params;
  params.replay_rate = 0.0;  // full speed
  params.reconnect_interval = 1.0;
  const Recording recording = recordingOf(
      "/dev/ttyUSB0", {{RecordedStamp(1000), {}}, {RecordedStamp(2000), {0x01, 0x02, 0x03}}});
  RecordingReplay replay("a.bag", recording, params);
  SerialLink::StreamFactory factory;
  replay.standIn(params, factory);
  EXPECT_EQ(params.reconnect_interval, 0.0) << "the recording paces its reopens";
  EXPECT_EQ(params.replay_timeline, replay.timeline());
  ASSERT_TRUE(factory);
  EXPECT_FALSE(replay.finished());

  replay.startClock();
  SerialLinkOptions options;
  options.path = "/dev/ttyUSB0";
  const auto stream = factory(options);
  stream->open();
  uint8_t buffer[16];
  EXPECT_EQ(stream->read(buffer, sizeof(buffer), 10), 3u);
  stream->write(buffer, 2);
  EXPECT_EQ(stream->read(buffer, sizeof(buffer), 10), 0u);
  EXPECT_TRUE(replay.finished());
  EXPECT_EQ(replay.summary(),
            "replay of a.bag (/serial_raw): port /dev/ttyUSB0: 1 chunks (3 bytes) fed, 1 opens, "
            "1 writes (2 bytes) discarded;");
}

TEST(RecordingReplay, ThePaceIsNamedForTheLog) {
  EXPECT_EQ(replayPaceText(0.0), "full speed");
  EXPECT_EQ(replayPaceText(-1.0), "full speed");
  EXPECT_EQ(replayPaceText(std::numeric_limits<double>::quiet_NaN()), "full speed");
  EXPECT_EQ(replayPaceText(2.0), "2.000000x the recorded pace");
}

}  // namespace
}  // namespace serial_robot_driver::core
