// Throughput of the inbound path: the stream framer on a realistic mixed stream, and the decoders.
// Run: ./bench_framer  (prints bytes/s, frames/s and heap allocations per frame).
//
// A counting global operator new shows that framing (and decoding telemetry) allocates nothing per
// frame in steady state; the counter `allocs_per_frame` must read 0 for the framer benchmarks.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <cstdlib>
#include <new>
#include <random>
#include <vector>

#include "serial_robot_driver/devices/base/base_codec.h"
#include "serial_robot_driver/devices/body/body_codec.h"
#include "serial_robot_driver/devices/servo_bus/servo_bus_codec.h"
#include "serial_robot_driver/protocol/stream_framer.h"
#include "support/framer_configs.h"

namespace {
std::atomic<uint64_t> g_allocations{0};
}  // namespace

// Counting replacements of the global allocation functions (every other form forwards to these).
// They are kept out of line: once inlined, GCC pairs malloc()/free() with the other side's
// operator call and warns about a mismatch that is not there.
__attribute__((noinline)) void* operator new(std::size_t size) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(size == 0 ? 1 : size)) return p;
  throw std::bad_alloc();
}
__attribute__((noinline)) void* operator new[](std::size_t size) { return operator new(size); }
__attribute__((noinline)) void operator delete(void* p) noexcept { std::free(p); }
__attribute__((noinline)) void operator delete[](void* p) noexcept { std::free(p); }
__attribute__((noinline)) void operator delete(void* p, std::size_t) noexcept { std::free(p); }
__attribute__((noinline)) void operator delete[](void* p, std::size_t) noexcept { std::free(p); }

