// A bus servo's identity and the settings the driver depends on: the READ_DATA frames read and
// their answers (golden frames written out by hand from docs/protocols.md, section 3), the checks
// that warn, the read once per polled servo (ServoBus on a manual clock over a fake bus), its
// diagnostics content, and the simulated servo's identity flags.
#include <gtest/gtest.h>

#include <chrono>
#include <string>
#include <vector>

#include "serial_robot_driver/devices/servo_bus/servo_bus_status.h"
#include "serial_robot_driver/devices/servo_bus/servo_identity.h"
#include "serial_robot_driver/devices/servo_bus/sim/servo_bus_sim.h"
#include "support/servo_bus_rig.h"

namespace serial_robot_driver::devices::servo_bus {
namespace {

using std::chrono::milliseconds;

// Requests 12 4C 03 02 ID DATA_ID SUM and answers 05 1C 03 LEN ID DATA_ID VALUE.. SUM, with
// SUM the byte sum of everything before it, mod 256. Servo 3 throughout.
// servo_type (6): 5E+03+02+03+06 = 6C; answered 0x0A05 (05 0A): 21+03+04+03+06+05+0A = 40.
const Bytes kReadType3 = {0x12, 0x4C, 0x03, 0x02, 0x03, 0x06, 0x6C};
const Bytes kType3Is0A05 = {0x05, 0x1C, 0x03, 0x04, 0x03, 0x06, 0x05, 0x0A, 0x40};
// firmware_version (7): 6D; answered 0x0102 (02 01): 21+03+04+03+07+02+01 = 35.
const Bytes kReadFirmware3 = {0x12, 0x4C, 0x03, 0x02, 0x03, 0x07, 0x6D};
const Bytes kFirmware3Is0102 = {0x05, 0x1C, 0x03, 0x04, 0x03, 0x07, 0x02, 0x01, 0x35};
// serial_number (8, u32): 6E; answered 0x12345678 (78 56 34 12): 21+03+06+03+08 = 35,
// +78 = AD, +56 = 103 -> 03, +34 = 37, +12 = 49.
const Bytes kReadSerial3 = {0x12, 0x4C, 0x03, 0x02, 0x03, 0x08, 0x6E};
const Bytes kSerial3Is12345678 = {0x05, 0x1C, 0x03, 0x06, 0x03, 0x08, 0x78, 0x56, 0x34, 0x12, 0x49};
// response_switch (33 = 0x21, u8): 5E+03+02+03+21 = 87; answered 1: 21+03+03+03+21+01 = 4C.
const Bytes kReadResponseSwitch3 = {0x12, 0x4C, 0x03, 0x02, 0x03, 0x21, 0x87};
const Bytes kResponseSwitch3Is1 = {0x05, 0x1C, 0x03, 0x03, 0x03, 0x21, 0x01, 0x4C};
// angle_limit_switch (48 = 0x30, u8): 96; answered 0: 21+03+03+03+30 = 5A; answered 1: 5B.
const Bytes kReadAngleLimitSwitch3 = {0x12, 0x4C, 0x03, 0x02, 0x03, 0x30, 0x96};
const Bytes kAngleLimitSwitch3Off = {0x05, 0x1C, 0x03, 0x03, 0x03, 0x30, 0x00, 0x5A};
const Bytes kAngleLimitSwitch3On = {0x05, 0x1C, 0x03, 0x03, 0x03, 0x30, 0x01, 0x5B};
// angle_limit_low (52 = 0x34, i16): 9A; answered -900 = 0xFC7C (7C FC): 21+03+04+03+34 = 5F,
// +7C = DB, +FC = 1D7 -> D7.
const Bytes kReadAngleLimitLow3 = {0x12, 0x4C, 0x03, 0x02, 0x03, 0x34, 0x9A};
const Bytes kAngleLimitLow3IsMinus900 = {0x05, 0x1C, 0x03, 0x04, 0x03, 0x34, 0x7C, 0xFC, 0xD7};
// angle_limit_high (51 = 0x33, i16): 99; answered 900 = 0x0384 (84 03): 21+03+04+03+33 = 5E,
// +84 = E2, +03 = E5.
const Bytes kReadAngleLimitHigh3 = {0x12, 0x4C, 0x03, 0x02, 0x03, 0x33, 0x99};
const Bytes kAngleLimitHigh3Is900 = {0x05, 0x1C, 0x03, 0x04, 0x03, 0x33, 0x84, 0x03, 0xE5};
// READ_ANGLE (CMD 10) of servo 3: 5E+0A+01+03 = 6C; answered 0.0 deg: 21+0A+03+03 = 31.
const Bytes kReadAngle3 = {0x12, 0x4C, 0x0A, 0x01, 0x03, 0x6C};
const Bytes kAngle3IsZero = {0x05, 0x1C, 0x0A, 0x03, 0x03, 0x00, 0x00, 0x31};
// ROTATE (CMD 8) of servo 3 to 0.0 deg in 0 ms at default power: 5E+08+07+03 = 70; its
// completion answer (response_switch 1 only), result 1: 21+08+02+03+01 = 2F.
const Bytes kRotate3ToZero = {0x12, 0x4C, 0x08, 0x07, 0x03, 0x00,
                              0x00, 0x00, 0x00, 0x00, 0x00, 0x70};
const Bytes kRotate3Done = {0x05, 0x1C, 0x08, 0x02, 0x03, 0x01, 0x2F};

ServoIdentity plainServo() {
  ServoIdentity identity;
  identity.servo_type = 257;
  identity.firmware_version = 258;
  return identity;
}

bool mentions(const std::vector<std::string>& warnings, const std::string& text) {
  for (const std::string& warning : warnings) {
    if (warning.find(text) != std::string::npos) return true;
  }
  return false;
}

TEST(ServoIdentityWarnings, NoneWhenEverythingFitsOrNothingIsExpected) {
  EXPECT_TRUE(identityWarnings(3, plainServo(), {}).empty());
  EXPECT_TRUE(identityWarnings(3, plainServo(), {257, 258, {3}}).empty());
  ServoIdentity full_range = plainServo();
  full_range.angle_limit_on = true;
  full_range.angle_limit_low = kJointRangeLow;
  full_range.angle_limit_high = kJointRangeHigh;
  EXPECT_TRUE(identityWarnings(3, full_range, {0, 0, {3}}).empty());
}

TEST(ServoIdentityWarnings, NameTheTypeAndFirmwareThatDifferFromTheExpected) {
  const std::vector<std::string> warnings = identityWarnings(3, plainServo(), {300, 400, {}});
  ASSERT_EQ(warnings.size(), 2u);
  EXPECT_EQ(warnings[0].rfind("servo 3: servo_type 257 is not the expected 300", 0), 0u)
      << warnings[0];
  EXPECT_EQ(warnings[1].rfind("servo 3: firmware_version 258 is not the expected 400", 0), 0u)
      << warnings[1];
}

TEST(ServoIdentityWarnings, ResponseSwitchOneSaysAStopCannotInterruptAQueuedMotion) {
  ServoIdentity queued = plainServo();
  queued.response_switch = 1;
  const std::vector<std::string> warnings = identityWarnings(5, queued, {});
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_TRUE(mentions(warnings, "servo 5: response_switch is 1"));
  EXPECT_TRUE(mentions(warnings, "a stop cannot interrupt a motion already queued"));
  EXPECT_TRUE(mentions(warnings, "takes bus time"));
}

TEST(ServoIdentityWarnings, AngleLimitsNarrowerThanAJointsRangeOnlyForJoints) {
  ServoIdentity limited = plainServo();
  limited.angle_limit_on = true;
  limited.angle_limit_low = -900;
  limited.angle_limit_high = 900;
  EXPECT_TRUE(identityWarnings(3, limited, {0, 0, {}}).empty());  // not a joint
  const std::vector<std::string> warnings = identityWarnings(3, limited, {0, 0, {1, 3}});
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_TRUE(mentions(warnings, "angle limits -90.0..90.0 deg are narrower than its joint's"));
  limited.angle_limit_on = false;  // the servo does not apply them
  EXPECT_TRUE(identityWarnings(3, limited, {0, 0, {3}}).empty());
}

// --- the reads on the wire -------------------------------------------------------------------

TEST_F(ServoBusTest, IdentityReadsTypeFirmwareSerialAndTheSettingsInOrder) {
  answers_ = {{kReadType3, kType3Is0A05},
              {kReadFirmware3, kFirmware3Is0102},
              {kReadSerial3, kSerial3Is12345678},
              {kReadResponseSwitch3, kResponseSwitch3Is1},
              {kReadAngleLimitSwitch3, kAngleLimitSwitch3On},
              {kReadAngleLimitLow3, kAngleLimitLow3IsMinus900},
              {kReadAngleLimitHigh3, kAngleLimitHigh3Is900}};
  makeBus({});
  ServoIdentity identity;
  const ServoStatus status =
      readServoIdentity(bus_->client(), 3, BusPriority::kCaller, false, &identity);
  ASSERT_TRUE(status.ok()) << status.message;
  EXPECT_EQ(written(), (std::vector<Bytes>{kReadType3, kReadFirmware3, kReadSerial3,
                                           kReadResponseSwitch3, kReadAngleLimitSwitch3,
                                           kReadAngleLimitLow3, kReadAngleLimitHigh3}));
  EXPECT_EQ(identity.servo_type, 0x0A05);
  EXPECT_EQ(identity.firmware_version, 0x0102);
  EXPECT_EQ(identity.serial_number, 0x12345678u);
  EXPECT_EQ(identity.response_switch, 1);
  EXPECT_TRUE(identity.angle_limit_on);
  EXPECT_EQ(identity.angle_limit_low, -900);
  EXPECT_EQ(identity.angle_limit_high, 900);
  EXPECT_FALSE(identity.limits_known);
}

TEST_F(ServoBusTest, ServoInfoFailsClearlyWhenTheServoDoesNotAnswer) {
  answers_.clear();
  makeBus({});
  ServoIdentity identity;
  const ServoStatus status = readServoInfo(bus_->client(), 3, {}, &identity);
  EXPECT_EQ(status.error, ServoError::kTimeout);
  EXPECT_EQ(status.message.rfind("servo 3's identity could not be read: ", 0), 0u)
      << status.message;
  EXPECT_EQ(written(), std::vector<Bytes>{kReadType3});  // the first silent read ends it
}

// --- read once per polled servo, as background work ------------------------------------------

TEST_F(ServoBusTest, APolledServoIsIdentifiedOnceWhenItAnswersAndWarnedAbout) {
  answers_ = {{kReadAngle3, kAngle3IsZero},
              {kReadType3, kType3Is0A05},
              {kReadFirmware3, kFirmware3Is0102},
              {kReadSerial3, kSerial3Is12345678},
              {kReadResponseSwitch3, kResponseSwitch3Is1},
              {kReadAngleLimitSwitch3, kAngleLimitSwitch3Off}};
  makeBus({3}, [](ServoBusConfig& config) {
    config.read_identity = true;
    config.identity.expected_type = 257;
  });
  bus_->start();
  clock_->waitForLoop();  // the angle poll, then the identity read
  ASSERT_EQ(bus_->identities().size(), 1u);
  const ServoIdentityReport report = bus_->identities()[0];
  ASSERT_TRUE(report.known);
  EXPECT_EQ(report.identity.servo_type, 0x0A05);
  EXPECT_EQ(report.identity.serial_number, 0x12345678u);
  ASSERT_EQ(report.warnings.size(), 2u);
  EXPECT_TRUE(mentions(report.warnings, "servo_type 2565 is not the expected 257"));
  EXPECT_TRUE(mentions(report.warnings, "response_switch is 1"));
  // The angle poll goes on; the identity is not read again.
  clock_->advance(milliseconds(100));
  clock_->advance(milliseconds(100));
  bus_->shutdown();
  EXPECT_EQ(countWritten(kReadAngle3), 3u);
  EXPECT_EQ(countWritten(kReadType3), 1u);
  EXPECT_EQ(countWritten(kReadAngleLimitSwitch3), 1u);
  EXPECT_EQ(identities_.size(), 1u);  // logged once
}

TEST_F(ServoBusTest, AnIdentityThatIsNotAnsweredIsAskedAgainAfterABackoffQuietly) {
  answers_ = {{kReadAngle3, kAngle3IsZero}};  // answers its angle, not READ_DATA
  makeBus({3}, [](ServoBusConfig& config) { config.read_identity = true; });
  bus_->start();
  clock_->waitForLoop();
  EXPECT_EQ(countWritten(kReadType3), 1u);
  EXPECT_FALSE(bus_->identities()[0].known);
  // Not at every angle poll: after the back-off.
  clock_->advance(milliseconds(400));
  EXPECT_EQ(countWritten(kReadType3), 1u);
  {
    std::lock_guard<std::mutex> lock(mutex_);
    answers_[kReadType3] = kType3Is0A05;
    answers_[kReadFirmware3] = kFirmware3Is0102;
    answers_[kReadSerial3] = kSerial3Is12345678;
    answers_[kReadResponseSwitch3] = kResponseSwitch3Is1;
    answers_[kReadAngleLimitSwitch3] = kAngleLimitSwitch3Off;
  }
  clock_->advance(milliseconds(100));
  bus_->shutdown();
  EXPECT_EQ(countWritten(kReadType3), 2u);
  EXPECT_TRUE(bus_->identities()[0].known);
  EXPECT_EQ(identities_.size(), 1u);  // no report while it failed
}

TEST_F(ServoBusTest, NoIdentityReadWhenTurnedOff) {
  makeBus({0});
  bus_->start();
  clock_->waitForLoop();
  clock_->advance(milliseconds(100));
  bus_->shutdown();
  EXPECT_TRUE(bus_->identities().empty());
  for (const Bytes& frame : written()) EXPECT_EQ(frame, golden::servo::kReadAngle0);
}

// --- diagnostics -----------------------------------------------------------------------------

TEST(ServoIdentityStatus, ShowsTheIdentityAndWarnsWithEachMismatch) {
  ServoIdentityReport report;
  report.id = 3;
  report.known = true;
  report.identity = plainServo();
  report.identity.serial_number = 77;
  core::StatusReport status;
  status.summary(core::StatusLevel::kOk, "servo 3 ok");
  addServoIdentity(&report, &status);
  EXPECT_EQ(status.level, core::StatusLevel::kOk);
  EXPECT_EQ(*status.find("servo_type"), "257");
  EXPECT_EQ(*status.find("firmware_version"), "258");
  EXPECT_EQ(*status.find("serial_number"), "77");
  EXPECT_EQ(*status.find("response_switch"), "0");
  EXPECT_EQ(*status.find("angle limits"), "off");

  report.warnings = {"servo 3: response_switch is 1: ..."};
  core::StatusReport warned;
  warned.summary(core::StatusLevel::kOk, "servo 3 ok");
  addServoIdentity(&report, &warned);
  EXPECT_EQ(warned.level, core::StatusLevel::kWarn);
  EXPECT_EQ(warned.message, "servo 3: response_switch is 1: ...");

  core::StatusReport unknown;
  addServoIdentity(nullptr, &unknown);
  EXPECT_EQ(*unknown.find("identity"), "not read yet (read once the servo answers)");
}

// --- the simulated servo ---------------------------------------------------------------------

TEST(ServoBusSimIdentity, AnswersWithItsConfiguredIdentityAndResponseSwitch) {
  const serial_robot_driver::sim::TimePoint start =
      serial_robot_driver::sim::TimePoint() + std::chrono::hours(1);
  sim::ServoBusSimConfig config;
  config.servo_ids = {3};
  config.servo_type = {{3, 0x0A05}};
  config.response_switch = {{3, 1}};
  config.answer_latency_s = 0.001;
  sim::ServoBusSim bus(config, start);
  const auto ask = [&](const Bytes& request, int at_ms) {
    bus.handleRequest(request.data(), request.size(), start + milliseconds(at_ms));
    serial_robot_driver::sim::Outbox out;
    bus.tick(start + milliseconds(at_ms + 50), &out);
    std::vector<Bytes> frames;
    for (const serial_robot_driver::sim::Outgoing& frame : out) frames.push_back(frame.bytes);
    return frames;
  };
  EXPECT_EQ(ask(kReadType3, 0), std::vector<Bytes>{kType3Is0A05});
  EXPECT_EQ(ask(kReadResponseSwitch3, 100), std::vector<Bytes>{kResponseSwitch3Is1});
  // response_switch 1: the motion is answered once it completes.
  EXPECT_EQ(ask(kRotate3ToZero, 200), std::vector<Bytes>{kRotate3Done});
}

}  // namespace
}  // namespace serial_robot_driver::devices::servo_bus
