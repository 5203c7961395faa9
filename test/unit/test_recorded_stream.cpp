// transport::RecordedStream: a recorded port read back one chunk per read(), with the recorded
// arrival times, the recorded reopens as disconnects, and writes discarded.
#include <gtest/gtest.h>

#include <array>
#include <memory>
#include <thread>
#include <vector>

#include "serial_robot_driver/transport/recorded_stream.h"

namespace serial_robot_driver::transport {
namespace {

using std::chrono::milliseconds;

// A wall-clock stamp of 2026, as recorded: far beyond any steady clock's reading.
RecordedStamp at(int ms) { return RecordedStamp(std::chrono::seconds(1795000000)) + milliseconds(ms); }

std::shared_ptr<ReplayPacing> pacingOf(const std::vector<RecordedChunk>& chunks, double rate) {
  const RecordedStamp first = chunks.empty() ? at(0) : chunks.front().recorded;
  const RecordedStamp last = chunks.empty() ? at(0) : chunks.back().recorded;
  return std::make_shared<ReplayPacing>(rate, first, last);
}

std::shared_ptr<RecordedPort> portOf(std::vector<RecordedChunk> chunks, double rate = 0.0) {
  auto pacing = pacingOf(chunks, rate);
  return std::make_shared<RecordedPort>("/dev/ttyTEST", std::move(chunks), pacing);
}

/// One recorded port replayed from at(0) to `end` (silence after its last chunk included) at
/// `rate`, its stream open.
struct ReplayUntil {
  ReplayUntil(std::vector<RecordedChunk> chunks, double rate, RecordedStamp end)
      : pacing(std::make_shared<ReplayPacing>(rate, at(0), end)),
        port(std::make_shared<RecordedPort>("/dev/ttyTEST", std::move(chunks), pacing)),
        stream(port) {
    stream.open();
  }
  std::shared_ptr<ReplayPacing> pacing;
  std::shared_ptr<RecordedPort> port;
  RecordedStream stream;
};

std::vector<uint8_t> readOnce(RecordedStream& stream, std::size_t capacity = 64) {
  std::vector<uint8_t> buffer(capacity);
  buffer.resize(stream.read(buffer.data(), buffer.size(), 10));
  return buffer;
}

TEST(RecordedStream, HandsOutOneChunkPerReadWithItsArrival) {
  auto port = portOf({{at(0), {}}, {at(5), {0xAA, 0x55}}, {at(9), {0x01}}});
  RecordedStream stream(port);
  stream.open();  // takes the recorded "opened" mark
  EXPECT_EQ(readOnce(stream), (std::vector<uint8_t>{0xAA, 0x55}));
  ASSERT_TRUE(stream.arrivalTime());
  const SteadyTime first_arrival = *stream.arrivalTime();
  EXPECT_EQ(readOnce(stream), (std::vector<uint8_t>{0x01}));
  // On the replay's timeline the recorded gap keeps its length.
  EXPECT_EQ(*stream.arrivalTime() - first_arrival, milliseconds(4));
  EXPECT_FALSE(port->finished());
  EXPECT_TRUE(readOnce(stream).empty());
  EXPECT_TRUE(port->finished());
  EXPECT_EQ(port->stats().chunks_fed, 2u);
  EXPECT_EQ(port->stats().bytes_fed, 3u);
  EXPECT_EQ(port->stats().reopens, 1u);
}

TEST(RecordedStream, RecordedReopenIsADisconnectAndTheNextStreamReadsOn) {
  auto port = portOf({{at(0), {}}, {at(1), {0x10}}, {at(2), {}}, {at(3), {0x20}}});
  RecordedStream first(port);
  first.open();
  EXPECT_EQ(readOnce(first), (std::vector<uint8_t>{0x10}));
  try {
    readOnce(first);
    FAIL() << "the recorded reopen must end the stream";
  } catch (const TransportError& e) {
    EXPECT_EQ(e.kind(), TransportErrorKind::kDisconnected);
  }
  RecordedStream second(port);  // what SerialLink opens next
  second.open();
  EXPECT_EQ(readOnce(second), (std::vector<uint8_t>{0x20}));
  EXPECT_EQ(port->stats().reopens, 2u);
}

TEST(RecordedStream, ARecordingWithoutOpenMarksStartsWithData) {
  auto port = portOf({{at(0), {0x01, 0x02}}});
  RecordedStream stream(port);
  stream.open();
  EXPECT_EQ(readOnce(stream), (std::vector<uint8_t>{0x01, 0x02}));
}

TEST(RecordedStream, AChunkLargerThanTheBufferComesInPiecesWithTheSameArrival) {
  auto port = portOf({{at(7), {1, 2, 3, 4, 5}}});
  RecordedStream stream(port);
  stream.open();
  EXPECT_EQ(readOnce(stream, 3), (std::vector<uint8_t>{1, 2, 3}));
  const auto first_piece = stream.arrivalTime();
  EXPECT_EQ(readOnce(stream, 3), (std::vector<uint8_t>{4, 5}));
  EXPECT_EQ(stream.arrivalTime(), first_piece);
  EXPECT_EQ(port->stats().chunks_fed, 1u);
}

TEST(RecordedStream, WritesGoNowhereAndAreCounted) {
  auto port = portOf({{at(0), {0x01}}});
  RecordedStream stream(port);
  stream.open();
  const std::array<uint8_t, 4> frame{0xAA, 0x55, 0x00, 0x01};
  stream.write(frame.data(), frame.size());
  stream.write(frame.data(), 2);
  EXPECT_EQ(port->stats().writes_discarded, 2u);
  EXPECT_EQ(port->stats().bytes_discarded, 6u);
  EXPECT_EQ(readOnce(stream), (std::vector<uint8_t>{0x01}));  // nothing written is read back
}

TEST(RecordedStream, AChunkNotYetDueIsNotHandedOut) {
  // Rate 1: a chunk recorded an hour after the first is not due within the read's timeout.
  auto port = portOf({{at(0), {0x01}}, {at(3600000), {0x02}}}, 1.0);
  RecordedStream stream(port);
  stream.open();
  EXPECT_EQ(readOnce(stream), (std::vector<uint8_t>{0x01}));
  EXPECT_TRUE(readOnce(stream).empty());
  EXPECT_FALSE(port->finished());
}

TEST(ReplayPacing, MapsRecordedStampsOntoTheSteadyTimelineAndBackExactly) {
  ReplayPacing pacing(1.0, at(0), at(1000));
  const auto now = std::chrono::steady_clock::now();
  // The first chunk lies at the replay's start, near the steady clock's present (not at a
  // wall-clock reading decades away from it).
  EXPECT_LT(std::chrono::abs(pacing.onTimeline(at(0)) - now), std::chrono::seconds(60));
  EXPECT_EQ(pacing.onTimeline(at(250)) - pacing.onTimeline(at(0)), milliseconds(250));
  EXPECT_EQ(pacing.recordedAt(pacing.onTimeline(at(123))), at(123));
  EXPECT_EQ(pacing.end() - pacing.onTimeline(at(0)), milliseconds(1000));
}

TEST(ReplayPacing, ScalesTheWaitsNotTheTimeline) {
  ReplayPacing twice(2.0, at(0), at(1000));
  EXPECT_EQ(twice.steadyWait(milliseconds(1000)), milliseconds(500));
  EXPECT_EQ(twice.onTimeline(at(1000)) - twice.onTimeline(at(0)), milliseconds(1000));
  ReplayPacing flat_out(0.0, at(0), at(1000));
  EXPECT_EQ(flat_out.steadyWait(milliseconds(1000)), milliseconds(0));
}

// Rate 0: each port's clock stands at its next chunk, so the silence before it has passed by the
// time the link looks; after the last chunk it stands at the recording's end.
TEST(RecordedStream, AtFullSpeedTheClockJumpsToTheNextChunkThenToTheEnd) {
  ReplayUntil replay({{at(0), {0x01}}, {at(400), {0x02}}}, 0.0, at(900));
  RecordedStream& stream = replay.stream;
  const auto& pacing = replay.pacing;
  EXPECT_EQ(stream.now(), pacing->onTimeline(at(0)));
  readOnce(stream);
  EXPECT_EQ(stream.now(), pacing->onTimeline(at(400)));
  readOnce(stream);
  EXPECT_EQ(stream.now(), pacing->onTimeline(at(900)));
  EXPECT_TRUE(readOnce(stream).empty());
  EXPECT_TRUE(replay.port->finished());
}

// Paced: the port is finished only once the recording's end has been reached, silence included.
TEST(RecordedStream, APacedReplayRunsOnThroughTheSilenceAtTheEnd) {
  ReplayUntil replay({{at(0), {0x01}}}, 1.0, at(3600000));
  EXPECT_EQ(readOnce(replay.stream), (std::vector<uint8_t>{0x01}));
  EXPECT_TRUE(readOnce(replay.stream).empty());
  EXPECT_FALSE(replay.port->finished());
}

// Paced: however late the reader looks, the timeline stands at the next chunk it has not read
// (the live reader had those bytes by then), so a stale-frame timer counts the recorded silence
// before them and never more.
TEST(RecordedStream, APacedClockNeverRunsPastTheNextUnreadChunk) {
  ReplayUntil replay({{at(0), {0x01}}, {at(5), {0x02}}}, 1.0, at(900));
  RecordedStream& stream = replay.stream;
  const auto& pacing = replay.pacing;
  EXPECT_EQ(readOnce(stream), (std::vector<uint8_t>{0x01}));
  std::this_thread::sleep_for(milliseconds(20));  // a late reader: the timeline is past at(5)
  EXPECT_EQ(stream.now(), pacing->onTimeline(at(5)));
  EXPECT_EQ(readOnce(stream), (std::vector<uint8_t>{0x02}));
  EXPECT_GT(stream.now(), pacing->onTimeline(at(5)));  // past the last chunk it runs on
}

}  // namespace
}  // namespace serial_robot_driver::transport
