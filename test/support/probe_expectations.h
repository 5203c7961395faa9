// Expectations on a codec's probe (what the stream framer asks), shared by the codec unit tests.
#pragma once

#include <gtest/gtest.h>

#include <cstddef>

#include "serial_robot_driver/protocol/decode_result.h"
#include "support/test_helpers.h"

namespace test_support {

/// Every proper prefix of a complete frame needs more bytes; the whole frame, also with trailing
/// bytes of the next one, is a frame of exactly its size.
template <typename ProbeFn>
void expectProbeFindsFrame(ProbeFn probe, const Bytes& frame) {
  using serial_robot_driver::protocol::Probe;
  for (std::size_t size = 0; size < frame.size(); ++size) {
    EXPECT_EQ(probe(frame.data(), size).status, Probe::Status::kNeedMore) << "prefix " << size;
  }
  Bytes longer = frame;
  longer.push_back(frame[0]);
  const Bytes* const candidates[] = {&frame, &longer};
  for (const Bytes* bytes : candidates) {
    const Probe result = probe(bytes->data(), bytes->size());
    EXPECT_EQ(result.status, Probe::Status::kFrame);
    EXPECT_EQ(result.size, frame.size());
  }
}

/// The probe rejects `bytes` for `reason`.
template <typename ProbeFn>
void expectProbeRejects(ProbeFn probe, const Bytes& bytes,
                        serial_robot_driver::protocol::DecodeError reason) {
  using serial_robot_driver::protocol::Probe;
  const Probe result = probe(bytes.data(), bytes.size());
  EXPECT_EQ(result.status, Probe::Status::kInvalid);
  EXPECT_EQ(result.reason, reason) << serial_robot_driver::protocol::toString(result.reason);
}

}  // namespace test_support
