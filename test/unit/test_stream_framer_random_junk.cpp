// StreamFramer on random junk: never a frame its decoder rejects, good frames survive.
#include <gtest/gtest.h>

#include "support/stream_framer_recording.h"

namespace serial_robot_driver::protocol {
namespace {

using namespace stream_framer_test;  // NOLINT: the shared fixture

// --- random junk
// -----------------------------------------------------------------------------------

// Checks a frame the framer emitted against the family's own decoder.
void expectDecoderAccepts(const Frame& frame) {
  const uint8_t* data = frame.bytes.data();
  const std::size_t size = frame.bytes.size();
  const auto expectOk = [](const auto& decoded) {
    EXPECT_TRUE(decoded.ok()) << toString(decoded.error());
  };
  if (frame.family == devices::base::kFrames) {
    expectOk(devices::base::decodeFrame(data, size));
  } else if (frame.family == devices::body::kTelemetryFrames) {
    expectOk(devices::body::decodeTelemetry(data, size, kServoCount));
  } else if (frame.family == devices::servo_bus::kResponseFrames) {
    expectOk(devices::servo_bus::decodeResponse(data, size));
  } else if (frame.family == devices::servo_bus::kRequestFrames) {
    expectOk(devices::servo_bus::decodeRequest(data, size));
  } else if (frame.family == devices::body::kSyncWriteFrames) {
    expectOk(devices::body::decodeSyncWrite(data, size));
  } else {
    ADD_FAILURE() << "a frame of family " << frame.family.name;
  }
}

TEST(StreamFramerJunk, UniformRandomBytesNeverYieldABadFrame) {
  std::mt19937 rng(12345);
  std::uniform_int_distribution<int> byte(0, 255);
  Bytes junk(1 << 20);
  for (uint8_t& b : junk) b = static_cast<uint8_t>(byte(rng));
  RecordingFramer framer(allFamilies());
  framer.feedInRandomChunks(junk, &rng, 1000);
  for (const Frame& frame : framer.frames()) expectDecoderAccepts(frame);
  expectBytesAccountedFor(framer, framer.framer().buffered());
  EXPECT_GT(framer.stats().bytes_skipped, junk.size() / 2);
}

TEST(StreamFramerJunk, HeaderRichRandomBytesNeverYieldABadFrame) {
  // Bytes drawn mostly from the headers and small lengths, so that candidates are everywhere and
  // some pass their 8-bit check by chance: those must still satisfy the decoders.
  const Bytes alphabet = {0x55, 0xAA, 0x12, 0x34, 0x4C, 0x05, 0x1C, 0xFF, 0xFD, 0x00, 0xFE,
                          0x83, 0x01, 0x02, 0x03, 0x07, 0x0A, 0x0D, 0x20, 0x30, 0x1F, 0x2F};
  std::mt19937 rng(777);
  std::uniform_int_distribution<std::size_t> pick(0, alphabet.size() - 1);
  std::uniform_int_distribution<int> byte(0, 255);
  Bytes junk(1 << 19);
  for (uint8_t& b : junk) {
    b = (rng() % 4 == 0) ? static_cast<uint8_t>(byte(rng)) : alphabet[pick(rng)];
  }
  RecordingFramer framer(allFamilies());
  framer.feedInRandomChunks(junk, &rng, 64);
  for (const Frame& frame : framer.frames()) expectDecoderAccepts(frame);
  expectBytesAccountedFor(framer, framer.framer().buffered());
  EXPECT_GT(totalFrames(framer.stats()), 0u);  // the test exercised the emit path
  EXPECT_GT(framer.stats().checksum_errors, 0u);
  EXPECT_GT(framer.stats().bad_lengths, 0u);
}

TEST(StreamFramerJunk, GoodFramesSurviveBeingSurroundedByJunk) {
  std::mt19937 rng(99);
  std::uniform_int_distribution<int> byte(0, 255);
  const MixedStream stream = mixedStream();
  Bytes bytes;
  for (int i = 0; i < 50; ++i) {
    for (int j = 0; j < 300; ++j) bytes.push_back(static_cast<uint8_t>(byte(rng)));
    bytes.insert(bytes.end(), stream.bytes.begin(), stream.bytes.end());
  }
  RecordingFramer framer(allFamilies());
  framer.feedInRandomChunks(bytes, &rng, 100);
  // Junk may hide a frame only by forming a longer candidate that swallows it and then passes its
  // check, which random bytes practically never do: every good frame must come through.
  std::size_t found = 0;
  for (const Frame& frame : framer.frames()) {
    expectDecoderAccepts(frame);
    if (found < 50 * stream.frames.size() && frame == stream.frames[found % stream.frames.size()]) {
      ++found;
    }
  }
  EXPECT_EQ(found, 50 * stream.frames.size());
}

}  // namespace
}  // namespace serial_robot_driver::protocol
