// The body's diagnostic status from its statistics: no telemetry yet, telemetry stopped between
// two diagnostics periods (reported once per outage), the port down, and the counters.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "serial_robot_driver/devices/body/body_status.h"

namespace {

using namespace serial_robot_driver::devices::body;
using namespace serial_robot_driver::core;
using Flow = BodyStatus::FlowChange;

const PortState kUp{"/dev/ttyACM0", true};

BodyStats decoded(uint64_t frames) {
  BodyStats stats;
  stats.frames_decoded = frames;
  return stats;
}

TEST(BodyStatus, FlowingTelemetryLeavesTheRateVerdictAlone) {
  BodyStatus body;
  const BodyStatus::Update first = body.update(decoded(10), {}, kUp);
  EXPECT_EQ(first.report.level, StatusLevel::kOk);
  EXPECT_EQ(first.report.message, "") << "nothing to merge into the telemetry rate's summary";
  EXPECT_EQ(first.flow, Flow::kNone);
  const BodyStatus::Update second = body.update(decoded(20), {}, kUp);
  EXPECT_EQ(second.report.level, StatusLevel::kOk);
  EXPECT_EQ(second.flow, Flow::kNone);
}

TEST(BodyStatus, NoTelemetryYetIsAnError) {
  BodyStatus body;
  const BodyStatus::Update update = body.update(decoded(0), {}, kUp);
  EXPECT_EQ(update.report.level, StatusLevel::kError);
  EXPECT_EQ(update.report.message, "no telemetry received yet");
  EXPECT_EQ(update.flow, Flow::kNone) << "it never flowed, so it did not stop";
}

TEST(BodyStatus, TelemetryThatStopsIsAnErrorReportedOncePerOutage) {
  BodyStatus body;
  body.update(decoded(10), {}, kUp);
  const BodyStatus::Update stopped = body.update(decoded(10), {}, kUp);
  EXPECT_EQ(stopped.report.level, StatusLevel::kError);
  EXPECT_EQ(stopped.report.message, "telemetry stopped");
  EXPECT_EQ(stopped.flow, Flow::kStopped);
  const BodyStatus::Update still = body.update(decoded(10), {}, kUp);
  EXPECT_EQ(still.report.message, "telemetry stopped");
  EXPECT_EQ(still.flow, Flow::kNone) << "logged once, not once per period";
  const BodyStatus::Update resumed = body.update(decoded(11), {}, kUp);
  EXPECT_EQ(resumed.report.level, StatusLevel::kOk);
  EXPECT_EQ(resumed.flow, Flow::kResumed);
  EXPECT_EQ(body.update(decoded(11), {}, kUp).flow, Flow::kStopped) << "a new outage";
}

TEST(BodyStatus, APortDownIsAnErrorNotAStoppedTelemetry) {
  BodyStatus body;
  body.update(decoded(10), {}, kUp);
  const BodyStatus::Update down = body.update(decoded(10), {}, {"/dev/ttyACM0", false});
  EXPECT_EQ(down.report.level, StatusLevel::kError);
  EXPECT_EQ(down.report.message, "port /dev/ttyACM0 not connected");
  EXPECT_EQ(down.flow, Flow::kNone);
  EXPECT_EQ(*down.report.find("connected"), "False");
}

TEST(BodyStatus, ListsTheCountersAndTheFramersErrors) {
  BodyStats stats = decoded(7);
  stats.decode_errors = 1;
  stats.commands_sent = 3;
  stats.motion_refused = 2;
  serial_robot_driver::protocol::FramerStats framer;
  framer.checksum_errors = 4;
  framer.bad_tails = 5;
  framer.bytes_skipped = 6;
  BodyStatus body;
  const StatusReport status = body.update(stats, framer, kUp).report;
  EXPECT_EQ(status.hardware_id, "/dev/ttyACM0");
  std::vector<std::string> keys;
  for (const auto& [key, value] : status.values) keys.push_back(key);
  EXPECT_EQ(keys, (std::vector<std::string>{
                      "port", "connected", "frames decoded", "decode errors", "last decode error",
                      "commands sent", "commands rejected", "joint targets out of range",
                      "command write failures", "commands refused when written (e_stop)",
                      "commands voided (e_stop engaged after they were accepted)",
                      "port checksum errors", "port bad tails", "port bytes skipped (resync)"}));
  EXPECT_EQ(*status.find("frames decoded"), "7");
  EXPECT_EQ(*status.find("last decode error"), "none");
  EXPECT_EQ(*status.find("commands refused when written (e_stop)"), "2");
  EXPECT_EQ(*status.find("port checksum errors"), "4");
  EXPECT_EQ(*status.find("port bad tails"), "5");
  EXPECT_EQ(*status.find("port bytes skipped (resync)"), "6");
}

}  // namespace
