// calibrate_base's run, stepped against a fake robot (calibration_fake_robot.h) with the time
// given by the test: a whole run recovers the slip; the e-stop, lost telemetry, stopped wheel
// frames and a signal mid-turn command zero at once and wait for a zero frame; the refusals
// before moving never command motion; and the command line's options.
#include <gtest/gtest.h>

#include <csignal>
#include <regex>
#include <sstream>

#include "calibration_fake_robot.h"
#include "serial_robot_driver/devices/base/turn_calibration_options.h"

namespace {

using namespace calibration_test;
using serial_robot_driver::devices::base::CalibrationOptions;
using serial_robot_driver::devices::base::noCalibrationDriverText;
using serial_robot_driver::devices::base::parseCalibrationOptions;
using serial_robot_driver::devices::base::printCalibrationLines;

constexpr double kEffectiveSeparation = 0.40 / 0.85;  // slip 0.15

CalibrationOptions quickOptions() {
  CalibrationOptions options;
  options.angle = 3.14;
  options.rate = 1.0;
  return options;
}

TurnCalibrationRun makeRun(const CalibrationOptions& options = quickOptions()) {
  return TurnCalibrationRun(options, "/driver_node", "/imu/data", BaseConfig{});
}

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

/// At 1 s into the turn (the robot moving), does `act` once and remembers when.
struct MidTurn {
  double at = -1;
  int signal = 0;
  std::function<void(FakeRobot&)> act = [](FakeRobot&) {};
  Script script() {
    return [this](double t, FakeRobot& robot) {
      if (at >= 0 || robot.movingFor(t) < 1.0) return 0;
      at = t;
      act(robot);
      return signal;
    };
  }
};

/// The abort's step answered zero, nothing moved after it, and a zero frame confirmed the stop.
void expectStoppedAtOnce(const Outcome& outcome, double at) {
  const auto first = outcome.firstCommandFrom(at);
  ASSERT_TRUE(first);
  EXPECT_EQ(first->first, at) << "no command in the step that saw the reason to stop";
  EXPECT_TRUE(Outcome::isZero(first->second));
  EXPECT_FALSE(outcome.anyMovingCommandFrom(at));
  EXPECT_TRUE(
      contains(outcome.err, "calibrate_base: base stopped (a zero wheel frame was written)"))
      << outcome.err;
  EXPECT_LT(outcome.end - at, 1.0);
}

TEST(TurnCalibrationRun, AWholeRunRecoversTheSlip) {
  FakeRobot robot;
  auto run = makeRun();
  const Outcome outcome = runToEnd(run, robot);
  ASSERT_TRUE(outcome.finished);
  EXPECT_EQ(outcome.exit_status, 0) << outcome.out << outcome.err;
  EXPECT_TRUE(contains(outcome.out,
                       "driver /driver_node: wheel_separation 0.4000 m, wheel_diameter 0.2500 m\n"
                       "turning in place 3.14 rad each way at 1.00 rad/s; Ctrl-C stops the base\n"))
      << outcome.out;
  std::smatch match;
  ASSERT_TRUE(std::regex_search(
      outcome.out, match,
      std::regex(R"(effective wheel_separation: ([0-9.]+) m \(configured 0.4000 m\))")))
      << outcome.out;
  const std::string value = match[1];
  EXPECT_NEAR(std::stod(value), kEffectiveSeparation, kEffectiveSeparation * 0.005) << outcome.out;
  EXPECT_TRUE(contains(outcome.out,
                       "  try it now:  rosrun dynamic_reconfigure dynparam set "
                       "/driver_node/base wheel_separation " +
                           value + "\n"));
  EXPECT_TRUE(contains(outcome.out,
                       "  keep it:     in your config file, under base:   "
                       "wheel_separation: " +
                           value + "\n"));
  ASSERT_TRUE(std::regex_search(outcome.out, match, std::regex(R"(gyro bias ([-0-9.]+) rad/s)")));
  EXPECT_NEAR(std::stod(match[1]), robot.gyro_bias, 0.005);  // the bias, not 0
  EXPECT_TRUE(contains(outcome.out, "turning counter-clockwise: done"));
  EXPECT_TRUE(contains(outcome.out, "turning clockwise: done"));
  EXPECT_EQ(outcome.err, "");
  // Both ways were commanded, and the run ended with the base commanded still.
  bool ccw = false, cw = false;
  for (const auto& [at, twist] : outcome.commands) {
    ccw = ccw || twist.angular == 1.0;
    cw = cw || twist.angular == -1.0;
  }
  EXPECT_TRUE(ccw && cw);
  EXPECT_TRUE(Outcome::isZero(outcome.commands.back().second));
  EXPECT_EQ(robot.left, 0);
  EXPECT_EQ(robot.right, 0);
}

TEST(TurnCalibrationRun, TheStraightRunGivesTheDiameterFromTheTypedDistance) {
  FakeRobot robot;
  robot.typed_distance = 0.5 * 1.02;  // the wheels are 2 % larger than configured
  CalibrationOptions options = quickOptions();
  options.distance = 0.5;
  auto run = makeRun(options);
  const Outcome outcome = runToEnd(run, robot);
  ASSERT_EQ(outcome.exit_status, 0) << outcome.out << outcome.err;
  EXPECT_TRUE(contains(outcome.out, "measure the distance the robot travelled"));
  std::smatch match;
  ASSERT_TRUE(std::regex_search(outcome.out, match,
                                std::regex(R"(effective wheel_diameter: ([0-9.]+) m)")));
  // The straight run stops at the first frame past 0.5 m commanded: within one frame's travel.
  EXPECT_NEAR(std::stod(match[1]), 0.25 * 1.02, 0.25 * 0.01) << outcome.out;
  EXPECT_TRUE(contains(outcome.out, "dynparam set /driver_node/base wheel_diameter "));
  EXPECT_TRUE(contains(outcome.out, "(set both)"));
}

TEST(TurnCalibrationRun, TheEStopMidTurnStopsAtOnceAndEndsRefused) {
  FakeRobot robot;
  MidTurn mid;
  mid.act = [](FakeRobot& r) { r.e_stop = true; };
  auto run = makeRun();
  const Outcome outcome = runToEnd(run, robot, mid.script());
  ASSERT_GE(mid.at, 0);
  EXPECT_EQ(outcome.exit_status, 1);
  EXPECT_TRUE(contains(outcome.err, "calibrate_base: aborted: the e-stop engaged")) << outcome.err;
  expectStoppedAtOnce(outcome, mid.at);
  EXPECT_FALSE(contains(outcome.out, "effective wheel_separation"));
}

// An e-stop of 0.3 s mid-turn (far shorter than a diagnostics period): the run ends with the base
// stopped and never resumes the turn after the release.
TEST(TurnCalibrationRun, ABriefEStopMidTurnEndsTheRunForGood) {
  FakeRobot robot;
  MidTurn mid;
  mid.act = [](FakeRobot& r) { r.e_stop = true; };
  auto run = makeRun();
  const Outcome outcome = runToEnd(run, robot, [&](double t, FakeRobot& r) {
    if (mid.at >= 0 && t >= mid.at + 0.3) r.e_stop = false;  // released
    return mid.script()(t, r);
  });
  ASSERT_GE(mid.at, 0);
  EXPECT_EQ(outcome.exit_status, 1);
  EXPECT_TRUE(contains(outcome.err,
                       "calibrate_base: aborted: the e-stop engaged; the run never resumes after "
                       "a release"))
      << outcome.err;
  expectStoppedAtOnce(outcome, mid.at);
  EXPECT_FALSE(contains(outcome.out, "turning counter-clockwise: done"));
}

// Engaged and released between two of the tool's looks: only the driver's count of engagements
// shows it. The run ends all the same.
TEST(TurnCalibrationRun, AnEngagementOnlyTheDriversCountShowsEndsTheRun) {
  FakeRobot robot;
  robot.e_stop_visible = false;
  MidTurn mid;
  mid.act = [](FakeRobot& r) { ++r.engagements; };
  auto run = makeRun();
  const Outcome outcome = runToEnd(run, robot, mid.script());
  ASSERT_GE(mid.at, 0);
  EXPECT_EQ(outcome.exit_status, 1);
  EXPECT_TRUE(contains(outcome.err, "calibrate_base: aborted: the e-stop engaged")) << outcome.err;
  expectStoppedAtOnce(outcome, mid.at);
}

// Between the turns the run holds the base still; an e-stop then (engaged for one step) ends it
// too: the clockwise turn never starts.
TEST(TurnCalibrationRun, AnEStopDuringTheHoldBetweenTheTurnsEndsTheRun) {
  FakeRobot robot;
  double at = -1;
  auto run = makeRun();
  const Outcome outcome = runToEnd(run, robot, [&](double t, FakeRobot& r) {
    const bool holding = r.first_moving_frame && r.command.angular == 0 && r.left == 0;
    if (at < 0 && holding) {
      at = t;
      r.e_stop = true;
    } else if (at >= 0) {
      r.e_stop = false;
    }
    return 0;
  });
  ASSERT_GE(at, 0);
  EXPECT_EQ(outcome.exit_status, 1);
  EXPECT_TRUE(contains(outcome.err, "calibrate_base: aborted: the e-stop engaged")) << outcome.err;
  EXPECT_FALSE(outcome.anyMovingCommandFrom(at));
  EXPECT_FALSE(contains(outcome.out, "turning clockwise: done"));
}

TEST(TurnCalibrationRun, TelemetryLostMidTurnStopsAndEndsRefused) {
  FakeRobot robot;
  MidTurn mid;
  mid.act = [](FakeRobot& r) { r.telemetry = false; };
  auto run = makeRun();
  const Outcome outcome = runToEnd(run, robot, mid.script());
  ASSERT_GE(mid.at, 0);
  EXPECT_EQ(outcome.exit_status, 1);
  EXPECT_TRUE(contains(outcome.err, "aborted: telemetry stopped (no imu/data for 0.5 s)"))
      << outcome.err;
  // Found stale 0.5 s after the last sample (the step before mid.at), zero in that very step.
  double first_zero = -1;
  for (const auto& [at, twist] : outcome.commands) {
    if (at >= mid.at && Outcome::isZero(twist)) {
      first_zero = at;
      break;
    }
  }
  EXPECT_GE(first_zero, mid.at + 0.45);
  EXPECT_LE(first_zero, mid.at + 0.55);
  expectStoppedAtOnce(outcome, first_zero);
}

TEST(TurnCalibrationRun, WheelFramesStoppingMidTurnAbortsAndLeavesTheStopToTheNodesTimeout) {
  FakeRobot robot;
  MidTurn mid;
  mid.act = [](FakeRobot& r) { r.frames = false; };
  auto run = makeRun();
  const Outcome outcome = runToEnd(run, robot, mid.script());
  EXPECT_EQ(outcome.exit_status, 1);
  EXPECT_TRUE(contains(outcome.err, "aborted: the node stopped writing wheel frames"))
      << outcome.err;
  EXPECT_TRUE(contains(outcome.err, "the node's ~base/cmd_vel_timeout stops the base"));
  EXPECT_FALSE(outcome.anyMovingCommandFrom(mid.at + 0.55));
}

class CalibrationStopRequest : public ::testing::TestWithParam<std::pair<int, std::string>> {};

TEST_P(CalibrationStopRequest, MidTurnStopsAtOnceAndExitsWith128PlusTheSignal) {
  FakeRobot robot;
  MidTurn mid;
  mid.signal = GetParam().first;
  auto run = makeRun();
  const Outcome outcome = runToEnd(run, robot, mid.script());
  ASSERT_GE(mid.at, 0);
  EXPECT_EQ(outcome.exit_status, 128 + GetParam().first);
  EXPECT_TRUE(contains(outcome.err, "calibrate_base: " + GetParam().second)) << outcome.err;
  expectStoppedAtOnce(outcome, mid.at);
}

INSTANTIATE_TEST_SUITE_P(Signals, CalibrationStopRequest,
                         ::testing::Values(std::make_pair(SIGINT, "interrupted (SIGINT)"),
                                           std::make_pair(SIGTERM, "terminated")));

TEST(TurnCalibrationRun, NothingTypedAtTheDistancePromptEndsRefused) {
  FakeRobot robot;  // typed_distance unset: nothing could be read
  CalibrationOptions options = quickOptions();
  options.distance = 0.3;
  auto run = makeRun(options);
  const Outcome outcome = runToEnd(run, robot);
  ASSERT_TRUE(robot.prompted);
  EXPECT_EQ(outcome.exit_status, 1);
  EXPECT_TRUE(contains(outcome.err, "calibrate_base: no distance typed: no wheel_diameter"))
      << outcome.err;
  EXPECT_TRUE(contains(outcome.err, "base stopped (a zero wheel frame was written)"));
}

TEST(TurnCalibrationRun, ASignalAtTheDistancePromptStopsTheBaseWith128PlusTheSignal) {
  FakeRobot robot;
  CalibrationOptions options = quickOptions();
  options.distance = 0.3;
  auto run = makeRun(options);
  double sent_at = -1;
  // The signal interrupted the read: nothing typed, and the signal arrives with the next step.
  const Outcome outcome = runToEnd(run, robot, [&](double t, FakeRobot& r) {
    if (!r.prompted || sent_at >= 0) return 0;
    sent_at = t;
    return SIGINT;
  });
  ASSERT_GE(sent_at, 0);
  EXPECT_EQ(outcome.exit_status, 130);
  EXPECT_TRUE(contains(outcome.err, "calibrate_base: interrupted (SIGINT)")) << outcome.err;
  EXPECT_FALSE(contains(outcome.err, "no distance typed"));
  expectStoppedAtOnce(outcome, sent_at);
}

TEST(TurnCalibrationRun, NoZeroFrameWithinTheBoundLeavesTheStopToTheNodesTimeout) {
  FakeRobot robot;
  MidTurn mid;
  mid.signal = SIGINT;
  mid.act = [](FakeRobot& r) { r.ignores_zero = true; };
  auto run = makeRun();
  const Outcome outcome = runToEnd(run, robot, mid.script());
  ASSERT_GE(mid.at, 0);
  EXPECT_EQ(outcome.exit_status, 130);
  EXPECT_TRUE(contains(outcome.err,
                       "calibrate_base: no zero wheel frame written within 3 s of the stop; the "
                       "node's ~base/cmd_vel_timeout stops the base"))
      << outcome.err;
  EXPECT_FALSE(contains(outcome.err, "base stopped"));
  EXPECT_FALSE(outcome.anyMovingCommandFrom(mid.at));
  // Zero repeated until the bound, then the tool gives up.
  EXPECT_GE(outcome.end - mid.at, 3.0);
  EXPECT_LT(outcome.end - mid.at, 3.5);
  std::size_t zeros = 0;
  for (const auto& [at, twist] : outcome.commands) zeros += at >= mid.at ? 1 : 0;
  EXPECT_GE(zeros, 50u);  // every 0.05 s for 3 s
}

TEST(TurnCalibrationRun, RefusedWithTheEStopEngagedBeforeMoving) {
  FakeRobot robot;
  robot.e_stop = true;
  auto run = makeRun();
  const Outcome outcome = runToEnd(run, robot);
  EXPECT_EQ(outcome.exit_status, 1);
  EXPECT_TRUE(contains(outcome.err,
                       "calibrate_base: refused: the e-stop is engaged; release it (e_stop false) "
                       "and run again"))
      << outcome.err;
  EXPECT_FALSE(contains(outcome.out, "turning"));
  EXPECT_FALSE(outcome.anyMovingCommandFrom(0));
}

// The driver's e_stop status, as its values read on /diagnostics: "engaged" refuses the run, a
// rise of "engagements" ends it.
TEST(TurnCalibrationRun, TheEStopStatusValuesSayTheEStop) {
  FakeRobot engaged;
  engaged.status_values = true;
  engaged.e_stop = true;
  auto run = makeRun();
  Outcome outcome = runToEnd(run, engaged);
  EXPECT_EQ(outcome.exit_status, 1);
  EXPECT_TRUE(contains(outcome.err, "calibrate_base: refused: the e-stop is engaged"))
      << outcome.err;
  EXPECT_FALSE(outcome.anyMovingCommandFrom(0));

  FakeRobot counted;
  counted.status_values = true;
  counted.e_stop_visible = false;
  counted.engagements = 4294967296;  // beyond 32 bits
  MidTurn mid;
  mid.act = [](FakeRobot& r) { ++r.engagements; };
  auto second = makeRun();
  outcome = runToEnd(second, counted, mid.script());
  ASSERT_GE(mid.at, 0) << "released: the run moved";
  EXPECT_EQ(outcome.exit_status, 1);
  EXPECT_TRUE(contains(outcome.err, "calibrate_base: aborted: the e-stop engaged")) << outcome.err;
  expectStoppedAtOnce(outcome, mid.at);
}

TEST(TurnCalibrationRun, LinesGoToTheirStreams) {
  std::ostringstream out, err;
  printCalibrationLines({{CalibrationLine::Stream::kOut, "a"},
                         {CalibrationLine::Stream::kErr, "b"},
                         {CalibrationLine::Stream::kPrompt, "c? "},
                         {CalibrationLine::Stream::kOut, ""}},
                        out, err);
  EXPECT_EQ(out.str(), "a\nc? \n");
  EXPECT_EQ(err.str(), "b\n");
}

TEST(TurnCalibrationRun, WhyNoDriverWasFound) {
  EXPECT_EQ(noCalibrationDriverText(SIGINT, false, "/w"), "interrupted (SIGINT)");
  EXPECT_EQ(noCalibrationDriverText(SIGTERM, true, "/w"), "terminated");
  EXPECT_EQ(noCalibrationDriverText(0, false, "/w"), "ROS shut down");
  EXPECT_EQ(
      noCalibrationDriverText(0, true, "/robot1/wheel_command"),
      "no driver publishes /robot1/wheel_command: start it first (roslaunch "
      "serial_robot_driver sim.launch), or run the tool in its namespace (ROS_NAMESPACE=...)");
}

TEST(TurnCalibrationRun, RefusedWithoutTelemetryBeforeMoving) {
  FakeRobot robot;
  robot.telemetry = false;
  auto run = makeRun();
  const Outcome outcome = runToEnd(run, robot);
  EXPECT_EQ(outcome.exit_status, 1);
  EXPECT_TRUE(contains(outcome.err, "calibrate_base: refused: no telemetry on /imu/data in 3 s"))
      << outcome.err;
  EXPECT_GE(outcome.end, 3.0);
  EXPECT_LT(outcome.end, 3.5);
  EXPECT_FALSE(contains(outcome.out, "turning"));
  EXPECT_FALSE(outcome.anyMovingCommandFrom(0));
}

TEST(CalibrationOptions, DefaultsAndValues) {
  auto parsed = serial_robot_driver::devices::base::parseCalibrationOptions({});
  ASSERT_TRUE(parsed.options);
  EXPECT_DOUBLE_EQ(parsed.options->rate, 1.0);
  EXPECT_NEAR(parsed.options->angle, 6.2832, 1e-4);
  EXPECT_EQ(parsed.options->distance, 0.0);
  EXPECT_FALSE(parsed.options->measured);
  parsed = serial_robot_driver::devices::base::parseCalibrationOptions(
      {"--rate", "0.5", "--angle", "12.57", "--distance", "1", "--measured", "0.98", "--node",
       "/robot1/driver_node", "--settle", "1", "--speed", "0.3"});
  ASSERT_TRUE(parsed.options) << parsed.error;
  EXPECT_DOUBLE_EQ(parsed.options->rate, 0.5);
  EXPECT_DOUBLE_EQ(parsed.options->angle, 12.57);
  EXPECT_DOUBLE_EQ(parsed.options->distance, 1.0);
  EXPECT_DOUBLE_EQ(*parsed.options->measured, 0.98);
  EXPECT_EQ(parsed.options->node, "/robot1/driver_node");
  EXPECT_DOUBLE_EQ(parsed.options->settle, 1.0);
  EXPECT_DOUBLE_EQ(parsed.options->speed, 0.3);
  EXPECT_TRUE(
      serial_robot_driver::devices::base::parseCalibrationOptions({"--rate", "2", "--help"}).help);
  EXPECT_TRUE(serial_robot_driver::devices::base::parseCalibrationOptions({"-h"}).help);
}

TEST(CalibrationOptions, BadOptionsAreRefusedWithTheReason) {
  const std::vector<std::pair<std::vector<std::string>, std::string>> cases = {
      {{"--rate", "9"}, "--rate must be a number in 0.05..5, not 9"},
      {{"--rate", "1x"}, "--rate must be a number in 0.05..5, not 1x"},
      {{"--angle", "0.1"}, "--angle must be a number in 0.5..40, not 0.1"},
      {{"--settle", "nan"}, "--settle must be a number in 0.1..5, not nan"},
      {{"--angle"}, "--angle needs a value"},
      {{"--node"}, "unknown option --node (--help lists them)"},
      {{"--turbo"}, "unknown option --turbo (--help lists them)"},
  };
  for (const auto& [args, error] : cases) {
    const auto parsed = serial_robot_driver::devices::base::parseCalibrationOptions(args);
    EXPECT_FALSE(parsed.options) << args[0];
    EXPECT_FALSE(parsed.help);
    EXPECT_EQ(parsed.error, error);
  }
}

}  // namespace
