// SerialLink over a real pseudo-terminal: frames in through the reader thread, writes out,
// unplug (EIO) and replug at the same symlink, a port that appears only after start(), and a
// LinkWorker that writes a request and reads its answer on the reader thread.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <memory>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <thread>
#include <utility>
#include <vector>

#include "serial_robot_driver/core/serial_link.h"
#include "serial_robot_driver/devices/base/base_codec.h"
#include "serial_robot_driver/devices/servo_bus/servo_bus_codec.h"
#include "serial_robot_driver/sim/pseudo_terminal.h"
#include "serial_robot_driver/transport/recorded_stream.h"
#include "support/framer_configs.h"
#include "support/golden_frames.h"
#include "support/test_helpers.h"

namespace serial_robot_driver::core {
namespace {

using std::chrono::milliseconds;
using test_support::Bytes;
using test_support::waitFor;

class RecordingListener : public LinkListener {
 public:
  void onLinkUp() override { ++ups; }
  void onLinkDown() override { ++downs; }
  void onFrame(protocol::FrameFamily family, const uint8_t* data, std::size_t size,
               Clock::time_point) override {
    std::lock_guard<std::mutex> lock(mutex);
    frames.emplace_back(family, Bytes(data, data + size));
  }
  std::size_t frameCount() {
    std::lock_guard<std::mutex> lock(mutex);
    return frames.size();
  }

  std::atomic<int> ups{0};
  std::atomic<int> downs{0};
  std::mutex mutex;
  std::vector<std::pair<protocol::FrameFamily, Bytes>> frames;
};

constexpr double kWaitSeconds = 3.0;  // generous: the machine may be busy

std::string uniqueLinkPath(const char* name) {
  return "/tmp/srd_link_test_" + std::string(name) + "_" + std::to_string(::getpid());
}

SerialLinkOptions optionsFor(const std::string& path) {
  SerialLinkOptions options;
  options.path = path;
  options.reconnect_interval = 0.05;
  options.framer = test_support::driverFramer({"base", "body", "servo_bus"}, 2);
  return options;
}

/// What the driver wrote to the pty: `size` bytes, or fewer when they did not all come in time.
Bytes readWritten(sim::PseudoTerminal& pty, std::size_t size) {
  Bytes received(size);
  std::size_t got = 0;
  waitFor(
      [&] {
        got += pty.read(received.data() + got, size - got, 10);
        return got == size;
      },
      kWaitSeconds);
  received.resize(got);
  return received;
}

// Battery reply, 87 %, SEQ 00 and PING reply id 3.
const Bytes& kBatteryReply = golden::base::kBattery87ReplySeq0;
const Bytes& kPingReply = golden::servo::kPing3Reply;

TEST(SerialLink, GivesUpOnAStalePartialFrameAndDeliversTheFrameBehindIt) {
  const std::string path = uniqueLinkPath("stale");
  sim::PseudoTerminal pty(path);
  SerialLinkOptions options = optionsFor(path);
  options.stale_frame_timeout = milliseconds(50);
  SerialLink link(options);
  RecordingListener listener;
  link.addListener(&listener);
  link.start();
  ASSERT_TRUE(link.waitConnected(milliseconds(3000)));

  // A stray PING-answer header claiming N = 33, then the real answer: nothing more follows.
  Bytes stream = {0x05, 0x1C, 0x01, 0x21};
  stream.insert(stream.end(), kPingReply.begin(), kPingReply.end());
  pty.write(stream.data(), stream.size());
  ASSERT_TRUE(waitFor([&] { return listener.frameCount() == 1; }, kWaitSeconds));
  EXPECT_EQ(listener.frames[0].second, kPingReply);
  EXPECT_EQ(link.stats().framer.stale_candidates, 1u);
  link.stop();
}

// A port whose reader finds each chunk already waiting, stamped with the given arrival, its clock
// never ahead of the last one: a reader that a busy machine kept from bytes until after their
// stale-frame timeout, with no timer run out in between.
class LateReaderStream : public transport::ByteStream {
 public:
  using Chunks = std::vector<std::pair<Clock::time_point, Bytes>>;
  explicit LateReaderStream(std::shared_ptr<Chunks> chunks) : chunks_(std::move(chunks)) {}
  void open() override { open_ = true; }
  void close() override { open_ = false; }
  bool isOpen() const override { return open_; }
  std::size_t read(uint8_t* buffer, std::size_t capacity, int timeout_ms) override {
    if (next_ >= chunks_->size()) {
      std::this_thread::sleep_for(milliseconds(std::min(timeout_ms, 5)));
      return 0;
    }
    const auto& [arrival, bytes] = (*chunks_)[next_++];
    arrival_ = arrival;
    const std::size_t n = std::min(capacity, bytes.size());
    std::copy_n(bytes.begin(), n, buffer);
    return n;
  }
  void write(const uint8_t*, std::size_t) override {}
  std::string name() const override { return "late reader"; }
  std::optional<Clock::time_point> arrivalTime() const override { return arrival_; }
  Clock::time_point now() const override { return arrival_.value_or(Clock::now()); }