namespace {

using serial_robot_driver::protocol::FrameFamily;
using serial_robot_driver::protocol::FramerConfig;
using serial_robot_driver::protocol::StreamFramer;
namespace base = serial_robot_driver::devices::base;
namespace body = serial_robot_driver::devices::body;
namespace servo_bus = serial_robot_driver::devices::servo_bus;

using Bytes = std::vector<uint8_t>;

constexpr std::size_t kServoCount = 20;
constexpr std::size_t kStreamBytes = 1 << 20;

body::Telemetry sampleTelemetry(int step) {
  body::Telemetry telemetry;
  telemetry.servo_count = kServoCount;
  for (std::size_t i = 0; i < kServoCount; ++i) {
    telemetry.servos[i].position = static_cast<uint16_t>(2048 + 10 * i + step);
    telemetry.servos[i].speed = static_cast<int16_t>(static_cast<int>(i) - 10);
  }
  for (std::size_t k = 0; k < body::kImuValueCount; ++k) {
    telemetry.imu[k] = static_cast<int16_t>(100 * k - step);
  }
  telemetry.has_foot = (step % 2) == 0;
  for (std::size_t j = 0; j < body::kFootSensorCount; ++j) {
    telemetry.foot[j] = static_cast<uint16_t>(300 + j);
  }
  return telemetry;
}

void append(Bytes* stream, const Bytes& frame) {
  stream->insert(stream->end(), frame.begin(), frame.end());
}

// What one port shared by all three devices carries: mostly telemetry (20 servos, with and
// without foot data), base replies, servo bus answers plus the echo of our requests, and a few
// bytes of line noise now and then.
struct MixedStream {
  Bytes bytes;
  uint64_t frames = 0;
};

const MixedStream& mixedStream() {
  static const MixedStream stream = [] {
    MixedStream s;
    std::mt19937 rng(42);
    std::uniform_int_distribution<int> noise(0, 255);
    int step = 0;
    while (s.bytes.size() < kStreamBytes) {
      for (int i = 0; i < 8; ++i) {
        append(&s.bytes, body::encodeTelemetry(sampleTelemetry(step++)));
        ++s.frames;
      }
      append(&s.bytes, base::encodeBatteryReply(static_cast<uint8_t>(step), 87));
      append(&s.bytes, servo_bus::encodeReadAngle(3));  // half-duplex echo
      append(&s.bytes, servo_bus::encodeResponse(servo_bus::Command::kReadAngle, {3, 0x86, 0x03}));
      append(&s.bytes, servo_bus::encodePing(4));
      append(&s.bytes, servo_bus::encodeResponse(servo_bus::Command::kPing, {4}));
      s.frames += 5;
      if (step % 32 == 0) {
        for (int i = 0; i < 3; ++i) s.bytes.push_back(static_cast<uint8_t>(noise(rng)));
      }
    }
    return s;
  }();
  return stream;
}

FramerConfig driverConfig() {
  return test_support::driverFramer({"base", "body", "servo_bus"}, kServoCount);
}

// Framer over the mixed stream, fed in chunks of state.range(0) bytes (a serial read returns small
// chunks; a backlog after a stall returns big ones).
void BM_FramerMixedStream(benchmark::State& state) {
  const MixedStream& stream = mixedStream();
  const std::size_t chunk = static_cast<std::size_t>(state.range(0));
  uint64_t frames = 0;
  uint64_t frame_bytes = 0;
  StreamFramer framer(driverConfig(), [&](FrameFamily, const uint8_t*, std::size_t size) {
    ++frames;
    frame_bytes += size;
  });
  const uint64_t allocations_before = g_allocations.load();
  for (auto _ : state) {
    for (std::size_t pos = 0; pos < stream.bytes.size(); pos += chunk) {
      const std::size_t n = std::min(chunk, stream.bytes.size() - pos);
      framer.feed(stream.bytes.data() + pos, n);
    }
    benchmark::DoNotOptimize(frame_bytes);
  }
  const uint64_t allocations = g_allocations.load() - allocations_before;
  if (frames != stream.frames * static_cast<uint64_t>(state.iterations())) {
    state.SkipWithError("framer lost frames");
  }
  state.SetBytesProcessed(static_cast<int64_t>(stream.bytes.size()) * state.iterations());
  state.counters["frames/s"] =
      benchmark::Counter(static_cast<double>(frames), benchmark::Counter::kIsRate);
  state.counters["allocs_per_frame"] =
      static_cast<double>(allocations) / static_cast<double>(frames == 0 ? 1 : frames);
  state.counters["skipped"] =
      static_cast<double>(framer.stats().bytes_skipped) / static_cast<double>(state.iterations());
}
BENCHMARK(BM_FramerMixedStream)->Arg(1)->Arg(64)->Arg(512)->Arg(4096)->Arg(kStreamBytes);

// The whole inbound path: framing plus decoding every frame into its struct.
void BM_FramerAndDecodeMixedStream(benchmark::State& state) {
  const MixedStream& stream = mixedStream();
  uint64_t frames = 0;
  uint64_t decoded_ok = 0;
  StreamFramer framer(driverConfig(),
                      [&](const FrameFamily& family, const uint8_t* data, std::size_t size) {
                        ++frames;
                        if (family == body::kTelemetryFrames) {
                          decoded_ok += body::decodeTelemetry(data, size, kServoCount).ok();
                        } else if (family == base::kFrames) {
                          decoded_ok += base::decodeFrame(data, size).ok();
                        } else if (family == servo_bus::kResponseFrames) {
                          decoded_ok += servo_bus::decodeResponse(data, size).ok();
                        } else if (family == servo_bus::kRequestFrames) {
                          decoded_ok += servo_bus::decodeRequest(data, size).ok();
                        }
                      });
  constexpr std::size_t kChunk = 512;
  const uint64_t allocations_before = g_allocations.load();
  for (auto _ : state) {
    for (std::size_t pos = 0; pos < stream.bytes.size(); pos += kChunk) {
      framer.feed(stream.bytes.data() + pos, std::min(kChunk, stream.bytes.size() - pos));
    }
    benchmark::DoNotOptimize(decoded_ok);
  }
  const uint64_t allocations = g_allocations.load() - allocations_before;
  if (decoded_ok != frames) state.SkipWithError("a framed frame failed its decoder");
  state.SetBytesProcessed(static_cast<int64_t>(stream.bytes.size()) * state.iterations());
  state.counters["frames/s"] =
      benchmark::Counter(static_cast<double>(frames), benchmark::Counter::kIsRate);
  state.counters["allocs_per_frame"] =
      static_cast<double>(allocations) / static_cast<double>(frames == 0 ? 1 : frames);
}
BENCHMARK(BM_FramerAndDecodeMixedStream);

// Worst case: nothing but line noise (every header byte starts a candidate that must be rejected).
void BM_FramerRandomJunk(benchmark::State& state) {
  Bytes junk(kStreamBytes);
  std::mt19937 rng(7);
  std::uniform_int_distribution<int> byte(0, 255);
  for (uint8_t& b : junk) b = static_cast<uint8_t>(byte(rng));
  uint64_t frames = 0;
  StreamFramer framer(driverConfig(), [&](FrameFamily, const uint8_t*, std::size_t) { ++frames; });
  for (auto _ : state) {
    for (std::size_t pos = 0; pos < junk.size(); pos += 512) {
      framer.feed(junk.data() + pos, std::min<std::size_t>(512, junk.size() - pos));
    }
    benchmark::DoNotOptimize(frames);
  }
  state.SetBytesProcessed(static_cast<int64_t>(junk.size()) * state.iterations());
}
BENCHMARK(BM_FramerRandomJunk);

// --- decoders ----------------------------------------------------------------------------------

template <typename Decode>
void runDecoder(benchmark::State& state, const Bytes& frame, Decode decode) {
  const uint64_t allocations_before = g_allocations.load();
  for (auto _ : state) {
    auto decoded = decode(frame.data(), frame.size());
    if (!decoded.ok()) state.SkipWithError("decode failed");
    benchmark::DoNotOptimize(decoded);
  }
  const uint64_t allocations = g_allocations.load() - allocations_before;
  state.SetBytesProcessed(static_cast<int64_t>(frame.size()) * state.iterations());
  state.counters["frames/s"] =
      benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
  state.counters["allocs_per_frame"] =
      static_cast<double>(allocations) / static_cast<double>(state.iterations());
}

void BM_DecodeTelemetry20Servos(benchmark::State& state) {
  const Bytes frame = body::encodeTelemetry(sampleTelemetry(1));  // no foot block
  runDecoder(state, frame, [](const uint8_t* data, std::size_t size) {
    return body::decodeTelemetry(data, size, kServoCount);
  });
}
BENCHMARK(BM_DecodeTelemetry20Servos);

void BM_DecodeTelemetry20ServosFoot(benchmark::State& state) {
  const Bytes frame = body::encodeTelemetry(sampleTelemetry(0));  // with the foot block
  runDecoder(state, frame, [](const uint8_t* data, std::size_t size) {
    return body::decodeTelemetry(data, size, kServoCount);
  });
}
BENCHMARK(BM_DecodeTelemetry20ServosFoot);

void BM_DecodeBaseFrame(benchmark::State& state) {
  runDecoder(state, base::encodeBatteryReply(1, 87), base::decodeFrame);
}
BENCHMARK(BM_DecodeBaseFrame);

void BM_DecodeServoResponse(benchmark::State& state) {
  runDecoder(state, servo_bus::encodeResponse(servo_bus::Command::kReadAngle, {3, 0x86, 0x03}),
             servo_bus::decodeResponse);
}
BENCHMARK(BM_DecodeServoResponse);

// The simulator's side: sync write of 20 servos (its result is a vector, so it allocates once).
void BM_DecodeSyncWrite20Servos(benchmark::State& state) {
  std::vector<body::ServoTarget> targets;
  for (uint8_t id = 1; id <= kServoCount; ++id) targets.push_back({id, 2048});
  runDecoder(state, body::encodeSyncWrite(targets), body::decodeSyncWrite);
}
BENCHMARK(BM_DecodeSyncWrite20Servos);

}  // namespace

BENCHMARK_MAIN();
