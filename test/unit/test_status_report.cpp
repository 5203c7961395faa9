// The core's diagnostic status type (the same merge and value rules as diagnostic_updater's
// DiagnosticStatusWrapper) and the statuses of the node's own parts: a port, the e-stop, the wire
// capture.
#include <gtest/gtest.h>

#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "serial_robot_driver/core/e_stop_status.h"
#include "serial_robot_driver/core/link_status.h"
#include "serial_robot_driver/core/status_report.h"
#include "serial_robot_driver/core/wire_capture_status.h"

namespace {

using namespace serial_robot_driver::core;
using Values = std::vector<std::pair<std::string, std::string>>;

TEST(StatusReport, MergeNamesEveryProblemAndKeepsTheWorstLevel) {
  StatusReport status;
  status.summary(StatusLevel::kOk, "driving");
  status.mergeSummary(StatusLevel::kOk, "ignored: not worse than OK");
  EXPECT_EQ(status.message, "driving");
  status.mergeSummary(StatusLevel::kWarn, "battery low");
  EXPECT_EQ(status.level, StatusLevel::kWarn);
  EXPECT_EQ(status.message, "battery low") << "a problem replaces an OK message";
  status.mergeSummaryf(StatusLevel::kError, "no reply for %.0f s", 3.4);
  EXPECT_EQ(status.level, StatusLevel::kError);
  EXPECT_EQ(status.message, "battery low; no reply for 3 s");
  status.mergeSummary(StatusLevel::kWarn, "e-stop");
  EXPECT_EQ(status.level, StatusLevel::kError) << "a lesser problem does not lower the level";
  EXPECT_EQ(status.message, "battery low; no reply for 3 s; e-stop");
}

TEST(StatusReport, MergeIntoAnEmptyOkReportChangesNothingUntilAProblem) {
  StatusReport status;
  status.mergeSummary(StatusLevel::kOk, "fine");
  EXPECT_EQ(status.level, StatusLevel::kOk);
  EXPECT_EQ(status.message, "");
}

TEST(StatusReport, ValuesReadAsDiagnosticUpdaterWritesThem) {
  StatusReport status;
  status.add("flag", true);
  status.add("off", false);
  status.add("count", uint64_t{42});
  status.add("signed", int64_t{-7});
  status.add("rate", 2.5);
  status.add("whole", 1.0);
  status.add("text", "literal");
  status.add("string", std::string("owned"));
  status.addf("formatted", "%.2f", 1.0 / 3.0);
  EXPECT_EQ(status.values, (Values{{"flag", "True"},
                                   {"off", "False"},
                                   {"count", "42"},
                                   {"signed", "-7"},
                                   {"rate", "2.5"},
                                   {"whole", "1"},
                                   {"text", "literal"},
                                   {"string", "owned"},
                                   {"formatted", "0.33"}}));
  ASSERT_NE(status.find("rate"), nullptr);
  EXPECT_EQ(*status.find("rate"), "2.5");
  EXPECT_EQ(status.find("missing"), nullptr);
}

// Integers are written without a stream now: the text must stay what a stream wrote.
TEST(StatusReport, NumbersReadAsAStreamWritesThem) {
  StatusReport status;
  status.add("min", std::numeric_limits<int64_t>::min());
  status.add("max", std::numeric_limits<uint64_t>::max());
  status.add("short", int16_t{-300});
  status.add("byte", uint8_t{65});  // a stream writes a char type as its character
  status.add("float", 0.1f);
  EXPECT_EQ(status.values, (Values{{"min", "-9223372036854775808"},
                                   {"max", "18446744073709551615"},
                                   {"short", "-300"},
                                   {"byte", "A"},
                                   {"float", "0.1"}}));
}

TEST(StatusReport, LevelsNameDiagnosticStatusLevels) {
  EXPECT_STREQ(toString(StatusLevel::kOk), "OK");
  EXPECT_STREQ(toString(StatusLevel::kWarn), "WARN");
  EXPECT_STREQ(toString(StatusLevel::kError), "ERROR");
  EXPECT_STREQ(toString(StatusLevel::kStale), "STALE");
  EXPECT_EQ(static_cast<int>(StatusLevel::kStale), 3);
}

TEST(EStopStatus, ReleasedIsOkEngagedWarnsAndRefusalsAreSummedBySource) {
  EStopStats stats;
  StatusReport released = eStopStatus(stats);
  EXPECT_EQ(released.level, StatusLevel::kOk);
  EXPECT_EQ(released.message, "released");
  EXPECT_EQ(released.values,
            (Values{{"engaged", "False"}, {"engagements", "0"}, {"commands refused", "0"}}));

  stats.engaged = true;
  stats.engagements = 2;
  stats.refused = {{"cmd_vel", 3}, {"joint_commands", 1}};
  StatusReport engaged = eStopStatus(stats);
  EXPECT_EQ(engaged.level, StatusLevel::kWarn);
  EXPECT_EQ(engaged.message, "engaged: every actuator stopped, motion commands refused");
  EXPECT_EQ(engaged.values, (Values{{"engaged", "True"},
                                    {"engagements", "2"},
                                    {"refused: cmd_vel", "3"},
                                    {"refused: joint_commands", "1"},
                                    {"commands refused", "4"}}));
}

TEST(LinkStatus, ConnectedIsOkAndListsTheCountersInOrder) {
  LinkStats stats;
  stats.connected = true;
  stats.connects = 1;
  stats.bytes_out = 10;
  stats.frames_out = 2;
  stats.framer.bytes_in = 30;
  stats.framer.family_count = 1;
  stats.framer.by_family[0] = {"base", 5};
  SerialLinkOptions options;
  options.path = "/dev/ttyUSB0";
  options.baud = 115200;
  const StatusReport status = linkStatus(stats, options);
  EXPECT_EQ(status.level, StatusLevel::kOk);
  EXPECT_EQ(status.message, "connected");
  EXPECT_EQ(status.hardware_id, "/dev/ttyUSB0");
  std::vector<std::string> keys;
  for (const auto& [key, value] : status.values) keys.push_back(key);
  const std::string frames_key = "frames in: base";
  EXPECT_EQ(keys, (std::vector<std::string>{
                      "path", "baud", "connected", "connects", "disconnects", "last error",
                      "bytes in", "bytes out", "frames out", "write failures", frames_key,
                      "checksum errors", "bad tails", "bad lengths", "unknown servo commands",
                      "stale partial frames dropped", "bytes skipped (resync)",
                      "internal errors (reader thread)", "last internal error", "low latency",
                      "latency_timer (ms)"}))
      << "a frame family with no frame is left out";
  EXPECT_EQ(*status.find("baud"), "115200");
  EXPECT_EQ(*status.find("bytes in"), "30");
  EXPECT_EQ(*status.find(frames_key), "5");
  EXPECT_EQ(*status.find("latency_timer (ms)"), "n/a");
}

TEST(LinkStatus, ALatencyTimerAbove1MsWarnsOnlyWhileConnected) {
  LinkStats stats;
  stats.connected = true;
  stats.latency_timer_ms = 1;
  SerialLinkOptions options;
  EXPECT_EQ(linkStatus(stats, options).level, StatusLevel::kOk) << "1 ms is the goal";
  stats.latency_timer_ms = 16;
  StatusReport slow = linkStatus(stats, options);
  EXPECT_EQ(slow.level, StatusLevel::kWarn);
  EXPECT_EQ(slow.message, "latency_timer above 1 ms");
  EXPECT_EQ(*slow.find("latency_timer (ms)"), "16");
  stats.connected = false;
  stats.last_error = "No such file or directory";
  StatusReport down = linkStatus(stats, options);
  EXPECT_EQ(down.level, StatusLevel::kError);
  EXPECT_EQ(down.message, "not connected: No such file or directory");
  stats.last_error.clear();
  EXPECT_EQ(linkStatus(stats, options).message, "not connected");
}

TEST(LinkStatus, AnInternalErrorOnTheReaderThreadWarnsAndNamesTheLastOne) {
  LinkStats stats;
  stats.connected = true;
  stats.handler_errors = 2;
  stats.last_handler_error = "a frame's listener: vector::_M_range_check";
  const StatusReport status = linkStatus(stats, SerialLinkOptions{});
  EXPECT_EQ(status.level, StatusLevel::kWarn);
  EXPECT_EQ(status.message, "2 internal errors on the reader thread");
  EXPECT_EQ(*status.find("internal errors (reader thread)"), "2");
  EXPECT_EQ(*status.find("last internal error"), "a frame's listener: vector::_M_range_check");
}

TEST(WireCaptureStatus, ADroppedChunkWarns) {
  WireCaptureStats stats;
  stats.chunks = 40;
  stats.bytes = 1200;
  stats.queued = 3;
  stats.in_roscpp = 2;
  const StatusReport capturing = wireCaptureStatus(stats);
  EXPECT_EQ(capturing.level, StatusLevel::kOk);
  EXPECT_EQ(capturing.message, "capturing on serial_raw");
  EXPECT_TRUE(capturing.hardware_id.empty()) << "the node's own";
  EXPECT_EQ(capturing.values, (Values{{"chunks published", "40"},
                                      {"bytes published", "1200"},
                                      {"chunks dropped", "0"},
                                      {"chunks queued", "3"},
                                      {"chunks held by roscpp", "2"}}));
  stats.dropped = 1;
  const StatusReport dropping = wireCaptureStatus(stats);
  EXPECT_EQ(dropping.level, StatusLevel::kWarn);
  EXPECT_EQ(dropping.message, "chunks dropped: the subscribers fell behind");
  EXPECT_EQ(*dropping.find("chunks dropped"), "1");
}

}  // namespace
