// The trajectory executor's test rig (test_trajectory_executor*.cpp): two streamed joints and a
// per-segment one whose every call is recorded, on a clock the tests step by hand.
#pragma once

#include <gtest/gtest.h>

#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "serial_robot_driver/trajectory/executor.h"

// Not in an anonymous namespace: the test files of one binary share the fixture class.
namespace serial_robot_driver::trajectory::test {

constexpr double kEps = 1e-9;

/// What a goal was told.
struct GoalLog {
  int accepted = 0;
  std::vector<GoalFeedback> feedback;
  std::vector<GoalOutcome> outcomes;

  GoalCallbacks callbacks() {
    return {[this] { ++accepted; }, [this](const GoalFeedback& f) { feedback.push_back(f); },
            [this](const GoalOutcome& o) { outcomes.push_back(o); }};
  }
  bool over() const { return !outcomes.empty(); }
  const GoalOutcome& outcome() const { return outcomes.at(0); }
};

/// Two streamed joints (arm_1, arm_2: the body) and one per-segment joint (pan: a bus servo),
/// every call they get recorded, on a clock at 100 s.
class ExecutorRig : public ::testing::Test {
 protected:
  using Frame = std::pair<std::vector<std::string>, std::vector<double>>;

  ExecutorRig()
      : executor(
            groups(), defaults(), [this] { return now; }, warner()) {
    executor.start();
  }

  static GoalDefaults defaults() {
    GoalDefaults d;
    d.goal_tolerance = 0.05;
    d.goal_time_tolerance = 0.5;
    return d;
  }

  std::vector<TrajectoryJoints> groups() {
    TrajectoryJoints body;
    body.joints = {{"arm_1", -3.0, 3.0}, {"arm_2", -3.0, 3.0}};
    body.write = [this](const std::vector<std::string>& names, const std::vector<double>& p,
                        std::optional<uint64_t> accepted) {
      if (during_write) during_write();
      frames.emplace_back(names, p);
      frame_generations.push_back(accepted);
      // As the body's gate: a frame accepted before the last e-stop is not written.
      if (accepted && *accepted != body_generation) return std::string("voided");
      return write_error;
    };
    body.generation = [this] { return body_generation; };
    body.last_commanded = [this](std::size_t) { return body_last_commanded; };
    TrajectoryJoints bus;
    bus.joints = {{"pan", -3.0, 3.0}};
    bus.move = [this](std::size_t index, double position, double duration) {
      moves.emplace_back(index, position, duration);
      return std::string();
    };
    bus.stop = [this](std::size_t index) {
      stops.push_back(index);
      return std::string();
    };
    return {body, bus};
  }

  TrajectoryExecutor::Warn warner() {
    return [this](const std::string& text) { warnings.push_back(text); };
  }

  void measure(const std::vector<std::string>& names, const std::vector<double>& positions,
               const std::vector<double>& velocities = {}) {
    executor.updateActual(names, positions, velocities);
  }

  /// A goal moving `names` to `positions` in `seconds`, starting at once.
  static Goal goalTo(const std::vector<std::string>& names, const std::vector<double>& positions,
                     double seconds = 1.0, const std::string& id = "g") {
    Goal goal;
    goal.id = id;
    goal.command.joint_names = names;
    goal.command.points.push_back({seconds, positions, {}, {}});
    return goal;
  }

  /// Steps the clock to `time`, then ticks.
  void tickAt(double time) {
    now = time;
    executor.tick();
  }

  double now = 100.0;
  uint64_t body_generation = 0;        ///< the body gate's e-stop generation
  std::function<void()> during_write;  ///< runs inside each body write
  std::vector<Frame> frames;
  std::vector<std::optional<uint64_t>> frame_generations;  ///< what each frame was written with
  std::string write_error;
  std::optional<double> body_last_commanded;
  std::vector<std::tuple<std::size_t, double, double>> moves;
  std::vector<std::size_t> stops;
  std::vector<std::string> warnings;
  TrajectoryExecutor executor;
};

}  // namespace serial_robot_driver::trajectory::test
