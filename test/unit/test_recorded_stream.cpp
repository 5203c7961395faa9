// transport::RecordedStream: a recorded port read back one chunk per read(), with the recorded
// arrival times, the recorded reopens as disconnects, and writes discarded.
#include <gtest/gtest.h>

#include <array>
#include <memory>
#include <vector>

#include "serial_robot_driver/transport/recorded_stream.h"

namespace serial_robot_driver::transport {
namespace {

using std::chrono::milliseconds;

SteadyTime at(int ms) { return SteadyTime(milliseconds(1000000 + ms)); }

std::shared_ptr<RecordedPort> portOf(std::vector<RecordedChunk> chunks, double rate = 0.0) {
  auto pacing =
      std::make_shared<ReplayPacing>(rate, chunks.empty() ? at(0) : chunks.front().arrival);
  return std::make_shared<RecordedPort>("/dev/ttyTEST", std::move(chunks), pacing);
}

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
  EXPECT_EQ(stream.arrivalTime(), at(5));
  EXPECT_EQ(readOnce(stream), (std::vector<uint8_t>{0x01}));
  EXPECT_EQ(stream.arrivalTime(), at(9));
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
  EXPECT_EQ(readOnce(stream, 3), (std::vector<uint8_t>{4, 5}));
  EXPECT_EQ(stream.arrivalTime(), at(7));
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

TEST(ReplayPacing, ScalesTheRecordedOffsets) {
  ReplayPacing twice(2.0, at(0));
  ReplayPacing flat_out(0.0, at(0));
  EXPECT_EQ(twice.dueAt(at(1000)) - twice.dueAt(at(0)), milliseconds(500));
  EXPECT_EQ(flat_out.dueAt(at(1000)), flat_out.dueAt(at(0)));
}

}  // namespace
}  // namespace serial_robot_driver::transport