 private:
  std::shared_ptr<Chunks> chunks_;
  std::size_t next_ = 0;
  bool open_ = false;
  std::optional<Clock::time_point> arrival_;
};

// The stale-frame decision follows the bytes' arrival times, the ones a capture records, not
// whether the reader's timer ran out first: so a replay of the capture decides the same.
TEST(SerialLink, BytesArrivingATimeoutAfterAPartialFrameFindItStaleHoweverLateTheyAreRead) {
  SerialLinkOptions options = optionsFor("late reader");
  options.stale_frame_timeout = milliseconds(50);
  const Clock::time_point start = Clock::now();
  auto chunks = std::make_shared<LateReaderStream::Chunks>(LateReaderStream::Chunks{
      {start, {0x05, 0x1C, 0x01, 0x21}},  // a stray PING-answer header claiming N = 33
      {start + milliseconds(50), kPingReply}});
  SerialLink link(options, [chunks](const SerialLinkOptions&) {
    return std::make_unique<LateReaderStream>(chunks);
  });
  RecordingListener listener;
  link.addListener(&listener);
  link.start();
  ASSERT_TRUE(waitFor([&] { return listener.frameCount() == 1; }, kWaitSeconds));
  EXPECT_EQ(listener.frames[0].second, kPingReply);
  EXPECT_EQ(link.stats().framer.stale_candidates, 1u);
  link.stop();
}

// What a wire capture keeps of a live link: its inbound chunks with their times.
class InboundCapture : public ChunkObserver {
 public:
  void onChunk(const WireChunk& chunk) override {
    if (chunk.outbound) return;
    std::lock_guard<std::mutex> lock(mutex);
    // As a bag holds them: wall-clock stamps (a 2026 date plus the steady reading).
    const auto stamp = std::chrono::duration_cast<std::chrono::nanoseconds>(
        chunk.time.time_since_epoch() + std::chrono::seconds(1795000000));
    chunks.push_back({stamp, Bytes(chunk.data, chunk.data + chunk.size)});
  }
  std::vector<transport::RecordedChunk> taken() {
    std::lock_guard<std::mutex> lock(mutex);
    return chunks;
  }
  std::mutex mutex;
  std::vector<transport::RecordedChunk> chunks;
};

void expectSameCounters(const protocol::FramerStats& replayed, const protocol::FramerStats& live) {
  EXPECT_EQ(replayed.bytes_in, live.bytes_in);
  EXPECT_EQ(replayed.bytes_skipped, live.bytes_skipped);
  EXPECT_EQ(replayed.checksum_errors, live.checksum_errors);
  EXPECT_EQ(replayed.unknown_commands, live.unknown_commands);
  EXPECT_EQ(replayed.stale_candidates, live.stale_candidates);
  ASSERT_EQ(replayed.family_count, live.family_count);
  for (std::size_t i = 0; i < live.family_count; ++i) {
    EXPECT_STREQ(replayed.by_family[i].family, live.by_family[i].family);
    EXPECT_EQ(replayed.by_family[i].frames, live.by_family[i].frames);
  }
}

// A partial frame followed by silence, live on a pty and captured; then that capture replayed at
// full speed and at the recorded pace: the stale-frame timer must fire in the replay just as it
// did live (the recorded silence counts on the replay's timeline), with the same counters. Two
// silences: one before the next frame, one at the end of the capture.
TEST(SerialLink, ACapturedSilenceReplaysWithTheLiveCounters) {
  const std::string path = uniqueLinkPath("capture");
  SerialLinkOptions options = optionsFor(path);
  options.stale_frame_timeout = milliseconds(100);
  const Bytes stray_header = {0x05, 0x1C, 0x01, 0x21};  // a PING answer claiming N = 33

  InboundCapture capture;
  protocol::FramerStats live;
  std::chrono::nanoseconds capture_end{};
  {
    sim::PseudoTerminal pty(path);
    SerialLink link(options);
    RecordingListener listener;
    link.addListener(&listener);
    link.setChunkObserver(&capture);
    link.start();
    ASSERT_TRUE(link.waitConnected(milliseconds(3000)));
    pty.write(stray_header.data(), stray_header.size());
    ASSERT_TRUE(waitFor([&] { return link.stats().framer.stale_candidates == 1; }, kWaitSeconds));
    pty.write(kPingReply.data(), kPingReply.size());
    ASSERT_TRUE(waitFor([&] { return listener.frameCount() == 1; }, kWaitSeconds));
    pty.write(stray_header.data(), 2);  // half a header, and nothing after it
    ASSERT_TRUE(waitFor([&] { return link.stats().framer.stale_candidates == 2; }, kWaitSeconds));
    capture_end = std::chrono::duration_cast<std::chrono::nanoseconds>(
        Clock::now().time_since_epoch() + std::chrono::seconds(1795000000));
    live = link.stats().framer;
    link.stop();
  }
  const std::vector<transport::RecordedChunk> chunks = capture.taken();
  ASSERT_GE(chunks.size(), 4u);  // the open mark and three writes (a write may split)

  for (double rate : {0.0, 1.0}) {
    SCOPED_TRACE("rate " + std::to_string(rate));
    auto pacing =
        std::make_shared<transport::ReplayPacing>(rate, chunks.front().recorded, capture_end);
    auto port = std::make_shared<transport::RecordedPort>(path, chunks, pacing);
    SerialLink link(options, [port](const SerialLinkOptions&) {
      return std::make_unique<transport::RecordedStream>(port);
    });
    RecordingListener listener;
    link.addListener(&listener);
    pacing->restart();
    link.start();
    ASSERT_TRUE(waitFor([&] { return port->finished(); }, 10.0));
    const protocol::FramerStats replayed = link.stats().framer;
    link.stop();
    EXPECT_EQ(listener.frameCount(), 1u);
    expectSameCounters(replayed, live);
  }
}

TEST(SerialLink, DeliversFramesAndWritesBytes) {
  const std::string path = uniqueLinkPath("basic");
  sim::PseudoTerminal pty(path);
  SerialLink link(optionsFor(path));
  RecordingListener listener;
  link.addListener(&listener);
  link.start();
  ASSERT_TRUE(link.waitConnected(milliseconds(3000)));
  EXPECT_EQ(listener.ups, 1);

  Bytes stream = {0x00, 0x13};  // junk first
  stream.insert(stream.end(), kBatteryReply.begin(), kBatteryReply.end());
  stream.insert(stream.end(), kPingReply.begin(), kPingReply.end());
  pty.write(stream.data(), stream.size());
  ASSERT_TRUE(waitFor([&] { return listener.frameCount() == 2; }, kWaitSeconds));
  EXPECT_EQ(listener.frames[0].first, devices::base::kFrames);
  EXPECT_EQ(listener.frames[0].second, kBatteryReply);
  EXPECT_EQ(listener.frames[1].first, devices::servo_bus::kResponseFrames);
  EXPECT_EQ(listener.frames[1].second, kPingReply);

  const Bytes& reset = golden::base::kResetSeq2;
  ASSERT_TRUE(link.write(reset));
  EXPECT_EQ(readWritten(pty, reset.size()), reset);

  const LinkStats stats = link.stats();
  EXPECT_TRUE(stats.connected);
  EXPECT_EQ(stats.frames_out, 1u);
  EXPECT_EQ(stats.framer.bytes_skipped, 2u);
  link.stop();
}

// With nothing due, the reader of a wakeable port waits without a timer, so stop() must end that
// wait itself (a reader that missed it would hang here, and ctest's time-out fails the test). The
// port is up and has just delivered a frame: the reader is back in its wait, not reopening.
TEST(SerialLink, StopEndsAReaderWaitingWithoutATimer) {
  const std::string path = uniqueLinkPath("untimed");
  sim::PseudoTerminal pty(path);
  SerialLink link(optionsFor(path));
  RecordingListener listener;
  link.addListener(&listener);
  link.start();
  ASSERT_TRUE(link.waitConnected(milliseconds(3000)));
  pty.write(kPingReply.data(), kPingReply.size());
  ASSERT_TRUE(waitFor([&] { return listener.frameCount() == 1; }, kWaitSeconds));

  link.stop();
  EXPECT_EQ(listener.downs, 1);
  EXPECT_FALSE(link.stats().connected);
}

/// A listener with a bug: it throws on its first frame and on the link coming up (when asked to).
class ThrowingListener : public RecordingListener {
 public:
  explicit ThrowingListener(bool throw_on_link_up) : throw_on_link_up_(throw_on_link_up) {}
  void onLinkUp() override {
    RecordingListener::onLinkUp();
    if (throw_on_link_up_) throw std::runtime_error("link up went wrong");
  }
  void onFrame(protocol::FrameFamily family, const uint8_t* data, std::size_t size,
               Clock::time_point arrival) override {
    RecordingListener::onFrame(family, data, size, arrival);
    if (frameCount() == 1) throw std::out_of_range("vector::_M_range_check");
  }

