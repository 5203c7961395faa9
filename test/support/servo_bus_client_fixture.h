// The ServoBusClient test fixture: a fake bus whose write seam records every frame and answers
// synchronously (or from a thread of its own) by calling onFrame() with response bytes written
// out by hand from docs/protocols.md, section 3.
#pragma once

#include <gtest/gtest.h>

#include <chrono>
#include <map>
#include <mutex>
#include <thread>
#include <utility>
#include <vector>

#include "serial_robot_driver/devices/servo_bus/servo_bus_client.h"
#include "support/golden_frames.h"

namespace serial_robot_driver::devices::servo_bus {

using Bytes = std::vector<uint8_t>;
using protocol::FrameFamily;

using namespace golden::servo;  // NOLINT: the frames shared with the rostest

// --- more golden frames (docs/protocols.md, section 3; SUM = byte sum mod 256, values
// little-endian) -
const Bytes kPing5Reply = {0x05, 0x1C, 0x01, 0x01, 0x05, 0x28};
// A PING answer with two content bytes: right CMD and id, wrong shape.
const Bytes kPing3ReplyTooLong = {0x05, 0x1C, 0x01, 0x02, 0x03, 0x00, 0x27};

// WRITE_DATA id 3 soft_start_time: refused (result 0), and a read-back of 200.
const Bytes kWriteSoftStart3Failed = {0x05, 0x1C, 0x04, 0x03, 0x03, 0x32, 0x00, 0x5D};
const Bytes kReadSoftStart3Reply200 = {0x05, 0x1C, 0x03, 0x04, 0x03, 0x32, 0xC8, 0x00, 0x25};

// The bus: records what the client writes and plays the servos by answering synchronously.
class FakeBus {
 public:
  bool connected = true;
  bool echo = false;  // send our own request back first, like a half-duplex adapter
  bool drop_link_on_write = false;
  bool from_other_thread = false;  // answer from a thread of its own, like the link's reader
  ServoBusClient* client = nullptr;
  std::vector<Bytes> written;

  ~FakeBus() { joinAnswerThreads(); }
  void joinAnswerThreads() {
    for (std::thread& thread : answer_threads_) thread.join();
    answer_threads_.clear();
  }

  /// After `request`, deliver `frames`, starting with its `first_answered_write`-th occurrence.
  void answer(const Bytes& request, std::vector<Bytes> frames, int first_answered_write = 1) {
    script_[request] = Script{std::move(frames), first_answered_write, 0};
  }

  bool write(const Bytes& frame) {
    if (!connected) return false;
    std::lock_guard<std::mutex> lock(mutex_);  // two callers may write (the client serializes them)
    written.push_back(frame);
    if (echo) deliver(kRequestFrames, frame);
    if (drop_link_on_write) client->onLinkDown();
    auto it = script_.find(frame);
    if (it == script_.end()) return true;
    Script& script = it->second;
    if (++script.writes < script.first_answered_write) return true;
    if (from_other_thread) {
      answer_threads_.emplace_back([this, frames = script.frames] {
        for (const Bytes& reply : frames) deliver(kResponseFrames, reply);
      });
      return true;
    }
    for (const Bytes& reply : script.frames) deliver(kResponseFrames, reply);
    return true;
  }

 private:
  struct Script {
    std::vector<Bytes> frames;
    int first_answered_write;
    int writes;
  };
  void deliver(FrameFamily family, const Bytes& frame) {
    client->onFrame(family, frame.data(), frame.size(), core::Clock::now());
  }
  std::map<Bytes, Script> script_;
  std::mutex mutex_;
  std::vector<std::thread> answer_threads_;
};

inline ServoBusOptions testOptions(bool armed) {
  ServoBusOptions options;
  options.timeout = std::chrono::milliseconds(20);
  options.retries = 1;
  options.allow_dangerous_writes = armed;
  return options;
}

class ServoBusClientTest : public ::testing::Test {
 protected:
  explicit ServoBusClientTest(bool armed = false)
      : client_(testOptions(armed), [this](const Bytes& frame) { return bus_.write(frame); }) {
    bus_.client = &client_;
  }

  FakeBus bus_;
  ServoBusClient client_;
};

class ServoBusClientArmedTest : public ServoBusClientTest {
 protected:
  ServoBusClientArmedTest() : ServoBusClientTest(true) {}
};

}  // namespace serial_robot_driver::devices::servo_bus
