// The samples the DDS front ends publish, built from core values: stamps split as
// builtin_interfaces/Time does, JointState and DiagnosticArray pointing at what they were given.
#include <gtest/gtest.h>

#include <cstring>
#include <stdexcept>

#include "serial_robot_driver/dds_front/dds_conversions.h"

namespace serial_robot_driver::dds_front {
namespace {

TEST(DdsConversions, StampsSplitIntoSecondsAndNanoseconds) {
  const auto stamp = toTime(std::chrono::nanoseconds(1700000000123456789));
  EXPECT_EQ(stamp.sec, 1700000000);
  EXPECT_EQ(stamp.nanosec, 123456789u);
  EXPECT_EQ(fromTime(stamp).count(), 1700000000123456789);
}

TEST(DdsConversions, JointStateCarriesNamesPositionsAndNoVelocityWhenUnknown) {
  const JointStateSample joints(std::chrono::seconds(3), "base_link", {"hip", "knee"},
                                {0.25, -1.5});
  const auto& sample = joints.sample();
  EXPECT_EQ(sample.header.stamp.sec, 3);
  EXPECT_STREQ(sample.header.frame_id, "base_link");
  ASSERT_EQ(sample.name._length, 2u);
  EXPECT_STREQ(sample.name._buffer[0], "hip");
  EXPECT_STREQ(sample.name._buffer[1], "knee");
  ASSERT_EQ(sample.position._length, 2u);
  EXPECT_EQ(sample.position._buffer[0], 0.25);
  EXPECT_EQ(sample.position._buffer[1], -1.5);
  EXPECT_EQ(sample.velocity._length, 0u);
  EXPECT_EQ(sample.effort._length, 0u);
}

TEST(DdsConversions, DiagnosticsAreTheReportsWithTheNodesHardwareIdAsFallback) {
  core::StatusReport base;
  base.summary(core::StatusLevel::kWarn, "silent");
  base.add("frames in", 7);
  core::StatusReport port;
  port.hardware_id = "/dev/ttyUSB1";
  const DiagnosticsSample diagnostics(std::chrono::seconds(9),
                                      {{"driver_node: base", base}, {"driver_node: port", port}},
                                      "/dev/ttyUSB0");
  const auto& sample = diagnostics.sample();
  ASSERT_EQ(sample.status._length, 2u);
  const auto& first = sample.status._buffer[0];
  EXPECT_EQ(first.level, 1);  // diagnostic_msgs/DiagnosticStatus WARN
  EXPECT_STREQ(first.name, "driver_node: base");
  EXPECT_STREQ(first.message, "silent");
  EXPECT_STREQ(first.hardware_id, "/dev/ttyUSB0");
  ASSERT_EQ(first.values._length, 1u);
  EXPECT_STREQ(first.values._buffer[0].key, "frames in");
  EXPECT_STREQ(first.values._buffer[0].value, "7");
  EXPECT_STREQ(sample.status._buffer[1].hardware_id, "/dev/ttyUSB1");
  EXPECT_EQ(sample.status._buffer[1].values._length, 0u);
}

TEST(DdsConversions, AGuardedCallbacksErrorIsCountedNotLetOut) {
  core::InputRefusals counters;
  int calls = 0;
  const auto callback = guarded<std_msgs_msg_dds__Bool_>(
      counters, "e_stop", [&calls](const std_msgs_msg_dds__Bool_& msg) {
        ++calls;
        if (msg.data) throw std::runtime_error("a check missed this sample");
      });
  EXPECT_NO_THROW(callback(std_msgs_msg_dds__Bool_{true}));
  EXPECT_NO_THROW(callback(std_msgs_msg_dds__Bool_{false}));
  EXPECT_EQ(calls, 2) << "the next sample is taken as usual";
  const core::InputRefusalStats stats = counters.stats();
  ASSERT_EQ(stats.errors.count("e_stop"), 1u);
  EXPECT_EQ(stats.errors.at("e_stop"), 1u);
}

}  // namespace
}  // namespace serial_robot_driver::dds_front