 private:
  const bool throw_on_link_up_;
};

TEST(SerialLink, AListenerThatThrowsLosesItsFrameNotTheReaderNorTheOtherListeners) {
  const std::string path = uniqueLinkPath("throwing");
  sim::PseudoTerminal pty(path);
  SerialLink link(optionsFor(path));
  ThrowingListener buggy(true);
  RecordingListener after;  // after the buggy one: it must still get every frame
  link.addListener(&buggy);
  link.addListener(&after);
  link.start();
  ASSERT_TRUE(link.waitConnected(milliseconds(3000)));
  ASSERT_TRUE(waitFor([&] { return after.ups == 1; }, kWaitSeconds));

  pty.write(kBatteryReply.data(), kBatteryReply.size());
  ASSERT_TRUE(waitFor([&] { return after.frameCount() == 1; }, kWaitSeconds));
  pty.write(kPingReply.data(), kPingReply.size());
  ASSERT_TRUE(waitFor([&] { return after.frameCount() == 2; }, kWaitSeconds))
      << "the reader went on after the exception";
  EXPECT_EQ(buggy.frameCount(), 2u);
  EXPECT_EQ(after.frames[1].second, kPingReply);

  const LinkStats stats = link.stats();
  EXPECT_TRUE(stats.connected);
  EXPECT_EQ(stats.handler_errors, 2u) << "the link coming up and the first frame";
  EXPECT_EQ(stats.last_handler_error, "a frame's listener: vector::_M_range_check");
  // The port still writes: nothing took it down.
  ASSERT_TRUE(link.write(golden::base::kResetSeq2));
  EXPECT_EQ(readWritten(pty, golden::base::kResetSeq2.size()), golden::base::kResetSeq2);
  link.stop();
}

/// A worker with a bug: its first work() throws; the reader asks it again when woken.
class ThrowingWorker : public LinkWorker {
 public:
  Clock::time_point nextWork() override {
    return armed ? Clock::time_point::min() : Clock::time_point::max();
  }
  void work() override {
    armed = false;
    if (++calls == 1) throw std::runtime_error("transaction went wrong");
  }
  std::atomic<bool> armed{false};
  std::atomic<int> calls{0};
};

TEST(SerialLink, AWorkerThatThrowsIsCountedAndTheReaderGoesOn) {
  const std::string path = uniqueLinkPath("throwing_worker");
  sim::PseudoTerminal pty(path);
  SerialLink link(optionsFor(path));
  RecordingListener listener;
  ThrowingWorker worker;
  link.addListener(&listener);
  link.setWorker(&worker);
  link.start();
  ASSERT_TRUE(link.waitConnected(milliseconds(3000)));
  for (int round = 1; round <= 2; ++round) {
    worker.armed = true;
    link.wake();
    ASSERT_TRUE(waitFor([&] { return worker.calls == round; }, kWaitSeconds));
  }
  pty.write(kPingReply.data(), kPingReply.size());
  ASSERT_TRUE(waitFor([&] { return listener.frameCount() == 1; }, kWaitSeconds));
  const LinkStats stats = link.stats();
  EXPECT_EQ(stats.handler_errors, 1u);
  EXPECT_EQ(stats.last_handler_error, "the port's worker: transaction went wrong");
  link.stop();
}

TEST(SerialLink, RecoversAfterUnplugAtTheSameSymlink) {
  const std::string path = uniqueLinkPath("unplug");
  auto pty = std::make_unique<sim::PseudoTerminal>(path);
  SerialLink link(optionsFor(path));
  RecordingListener listener;
  link.addListener(&listener);
  link.start();
  ASSERT_TRUE(link.waitConnected(milliseconds(3000)));

  pty->close();  // the driver's reads now fail with EIO: an unplugged adapter
  ASSERT_TRUE(waitFor([&] { return listener.downs == 1; }, kWaitSeconds));
  EXPECT_FALSE(link.connected());
  EXPECT_FALSE(link.write(kBatteryReply)) << "writes fail fast while the port is gone";

  pty = std::make_unique<sim::PseudoTerminal>(path);
  ASSERT_TRUE(waitFor([&] { return link.connected(); }, kWaitSeconds));
  EXPECT_EQ(listener.ups, 2) << "listeners hear of the reconnect before the link reports it";
  pty->write(kPingReply.data(), kPingReply.size());
  ASSERT_TRUE(waitFor([&] { return listener.frameCount() == 1; }, kWaitSeconds));
  const LinkStats stats = link.stats();
  EXPECT_EQ(stats.connects, 2u);
  EXPECT_EQ(stats.disconnects, 1u);
  EXPECT_GE(stats.write_failures, 1u);
  link.stop();
}

// A request/response worker as the servo bus runs on the link: armed from another thread, it
// writes a PING on the reader thread and pumps the port there until the answer has reached the
// listeners.
class PingWorker : public LinkWorker {
 public:
  explicit PingWorker(SerialLink& link, RecordingListener& listener)
      : link_(link), listener_(listener) {}
  Clock::time_point nextWork() override {
    return armed ? Clock::time_point::min() : Clock::time_point::max();
  }
  void work() override {
    armed = false;
    on_reader_thread = link_.onReaderThread();
    const std::size_t before = listener_.frameCount();
    ASSERT_TRUE(link_.write(golden::servo::kPing3));
    const Clock::time_point deadline = Clock::now() + std::chrono::seconds(3);
    while (listener_.frameCount() == before && Clock::now() < deadline) {
      if (!link_.pump(deadline)) {
        pump_failed = true;
        break;
      }
    }
    answered_inside_work = listener_.frameCount() > before;
    ++done;
  }

