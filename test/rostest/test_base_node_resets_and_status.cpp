// driver_node with the AP1 wheeled base (base_node.test): Resets after a timeout error and a
// replug, the battery and the diagnostics, and the base/reset and base/clear_encoders services.
#include <gtest/gtest.h>

#include "support/base_node_fixture.h"

namespace {

using namespace base_node_test;  // NOLINT: the shared fixture

// 8. An FF timeout-error frame from the base makes the node send a Reset before its next speed
// frame, at once rather than after a long delay.
TEST_F(BaseNodeTest, TimeoutErrorFromBaseTriggersReset) {
  // Settled: no Reset in a stretch of ordinary heartbeat frames.
  ASSERT_TRUE(base_->waitForCount(10, 5.0));
  const std::size_t settled = base_->count();
  ASSERT_TRUE(base_->waitForCount(settled + 15, 5.0));
  const std::vector<SeenFrame> before = base_->frames();
  ASSERT_FALSE(findFrom(before, settled, [](const SeenFrame& f) { return f.isReset(); }));

  const std::size_t from = base_->count();
  const Clock::time_point written = Clock::now();
  base_->write(kTimeoutErrorFrame);
  std::size_t reset = 0;
  ASSERT_TRUE(base_->waitUntil(
      [&](const std::vector<SeenFrame>& frames) {
        const auto found = findFrom(frames, from, [](const SeenFrame& f) { return f.isReset(); });
        if (!found || *found + 1 >= frames.size()) return false;
        reset = *found;
        return true;
      },
      3.0))
      << "no Reset after the FF error frame";
  const std::vector<SeenFrame> frames = base_->frames();
  EXPECT_EQ(frames[reset].bytes, resetFrame(frames[reset].seq));
  ASSERT_TRUE(frames[reset + 1].isSpeed());
  EXPECT_EQ(frames[reset + 1].seq, static_cast<uint8_t>(frames[reset].seq + 1));
  // Frames written before the node read the FF frame may precede it, but only a few.
  EXPECT_LE(speedCount(std::vector<SeenFrame>(frames.begin(), frames.begin() + reset), from), 25u);
  ASSERT_TRUE(g_ros->waitWheelCommand(frames[reset + 1].seq, written, 5.0));
  EXPECT_TRUE(g_ros->wheelCommand(frames[reset + 1].seq, written)->reset_before);
}

// 9. Unplugging and replugging the adapter: the node reopens the port and starts with a Reset.
TEST_F(BaseNodeTest, ReconnectAfterUnplugStartsWithReset) {
  ASSERT_TRUE(base_->waitForCount(10, 5.0));
  base_->unplug();
  std::this_thread::sleep_for(std::chrono::milliseconds(300));  // the node notices the loss
  base_->plug();
  ASSERT_TRUE(base_->waitForCount(2, 10.0)) << "the node did not reconnect";
  const std::vector<SeenFrame> frames = base_->frames();
  EXPECT_EQ(frames[0].bytes, resetFrame(frames[0].seq));
  ASSERT_TRUE(frames[1].isSpeed());
  EXPECT_EQ(frames[1].seq, static_cast<uint8_t>(frames[0].seq + 1));
  ASSERT_TRUE(base_->waitForCount(20, 5.0)) << "frames stopped after the reconnect";
}

// 10. The node polls the battery; the base's reply is published as a BatteryState.
TEST_F(BaseNodeTest, BatteryReplyIsPublished) {
  const std::size_t from = base_->count();
  std::size_t request = 0;
  ASSERT_TRUE(base_->waitUntil(
      [&](const std::vector<SeenFrame>& frames) {
        const auto found =
            findFrom(frames, from, [](const SeenFrame& f) { return f.msg_id == kMsgBattery; });
        if (found) request = *found;
        return found.has_value();
      },
      5.0))
      << "no battery request at battery_poll_rate 2 Hz";
  const std::vector<SeenFrame> frames = base_->frames();
  EXPECT_EQ(frames[request].bytes, batteryRequestFrame(frames[request].seq));

  const std::size_t replies_before = g_ros->battery().size();
  base_->write(kBattery87PercentFrame);
  ASSERT_TRUE(waitFor([&] { return g_ros->battery().size() > replies_before; }, 5.0));
  const sensor_msgs::BatteryState state = g_ros->battery().at(replies_before);
  EXPECT_NEAR(state.percentage, 0.87, 1e-6);
  EXPECT_TRUE(state.present);
}

// 10b. A base that never answers the battery requests (2 Hz) is an ERROR in /diagnostics once
// three poll periods passed (that a reply clears it is a BaseController unit test).
TEST_F(BaseNodeTest, SilentBaseIsADiagnosticsError) {
  ASSERT_TRUE(waitFor(
      [&] {
        const auto status = g_ros->baseDiagnostics();
        return status.level == 2 &&
               status.message.find("no reply from the base") != std::string::npos;
      },
      15.0))
      << "last base status: " << g_ros->baseDiagnostics().message;
  EXPECT_EQ(g_ros->baseDiagnostics().value("connected"), "True") << "the port itself is fine";
}

// 10c. Battery below base/battery_error_percent (10) is an ERROR, below base/battery_warn_percent
// (20) a WARN, as kobuki_node reports it.
TEST_F(BaseNodeTest, LowBatteryIsReportedInDiagnostics) {
  // Battery replies written by hand: 55 AA 02 SEQ 02 PCT XOR.
  const Bytes battery5 = {0x55, 0xAA, 0x02, 0x00, 0x02, 0x05, 0xFA};   // 5 %
  const Bytes battery15 = {0x55, 0xAA, 0x02, 0x01, 0x02, 0x0F, 0xF1};  // 15 %
  ASSERT_EQ(battery5, withXor({0x55, 0xAA, 0x02, 0x00, 0x02, 0x05}));
  ASSERT_EQ(battery15, withXor({0x55, 0xAA, 0x02, 0x01, 0x02, 0x0F}));
  base_->write(battery5);
  EXPECT_TRUE(waitFor(
      [&] {
        const auto status = g_ros->baseDiagnostics();
        return status.level == 2 &&
               status.message.find("battery 5 % (below 10 %)") != std::string::npos;
      },
      10.0))
      << "last base status: " << g_ros->baseDiagnostics().message;
  base_->write(battery15);
  EXPECT_TRUE(waitFor(
      [&] {
        return g_ros->baseDiagnostics().message.find("battery 15 % (below 20 %)") !=
               std::string::npos;
      },
      10.0))
      << "last base status: " << g_ros->baseDiagnostics().message;
}

// 11. base/reset and base/clear_encoders put their exact frames on the wire, in the SEQ sequence.
TEST_F(BaseNodeTest, ServicesWriteResetAndClearEncoders) {
  ASSERT_TRUE(base_->waitForCount(10, 5.0));
  const struct {
    const char* service;
    uint8_t msg_id;
    Bytes (*expected)(uint8_t);
  } cases[] = {{"base/reset", kMsgReset, resetFrame},
               {"base/clear_encoders", kMsgClearEncoders, clearEncodersFrame}};
  for (const auto& c : cases) {
    SCOPED_TRACE(c.service);
    ASSERT_TRUE(ros::service::waitForService(c.service, 10000));
    const std::size_t from = base_->count();
    std_srvs::Trigger trigger;
    ASSERT_TRUE(test_support::callService(c.service, trigger));
    EXPECT_TRUE(trigger.response.success) << trigger.response.message;
    std::size_t index = 0;
    ASSERT_TRUE(base_->waitUntil(
        [&](const std::vector<SeenFrame>& frames) {
          const auto found =
              findFrom(frames, from, [&](const SeenFrame& f) { return f.msg_id == c.msg_id; });
          if (!found || *found + 1 >= frames.size()) return false;
          index = *found;
          return true;
        },
        5.0));
    const std::vector<SeenFrame> frames = base_->frames();
    ASSERT_GE(index, 1u);
    const uint8_t seq = static_cast<uint8_t>(frames[index - 1].seq + 1);
    EXPECT_EQ(frames[index].bytes, c.expected(seq));
    EXPECT_EQ(frames[index + 1].seq, static_cast<uint8_t>(seq + 1));
    // Exactly one such frame for one call.
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
    const std::vector<SeenFrame> later = base_->frames();
    EXPECT_FALSE(
        findFrom(later, index + 1, [&](const SeenFrame& f) { return f.msg_id == c.msg_id; }));
  }
}

}  // namespace