  std::atomic<bool> armed{false};
  std::atomic<int> done{0};
  std::atomic<bool> on_reader_thread{false};
  std::atomic<bool> answered_inside_work{false};
  std::atomic<bool> pump_failed{false};

 private:
  SerialLink& link_;
  RecordingListener& listener_;
};

TEST(SerialLink, AWorkerWritesAndReadsItsAnswerOnTheReaderThread) {
  const std::string path = uniqueLinkPath("worker");
  sim::PseudoTerminal pty(path);
  SerialLink link(optionsFor(path));
  RecordingListener listener;
  PingWorker worker(link, listener);
  link.addListener(&listener);
  link.setWorker(&worker);
  link.start();
  ASSERT_TRUE(link.waitConnected(milliseconds(3000)));
  EXPECT_FALSE(link.onReaderThread());

  // The idle reader sleeps in its read (seconds at a time); wake() makes it ask the worker now.
  for (int round = 1; round <= 2; ++round) {
    worker.armed = true;
    link.wake();
    ASSERT_EQ(readWritten(pty, golden::servo::kPing3.size()), golden::servo::kPing3);
    // Junk, then the answer split in two writes: the pump frames it like the reader's own loop.
    const Bytes junk = {0xAA, 0x05};
    pty.write(junk.data(), junk.size());
    pty.write(kPingReply.data(), 3);
    pty.write(kPingReply.data() + 3, kPingReply.size() - 3);
    ASSERT_TRUE(waitFor([&] { return worker.done == round; }, kWaitSeconds));
    EXPECT_TRUE(worker.on_reader_thread);
    EXPECT_TRUE(worker.answered_inside_work) << "the answer reached the listener during pump()";
    EXPECT_FALSE(worker.pump_failed);
  }
  EXPECT_EQ(listener.frameCount(), 2u);
  EXPECT_EQ(listener.frames[1].second, kPingReply);
  link.stop();
}

TEST(SerialLink, APumpReportsAnUnpluggedPortAndTheLinkReopensIt) {
  const std::string path = uniqueLinkPath("worker_unplug");
  auto pty = std::make_unique<sim::PseudoTerminal>(path);
  SerialLink link(optionsFor(path));
  RecordingListener listener;
  PingWorker worker(link, listener);
  link.addListener(&listener);
  link.setWorker(&worker);
  link.start();
  ASSERT_TRUE(link.waitConnected(milliseconds(3000)));

  worker.armed = true;
  link.wake();
  ASSERT_EQ(readWritten(*pty, golden::servo::kPing3.size()), golden::servo::kPing3);
  pty->close();  // unplugged while the worker waits for its answer
  ASSERT_TRUE(waitFor([&] { return worker.done == 1; }, kWaitSeconds));
  EXPECT_TRUE(worker.pump_failed) << "the wait ends with the port, not at its deadline";
  EXPECT_FALSE(worker.answered_inside_work);
  EXPECT_EQ(listener.downs, 1);

  pty = std::make_unique<sim::PseudoTerminal>(path);
  ASSERT_TRUE(waitFor([&] { return link.connected(); }, kWaitSeconds));
  EXPECT_EQ(listener.ups, 2);
  link.stop();
}

TEST(SerialLink, WaitsForAPortThatDoesNotExistYet) {
  const std::string path = uniqueLinkPath("late");
  ::unlink(path.c_str());
  SerialLink link(optionsFor(path));
  RecordingListener listener;
  link.addListener(&listener);
  link.start();
  std::this_thread::sleep_for(milliseconds(150));
  EXPECT_FALSE(link.connected());
  EXPECT_NE(link.stats().last_error.find(path), std::string::npos) << link.stats().last_error;

  sim::PseudoTerminal pty(path);
  ASSERT_TRUE(link.waitConnected(milliseconds(3000)));
  link.stop();
  EXPECT_FALSE(link.connected());
}

}  // namespace
}  // namespace serial_robot_driver::core
