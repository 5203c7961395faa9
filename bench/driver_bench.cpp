// driver_bench: end-to-end performance numbers of driver_node, measured from the outside the way a
// robot sees it: bytes on a pseudo-terminal and messages on ROS topics/services.
//
// One run starts its own roscore, then one driver_node (and robot_sim) per measurement:
//  1. cmd_vel publish -> speed frame's last byte on the pty (p50/p99)
//  2. base loop period at 50 Hz from pty arrival times (std, worst, missed ticks)
//  3. node CPU while idle at 50 Hz
//  4. telemetry frame's last byte written -> joint_states received (p50/p99), node CPU at 100 Hz
//  5. delivered fraction of telemetry at 100 .. 5000 Hz
//  6. servo/read round trip (new connection per call and persistent), wheel loop under service
//  stress
//  7. 1, 4 and 5 again with polling_driver_node (the same node reading every 20 ms), and the ratios
//  8. the configuration users run (every default device, 20 body servos at 100 Hz, the topics a
//     user subscribes) against floor_node (bench/floor_node.cpp, the least a roscpp driver must
//     do), side by side, quiet and under a CPU hog per core, ~realtime_priority off and on: CPU,
//     cmd_vel latency, telemetry latency, loop jitter, and the ratios node / floor; the robot
//     played over a pty and over loopback TCP (no pty worker in the path), per --transport; with
//     RT off, CPU also with the node and the same-job floor streaming in one window
//  9. ~capture on vs off: base loop period and CPU (2, 3), telemetry -> joint_states and CPU (4),
//     with a subscriber on serial_raw as rosbag record would be
// 10. the servo bus at the wire's pace: READ_ANGLE transactions per second and CPU per
//     transaction of servo_states (20 servos) against servo_floor (bench/servo_floor.cpp, one
//     blocking request/answer loop), on robot_sim at pty speed and paced at 115200 baud; and how
//     closely the paced robot_sim keeps to the line's time
// 11. (not run by default) the earlier comparison with the floor: each device alone, one
//     subscriber (joint_states), idle loop; kept to show how far that differs from section 8
// Run it through bench/run_benchmarks.sh; `driver_bench --help` lists the knobs.
#include <diagnostic_msgs/DiagnosticArray.h>
#include <geometry_msgs/Twist.h>
#include <nav_msgs/Odometry.h>
#include <ros/ros.h>
#include <sched.h>
#include <sensor_msgs/Imu.h>
#include <sensor_msgs/JointState.h>
#include <tf2_msgs/TFMessage.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <map>
#include <mutex>
#include <optional>
#include <random>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "bench_support.h"
#include "robot_end.h"
#include "ros_bench_support.h"
#include "serial_robot_driver/SerialChunk.h"
#include "serial_robot_driver/ServoRead.h"
#include "serial_robot_driver/WheelCommand.h"
#include "serial_robot_driver/devices/base/base_codec.h"
#include "serial_robot_driver/devices/body/body_codec.h"
#include "support/pty_frame_reader.h"

namespace serial_robot_driver::bench {
namespace {

namespace base = devices::base;
namespace body = devices::body;
using namespace std::chrono_literals;
using test_support::PtyFrameReader;

// --- options ------------------------------------------------------------------------------------

struct Options {
  bool long_run = false;
  std::set<int> sections{1, 2, 3, 4, 5, 6, 7, 8, 9, 10};
  std::string output;                   ///< Markdown copy of the results; "" = none
  std::string bin_dir;                  ///< "" = the directory of this executable
  int master_port = 0;                  ///< 0 = any free port
  std::size_t commands = 1000;          ///< 1: cmd_vel commands timed
  double loop_seconds = 20;             ///< 2, 3: idle loop window
  std::size_t telemetry_frames = 1000;  ///< 4: frames timed at 100 Hz
  double rate_step_seconds = 2;         ///< 5: length of each rate step
  std::vector<double> rates{100, 200, 500, 1000, 2000, 5000};
  std::size_t service_calls = 200;  ///< 6: calls timed per client kind
  double stress_seconds = 5;        ///< 6: idle and stress windows of the wheel loop
  std::size_t floor_rounds = 1;     ///< 8, 11: node/floor rounds
  std::set<std::string> conditions;  ///< 8: the conditions run (UserCondition::tag()); empty: all
  double bus_seconds = 5;           ///< 10: window of each servo bus run
  std::string realtime_priority = "50";  ///< 8: ~realtime_priority when RT is on
  int node_slice_us = -1;  ///< 8: driver_node's ~scheduler_slice_us; -1: its default
  int floor_slice_us = 0;  ///< 8: the floors' ~scheduler_slice_us; 0: the kernel's slice
  int control_slice_us = -1;  ///< 8: the control's second driver_node's; -1: as driver_node's
  /// 8: the control's second driver_node, another build of it; "" = bin_dir's
  std::string control_bin;
  int bench_priority = 90;               ///< SCHED_FIFO of this process's threads; 0: normal
  /// 8: the lines the robot is played on, in this order within each condition.
  std::vector<Transport> transports{Transport::kPty, Transport::kTcp};
  double tcp_window = 0;  ///< 8: TCP sessions' share of the frames and commands; 0: tcpWindow()

  bool runs(int section) const { return sections.count(section) > 0; }
  /// With both transports a TCP session takes half a pty session's frames and commands (the
  /// default run stays under 9 minutes); over TCP alone all of them.
  double tcpWindow() const {
    if (tcp_window > 0) return tcp_window;
    return transports.size() > 1 ? 0.5 : 1.0;
  }
};

const char* const kUsage = R"(usage: driver_bench [options]
  --long                  longer runs (5000 commands, 120 s loop window, 6000 frames, ...)
  --sections 1,2,...      run only these sections (default 1-10; 7 repeats those of 1, 4, 5
                          that run; 8 compares driver_node in the configuration users run
                          with floor_node, quiet and loaded, RT off and on; 9 repeats 2, 3,
                          4 with ~capture, and runs 2-4 without it if they did not run;
                          11 is the earlier per-device comparison with floor_node)
  --floor-rounds N        8, 11: node/floor rounds, each with its share of the frames and
                          commands (default 1); 8 pools the rounds' samples for its
                          percentiles and lists each round's node / same-job ratio too
  --conditions A,B,...    8: only these conditions (quiet, quiet_rt, load, load_rt; default
                          all); the others' cells stay empty
  --realtime-priority V   8: the ~realtime_priority given for "RT on" (default 50; "true"
                          passes a bool)
  --node-slice US         8: driver_node's ~scheduler_slice_us (default: its own, 100; 0: the
                          kernel's slice, as before the parameter existed)
  --floor-slice US        8: the floors' ~scheduler_slice_us (default 0: the kernel's slice, as
                          a minimal driver has it; 100: the same request as driver_node's)
  --control-slice US      8: the control's second driver_node's ~scheduler_slice_us (default:
                          as driver_node's), so the control measures what the slice costs
  --control-bin PATH      8: the control's second driver_node is this executable (another
                          build, e.g. of the code before a change), so the control row is
                          that change measured side by side in one window (default: the
                          same driver_node)
  --transport T           8: the line the robot is played on: pty (the program opens a
                          pseudo-terminal; the kernel's pty worker carries the bytes), tcp
                          (the program connects to tcp://127.0.0.1:<port>, where this
                          benchmark listens: no pty worker, the programs' own latency) or
                          both (default: each condition over the pty, then over TCP; a
                          summary and a table of every figure per transport)
  --tcp-window F          8: a TCP session's share of the frames and commands of a pty
                          session (default 0.5 with both transports, 1 with tcp alone)
  --bench-priority N      SCHED_FIFO priority of this benchmark's own threads, so a load
                          delays the node, not the measuring (default 90; 0: normal)
  --bus-seconds S         10: window of each servo bus run (default 5)
  --output FILE           also write the results (Markdown) to FILE
  --bin-dir DIR           where driver_node and robot_sim are (default: next to driver_bench)
  --master-port N         port of the private roscore (default: a free one)
  --commands N            1: cmd_vel commands timed (default 1000)
  --loop-seconds S        2/3: idle window (default 20)
  --telemetry-frames N    4: telemetry frames timed at 100 Hz (default 1000)
  --rate-step-seconds S   5: length of each rate step (default 2)
  --service-calls N       6: servo/read calls per client kind (default 200)
  --stress-seconds S      6: idle and stress windows of the wheel loop (default 5)
)";

std::set<int> parseSections(const std::string& text) {
  std::set<int> sections;
  std::stringstream stream(text);
  std::string item;
  while (std::getline(stream, item, ',')) {
    const int section = std::stoi(item);
    if (section < 1 || section > 11) throw std::invalid_argument("no section " + item);
    sections.insert(section);
  }
  return sections;
}

std::vector<Transport> parseTransports(const std::string& text) {
  if (text == "pty") return {Transport::kPty};
  if (text == "tcp") return {Transport::kTcp};
  if (text == "both") return {Transport::kPty, Transport::kTcp};
  throw std::invalid_argument("--transport takes pty, tcp or both, not " + text);
}

std::set<std::string> splitList(const std::string& text) {
  std::set<std::string> items;
  std::stringstream stream(text);
  std::string item;
  while (std::getline(stream, item, ',')) items.insert(item);
  return items;
}

/// --long's windows.
void lengthen(Options& options) {
  options.long_run = true;
  options.commands = 5000;
  options.loop_seconds = 120;
  options.telemetry_frames = 6000;
  options.rate_step_seconds = 10;
  options.service_calls = 2000;
  options.stress_seconds = 30;
  options.bus_seconds = 20;
}

Options parseOptions(int argc, char** argv) {
  Options options;
  // --long first, so explicit knobs override it wherever they stand.
  for (int i = 1; i < argc; ++i) {
    if (std::string(argv[i]) == "--long") lengthen(options);
  }
  for (int i = 1; i < argc; ++i) {
    const std::string flag = argv[i];
    if (flag == "--long" || flag.find(":=") != std::string::npos) continue;  // ROS remappings
    if (flag == "--help" || flag == "-h") {
      std::cout << kUsage;
      std::exit(0);
    }
    if (i + 1 >= argc) throw std::invalid_argument("unknown flag or missing value: " + flag);
    const std::string value = argv[++i];
    if (flag == "--sections") {
      options.sections = parseSections(value);
    } else if (flag == "--output") {
      options.output = value;
    } else if (flag == "--bin-dir") {
      options.bin_dir = value;
    } else if (flag == "--master-port") {
      options.master_port = std::stoi(value);
    } else if (flag == "--commands") {
      options.commands = std::stoul(value);
    } else if (flag == "--loop-seconds") {
      options.loop_seconds = std::stod(value);
    } else if (flag == "--telemetry-frames") {
      options.telemetry_frames = std::stoul(value);
    } else if (flag == "--rate-step-seconds") {
      options.rate_step_seconds = std::stod(value);
    } else if (flag == "--service-calls") {
      options.service_calls = std::stoul(value);
    } else if (flag == "--floor-rounds") {
      options.floor_rounds = std::max<std::size_t>(1, std::stoul(value));
    } else if (flag == "--conditions") {
      options.conditions = splitList(value);
    } else if (flag == "--transport") {
      options.transports = parseTransports(value);
    } else if (flag == "--tcp-window") {
      options.tcp_window = std::stod(value);
    } else if (flag == "--realtime-priority") {
      options.realtime_priority = value;
    } else if (flag == "--node-slice") {
      options.node_slice_us = std::stoi(value);
    } else if (flag == "--floor-slice") {
      options.floor_slice_us = std::stoi(value);
    } else if (flag == "--control-slice") {
      options.control_slice_us = std::stoi(value);
    } else if (flag == "--control-bin") {
      if (::access(value.c_str(), X_OK) != 0) {
        throw std::invalid_argument("--control-bin: no executable at " + value);
      }
      // Absolute, so that the process that starts it reads it as a path, not a name in bin_dir.
      options.control_bin = std::filesystem::absolute(value).string();
    } else if (flag == "--bench-priority") {
      options.bench_priority = std::stoi(value);
    } else if (flag == "--bus-seconds") {
      options.bus_seconds = std::stod(value);
    } else if (flag == "--stress-seconds") {
      options.stress_seconds = std::stod(value);
    } else {
      throw std::invalid_argument("unknown flag: " + flag);
    }
  }
  return options;
}

// --- shared measurement pieces ------------------------------------------------------------------

constexpr double kLoopRate = 50.0;
constexpr double kLoopPeriodMs = 1000.0 / kLoopRate;

/// How the node reads its port: driver_node itself, or polling_driver_node (the same node with a
/// stream that reads once per ~read_poll_interval).
struct Variant {
  std::string name;
  std::string tag;  ///< part of the node namespace
  std::string program;
  double read_poll_interval;    ///< 0: event-driven
  bool spaced_cmd_vel = false;  ///< section 11: commands 10-40 ms apart instead of one per tick
  bool capture = false;         ///< ~capture on, with a subscriber on serial_raw
  /// floor_node's ~same_job and ~same_interface: the user's topics and driver_node's interface,
  /// done minimally.
  bool same_job = false;
  /// The control's second driver_node (section 8, at once): --control-slice applies to it.
  bool control_copy = false;
};
const Variant kEventDriven{"event-driven", "event", "driver_node", 0.0};
const Variant kPolling{"polling 20 ms", "poll", "polling_driver_node", 0.02};
const Variant kFloor{"floor", "floor", "floor_node", 0.0, true};
const Variant kSameJobFloor{"same-job floor", "floorjob", "floor_node", 0.0, true, false, true};
const Variant kCapturing{"capture on", "capture", "driver_node", 0.0, false, true};
const Variant kControlCopy{"event-driven", "event", "driver_node", 0.0, false, false, false, true};

struct Context {
  Options options;
  RunPaths paths;
  ros::NodeHandle nh;
  ResultTable results;
  std::size_t failures = 0;  ///< measurements that could not complete
  int bench_priority = 0;    ///< SCHED_FIFO priority this process's threads run at; 0: normal
  /// Section 8: statuses per /diagnostics message of driver_node (the same-job floor's count).
  std::size_t node_diagnostic_statuses = 0;
  std::size_t node_diagnostic_values = 0;  ///< their key/values in all (the same-job floor's)
};

void require(bool condition, const std::string& what) {
  if (!condition) throw std::runtime_error(stopRequested() ? "stopped by a signal" : what);
}

ParamList commonParams(const std::string& port, const Variant& variant) {
  ParamList params = {{"port", port}, {"loop_rate", kLoopRate}, {"reconnect_interval", 0.2}};
  if (variant.read_poll_interval > 0)
    params.emplace_back("read_poll_interval", variant.read_poll_interval);
  if (variant.capture) params.emplace_back("capture", true);
  if (variant.same_job) {
    params.emplace_back("same_job", true);
    params.emplace_back("same_interface", true);
  }
  return params;
}

struct LatencyResult {
  Summary ms;
  std::size_t attempted = 0;
  std::size_t lost = 0;  ///< no answer/frame within the timeout (or a failed call)
  std::vector<double> samples_ms;  ///< what `ms` summarizes (section 8 pools them over rounds)
};

LatencyResult latencyResult(const std::vector<double>& samples_ms, std::size_t attempted) {
  return {summarize(samples_ms), attempted, attempted - samples_ms.size(), samples_ms};
}

struct LoopResult {
  Summary period_ms;
  std::size_t missed_ticks = 0;
  double cpu_percent = 0;
  std::vector<double> periods_ms;  ///< what `period_ms` summarizes
};

/// Periods between consecutive event times (s); a period of k nominal periods missed k-1 ticks.
LoopResult analyzePeriods(const std::vector<double>& times_s) {
  LoopResult result;
  std::vector<double> periods_ms;
  for (std::size_t i = 1; i < times_s.size(); ++i) {
    const double period_ms = (times_s[i] - times_s[i - 1]) * 1e3;
    periods_ms.push_back(period_ms);
    const long ticks = std::lround(period_ms / kLoopPeriodMs);
    if (ticks > 1) result.missed_ticks += static_cast<std::size_t>(ticks - 1);
  }
  result.period_ms = summarize(periods_ms);
  result.periods_ms = std::move(periods_ms);
  return result;
}

std::string ms(double value) { return format("%.3f ms", value); }
std::string percent(double value) { return format("%.2f %%", value); }

/// Rows p50 / p99 / max of a latency measurement, the p99 checked against `p99_goal_ms`.
void addLatencyRows(ResultTable& table, const std::string& what, const LatencyResult& result,
                    std::optional<double> p99_goal_ms) {
  table.row(what + ": samples (lost)", format("%zu (%zu)", result.ms.count, result.lost), "",
            result.lost == 0);
  table.row(what + ": p50", ms(result.ms.p50));
  if (p99_goal_ms) {
    table.row(what + ": p99", ms(result.ms.p99), format("<= %.1f ms", *p99_goal_ms),
              result.ms.count > 0 && result.ms.p99 <= *p99_goal_ms);
  } else {
    table.row(what + ": p99", ms(result.ms.p99));
  }
  table.row(what + ": max", ms(result.ms.max));
}

void addLoopRows(ResultTable& table, const std::string& what, const LoopResult& loop,
                 bool with_goals) {
  const Summary& p = loop.period_ms;
  table.row(what + ": periods", format("%zu, mean %.3f ms", p.count, p.mean));
  if (with_goals) {
    table.row(what + ": period std", ms(p.stddev), "<= 0.1 ms", p.stddev <= 0.1);
    table.row(what + ": worst period", ms(p.max), "<= 22 ms", p.max <= 22.0);
    table.row(what + ": missed ticks", format("%zu", loop.missed_ticks), "0",
              loop.missed_ticks == 0);
  } else {
    table.row(what + ": period std", ms(p.stddev));
    table.row(what + ": worst period", ms(p.max));
    table.row(what + ": missed ticks", format("%zu", loop.missed_ticks));
  }
}

// --- base: speed frames on the pty --------------------------------------------------------------

struct SpeedFrame {
  Clock::time_point arrival;
  int16_t left = 0;
  int16_t right = 0;
};

/// Every wheel-speed frame the node wrote, in order, with its pty arrival time.
class SpeedFrameLog {
 public:
  void onFrame(protocol::FrameFamily family, const uint8_t* data, std::size_t size,
               Clock::time_point arrival) {
    if (family != devices::base::kFrames) return;
    const auto frame = base::decodeFrame(data, size);
    if (!frame || frame->msg_id != static_cast<uint8_t>(base::MsgId::kWheelSpeed)) return;
    const auto speed = base::interpretWheelSpeed(*frame);
    if (!speed) return;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      frames_.push_back({arrival, speed->left_ticks, speed->right_ticks});
    }
    arrived_.notify_all();
  }

  std::size_t count() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return frames_.size();
  }

  /// Frame number `index` (0-based), waiting for it until `deadline`.
  std::optional<SpeedFrame> waitFor(std::size_t index, Clock::time_point deadline) const {
    std::unique_lock<std::mutex> lock(mutex_);
    if (!arrived_.wait_until(lock, deadline, [&] { return frames_.size() > index; })) return {};
    return frames_[index];
  }

  /// Copies of frames [begin, count()).
  std::vector<SpeedFrame> framesFrom(std::size_t begin) const {
    std::lock_guard<std::mutex> lock(mutex_);
    if (begin >= frames_.size()) return {};
    return {frames_.begin() + static_cast<std::ptrdiff_t>(begin), frames_.end()};
  }

  /// Arrival times (s) of frames [begin, end).
  std::vector<double> arrivalSeconds(std::size_t begin, std::size_t end) const {
    std::lock_guard<std::mutex> lock(mutex_);
    std::vector<double> times;
    for (std::size_t i = begin; i < end && i < frames_.size(); ++i) {
      times.push_back(toSeconds(frames_[i].arrival.time_since_epoch()));
    }
    return times;
  }

 private:
  mutable std::mutex mutex_;
  mutable std::condition_variable arrived_;
  std::vector<SpeedFrame> frames_;
};

/// Times cmd_vel -> first speed frame carrying it. Each command is published 12 ms after a speed
/// frame: past the node's rate limit (no immediate frame within half a period of the last one),
/// so what is timed is the path, not the rate limit. Hence one command per loop period.
LatencyResult timeCmdVel(ros::Publisher& publisher, const SpeedFrameLog& log,
                         std::size_t commands) {
  constexpr std::size_t kWarmUp = 20;
  constexpr auto kPublishAfterFrame = 12ms;
  constexpr auto kTimeout = 200ms;
  // Truncated ticks per PID period for a wheel speed (AP1 defaults; dithering off in the node).
  const double ticks_per_mps = 1600.0 / (0.25 * M_PI) / 50.0;

  std::vector<double> samples_ms;
  std::size_t measured = 0;
  std::size_t next = log.count();
  for (std::size_t i = 0; i < kWarmUp + commands && !stopRequested(); ++i) {
    const auto tick = log.waitFor(next, Clock::now() + kTimeout);
    require(tick.has_value(), "the node stopped writing speed frames");
    // 1..600 ticks: each command differs from the one before, so its first frame is recognised.
    const auto ticks = static_cast<int16_t>(1 + i % 600);
    geometry_msgs::Twist command;
    command.linear.x = (ticks + 0.5) / ticks_per_mps;
    std::this_thread::sleep_until(tick->arrival + kPublishAfterFrame);
    const Clock::time_point published = Clock::now();
    publisher.publish(command);

    std::optional<SpeedFrame> match;
    std::size_t index = next + 1;
    while (const auto frame = log.waitFor(index++, published + kTimeout)) {
      if (frame->left == ticks && frame->right == ticks) {
        match = frame;
        break;
      }
    }
    if (i >= kWarmUp) {
      ++measured;
      if (match) samples_ms.push_back(toMs(match->arrival - published));
    }
    // `index` is one past the match: the next loop tick, after which the next command goes.
    next = match ? index : log.count();
  }
  return latencyResult(samples_ms, measured);
}

/// Sections 8 and 11: cmd_vel commands 10-40 ms apart (uniform, fixed seed), not aligned with the
/// loop, each timed to the first speed frame carrying its ticks. A command overtaken by the next
/// one before any frame carries it counts as lost.
LatencyResult timeCmdVelSpaced(ros::Publisher& publisher, const SpeedFrameLog& log,
                               std::size_t commands) {
  constexpr std::size_t kWarmUp = 20;
  const double ticks_per_mps = 1600.0 / (0.25 * M_PI) / 50.0;
  std::mt19937 random(14);
  std::uniform_real_distribution<double> spacing_ms(10.0, 40.0);
  std::vector<Clock::time_point> published;
  std::vector<int16_t> sent_ticks;
  const std::size_t first_frame = log.count();
  for (std::size_t i = 0; i < kWarmUp + commands && !stopRequested(); ++i) {
    const auto ticks = static_cast<int16_t>(1 + i % 600);
    geometry_msgs::Twist command;
    command.linear.x = (ticks + 0.5) / ticks_per_mps;
    published.push_back(Clock::now());
    sent_ticks.push_back(ticks);
    publisher.publish(command);
    std::this_thread::sleep_for(fromSeconds(spacing_ms(random) / 1e3));
  }
  std::this_thread::sleep_for(100ms);
  const std::vector<SpeedFrame> frames = log.framesFrom(first_frame);
  std::vector<double> samples_ms;
  std::size_t next_frame = 0;
  for (std::size_t i = kWarmUp; i < published.size(); ++i) {
    // Frames are in order and commands are distinct from their neighbours: search forward.
    while (next_frame < frames.size() && frames[next_frame].arrival < published[i]) ++next_frame;
    const Clock::time_point overtaken =
        i + 1 < published.size() ? published[i + 1] + 200ms : Clock::time_point::max();
    for (std::size_t k = next_frame; k < frames.size() && frames[k].arrival < overtaken; ++k) {
      if (frames[k].left == sent_ticks[i] && frames[k].right == sent_ticks[i]) {
        samples_ms.push_back(toMs(frames[k].arrival - published[i]));
        break;
      }
    }
  }
  return latencyResult(samples_ms, published.size() > kWarmUp ? published.size() - kWarmUp : 0);
}

/// With ~capture, a subscriber on serial_raw (as rosbag record would be), so the node really
/// serializes and sends every chunk.
class CaptureListener {
 public:
  CaptureListener(ros::NodeHandle& nh, const DriverProcess& driver, const Variant& variant) {
    if (!variant.capture) return;
    subscriber_ = nh.subscribe<serial_robot_driver::SerialChunk>(
        driver.topic("serial_raw"), 10000,
        [this](const serial_robot_driver::SerialChunk::ConstPtr&) { ++chunks_; });
  }

 private:
  ros::Subscriber subscriber_;
  std::atomic<uint64_t> chunks_{0};
};

struct BaseSessionResult {
  std::optional<LatencyResult> cmd_vel;
  std::optional<LoopResult> idle_loop;
};

/// driver_node with the base alone on a pty owned here.
BaseSessionResult runBaseSession(Context& context, const Variant& variant, bool time_cmd_vel,
                                 bool measure_idle_loop) {
  const std::string ns = "base_" + variant.tag;
  sim::PseudoTerminal pty(context.paths.link(ns));
  SpeedFrameLog log;
  protocol::FramerConfig framer;
  framer.accept(devices::base::kFrames);
  PtyFrameReader reader(pty, framer, [&log](auto family, auto data, auto size, auto arrival) {
    log.onFrame(family, data, size, arrival);
  });
  ParamList params = commonParams(pty.linkPath(), variant);
  params.insert(params.end(), {{"body/enabled", false},
                               {"servo_bus/enabled", false},
                               {"base/speed_dithering", false},   // one tick value per command
                               {"base/max_wheel_speed", 20.0}});  // room for 600 distinct ticks
  DriverProcess driver(context.paths, ns, params, variant.program);
  const CaptureListener capture(context.nh, driver, variant);
  ros::Publisher publisher =
      context.nh.advertise<geometry_msgs::Twist>(driver.topic("cmd_vel"), 10);
  require(waitUntil([&] { return log.count() > 0; }, 30s),
          "no speed frame on the pty within 30 s; see " + context.paths.log(ns));
  require(waitUntil([&] { return publisher.getNumSubscribers() > 0; }, 10s),
          "driver_node did not subscribe to cmd_vel");

  BaseSessionResult result;
  if (time_cmd_vel) {
    result.cmd_vel = variant.spaced_cmd_vel
                         ? timeCmdVelSpaced(publisher, log, context.options.commands)
                         : timeCmdVel(publisher, log, context.options.commands);
  }
  if (measure_idle_loop) {
    require(sleepUntil(Clock::now() + 1s), "stopped");  // past cmd_vel_timeout: no more commands
    const std::size_t first = log.count();
    const CpuWindow cpu(driver.pid());
    require(sleepUntil(Clock::now() + fromSeconds(context.options.loop_seconds)), "stopped");
    LoopResult loop = analyzePeriods(log.arrivalSeconds(first, log.count()));
    loop.cpu_percent = cpu.percent();
    result.idle_loop = loop;
  }
  return result;
}

// --- body: telemetry written to the pty, joint_states received -----------------------------------

/// Writes numbered telemetry frames and matches the joint_states they become. The frame number is
/// carried in the first two servo positions (12 bits each), which the node publishes as angles.
class TelemetryProbe {
 public:
  static constexpr std::size_t kServos = 20;

  /// Node parameters that make positions decode back to raw ticks (zero 0, direction +1).
  static ParamList nodeParams() {
    std::vector<int> ids, zeros(kServos, 0), directions(kServos, 1);
    std::vector<std::string> names;
    for (std::size_t i = 0; i < kServos; ++i) {
      ids.push_back(static_cast<int>(i + 1));
      names.push_back("joint_" + std::to_string(i + 1));
    }
    return {{"body/servo_ids", toXmlRpc(ids)},
            {"body/joint_names", toXmlRpc(names)},
            {"body/zero_ticks", toXmlRpc(zeros)},
            {"body/directions", toXmlRpc(directions)},
            {"body/ticks_per_revolution", kTicksPerRevolution}};
  }

  TelemetryProbe(ros::NodeHandle& nh, const std::string& topic, std::size_t capacity)
      : written_(capacity), latency_ms_(capacity, kNotReceived) {
    subscriber_ = nh.subscribe(topic, 10000, &TelemetryProbe::onJointState, this,
                               ros::TransportHints().tcpNoDelay());
  }

  std::size_t capacity() const { return written_.size(); }

  /// Writes frame `seq`; false when the line could not take it at once (dropped, like an overrun).
  bool write(RobotEnd& robot, uint32_t seq) {
    const std::vector<uint8_t> frame = encode(seq);
    // Locked across write + timestamp so the answer cannot be matched before its write time.
    std::lock_guard<std::mutex> lock(mutex_);
    if (!robot.writeFrame(frame)) return false;
    written_[seq] = Clock::now();
    return true;
  }

  /// Writes another device's frame under the same lock, so it never lands inside a telemetry
  /// frame written from another thread.
  bool writeOther(RobotEnd& robot, const std::vector<uint8_t>& frame) {
    std::lock_guard<std::mutex> lock(mutex_);
    return robot.writeFrame(frame);
  }

  std::size_t delivered(uint32_t begin, uint32_t end) const {
    std::lock_guard<std::mutex> lock(mutex_);
    std::size_t count = 0;
    for (uint32_t seq = begin; seq < end; ++seq) count += latency_ms_[seq] != kNotReceived;
    return count;
  }

  std::vector<double> latenciesMs(uint32_t begin, uint32_t end) const {
    std::lock_guard<std::mutex> lock(mutex_);
    std::vector<double> samples;
    for (uint32_t seq = begin; seq < end; ++seq) {
      if (latency_ms_[seq] != kNotReceived) samples.push_back(latency_ms_[seq]);
    }
    return samples;
  }

 private:
  static constexpr int kTicksPerRevolution = 4096;
  static constexpr double kNotReceived = -1.0;

  static std::vector<uint8_t> encode(uint32_t seq) {
    body::Telemetry telemetry;
    telemetry.servo_count = kServos;
    for (std::size_t i = 0; i < kServos; ++i) telemetry.servos[i].position = 2048;
    telemetry.servos[0].position = static_cast<uint16_t>(seq & 0xFFF);
    telemetry.servos[1].position = static_cast<uint16_t>((seq >> 12) & 0xFFF);
    return body::encodeTelemetry(telemetry);
  }

  static uint32_t ticksOf(double radians) {
    const long ticks = std::lround(radians * kTicksPerRevolution / (2 * M_PI));
    return static_cast<uint32_t>(((ticks % kTicksPerRevolution) + kTicksPerRevolution) %
                                 kTicksPerRevolution);
  }

  void onJointState(const sensor_msgs::JointState::ConstPtr& message) {
    const Clock::time_point received = Clock::now();  // before the lock: the lock is not timed
    if (message->position.size() < 2) return;
    const uint32_t seq = ticksOf(message->position[0]) | (ticksOf(message->position[1]) << 12);
    std::lock_guard<std::mutex> lock(mutex_);
    if (seq >= written_.size() || written_[seq] == Clock::time_point{}) return;
    latency_ms_[seq] = toMs(received - written_[seq]);
  }

  mutable std::mutex mutex_;
  std::vector<Clock::time_point> written_;  ///< per frame number; epoch = not written
  std::vector<double> latency_ms_;          ///< per frame number; kNotReceived
  ros::Subscriber subscriber_;
};

struct RateStep {
  double target_hz = 0;
  double achieved_hz = 0;
  std::size_t attempted = 0;
  std::size_t dropped_at_pty = 0;  ///< the pty buffer was full: the node did not read in time
  std::size_t delivered = 0;
  double ratio() const { return attempted ? static_cast<double>(delivered) / attempted : 0.0; }
};

/// Writes `count` frames at `rate_hz` (absolute schedule), numbered from *next_seq, then waits up
/// to 1 s for the last joint_states to come in.
RateStep streamTelemetry(TelemetryProbe& probe, RobotEnd& robot, double rate_hz, std::size_t count,
                         uint32_t* next_seq) {
  RateStep step;
  step.target_hz = rate_hz;
  const uint32_t first = *next_seq;
  require(first + count <= probe.capacity(), "telemetry probe too small");
  const Clock::time_point start = Clock::now();
  for (std::size_t k = 0; k < count && !stopRequested(); ++k) {
    std::this_thread::sleep_until(start + fromSeconds(k / rate_hz));
    if (!probe.write(robot, (*next_seq)++)) ++step.dropped_at_pty;
    ++step.attempted;
  }
  // Frames over the time between the first and the last write.
  const double elapsed = toSeconds(Clock::now() - start);
  step.achieved_hz = elapsed > 0 && step.attempted > 1 ? (step.attempted - 1) / elapsed : 0.0;
  const std::size_t written = step.attempted - step.dropped_at_pty;
  waitUntil([&] { return probe.delivered(first, *next_seq) >= written; }, 1s);
  step.delivered = probe.delivered(first, *next_seq);
  return step;
}

struct TelemetrySessionResult {
  std::optional<LatencyResult> latency;
  double cpu_percent = 0;
  std::vector<RateStep> steps;
  std::optional<double> max_rate_hz;  ///< highest step with >= 99.9 % delivered
};

/// Writes frames 0, 1, ... at 50 Hz (at most `frames`) until the node is connected, publishing,
/// and the probe's subscriber is attached; `log` is named in the error when it never is.
void warmUpTelemetry(TelemetryProbe& probe, RobotEnd& robot, uint32_t frames,
                     const std::string& log) {
  uint32_t seq = 0;
  const Clock::time_point give_up = Clock::now() + 30s;
  while (probe.delivered(0, seq) == 0 && Clock::now() < give_up && !stopRequested() &&
         seq < frames) {
    probe.write(robot, seq++);
    std::this_thread::sleep_for(20ms);
  }
  require(probe.delivered(0, seq) > 0, "no joint_states for the telemetry written; see " + log);
  sleepUntil(Clock::now() + 300ms);
}

/// driver_node with the body alone on a pty owned here; this process plays the servo board.
TelemetrySessionResult runTelemetrySession(Context& context, const Variant& variant,
                                           bool time_latency, bool step_rates) {
  constexpr std::size_t kWarmUpFrames = 2000;
  constexpr double kLatencyRateHz = 100.0;
  const Options& options = context.options;
  const std::string ns = "body_" + variant.tag;
  const auto robot = openRobotEnd(Transport::kPty, context.paths.link(ns));
  ParamList params = commonParams(robot->port(), variant);
  params.insert(params.end(), {{"base/enabled", false}, {"servo_bus/enabled", false}});
  const ParamList body_params = TelemetryProbe::nodeParams();
  params.insert(params.end(), body_params.begin(), body_params.end());

  std::size_t capacity = kWarmUpFrames + options.telemetry_frames;
  for (double rate : options.rates) capacity += std::lround(rate * options.rate_step_seconds);
  DriverProcess driver(context.paths, ns, params, variant.program);
  const CaptureListener capture(context.nh, driver, variant);
  TelemetryProbe probe(context.nh, driver.topic("joint_states"), capacity);

  warmUpTelemetry(probe, *robot, kWarmUpFrames, context.paths.log(ns));
  uint32_t seq = kWarmUpFrames;

  TelemetrySessionResult result;
  if (time_latency) {
    const uint32_t first = seq;
    const CpuWindow cpu(driver.pid());
    const RateStep run =
        streamTelemetry(probe, *robot, kLatencyRateHz, options.telemetry_frames, &seq);
    result.cpu_percent = cpu.percent();
    result.latency = latencyResult(probe.latenciesMs(first, seq), run.attempted);
  }
  if (step_rates) {
    for (double rate : options.rates) {
      if (stopRequested()) break;
      const auto count = static_cast<std::size_t>(std::lround(rate * options.rate_step_seconds));
      result.steps.push_back(streamTelemetry(probe, *robot, rate, count, &seq));
      if (result.steps.back().ratio() >= 0.999) result.max_rate_hz = rate;
    }
  }
  return result;
}

// --- servo bus: services against robot_sim ---------------------------------------------------

/// One servo/read of servo 0's voltage; false when the call failed or the servo did not answer.
bool readVoltage(const std::string& service, ros::ServiceClient* persistent) {
  ServoRead call;
  call.request.id = 0;
  call.request.param = "voltage";
  const bool called = persistent ? persistent->call(call) : ros::service::call(service, call);
  return called && call.response.success;
}

LatencyResult timeServoReads(ros::NodeHandle& nh, const std::string& service, std::size_t calls,
                             bool persistent) {
  ros::ServiceClient client;
  std::vector<double> samples_ms;
  std::size_t attempted = 0;
  for (; attempted < calls && !stopRequested(); ++attempted) {
    if (persistent && !client.isValid()) client = nh.serviceClient<ServoRead>(service, true);
    const Clock::time_point start = Clock::now();
    if (readVoltage(service, persistent ? &client : nullptr)) {
      samples_ms.push_back(toMs(Clock::now() - start));
    }
  }
  return latencyResult(samples_ms, attempted);
}

/// header.stamp of every wheel_command (the node stamps it right after writing the frame).
class WheelCommandLog {
 public:
  WheelCommandLog(ros::NodeHandle& nh, const std::string& topic) {
    subscriber_ = nh.subscribe(topic, 1000, &WheelCommandLog::onMessage, this,
                               ros::TransportHints().tcpNoDelay());
  }
  std::size_t count() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return stamps_.size();
  }
  std::vector<double> stamps(std::size_t begin, std::size_t end) const {
    std::lock_guard<std::mutex> lock(mutex_);
    return {stamps_.begin() + begin, stamps_.begin() + std::min(end, stamps_.size())};
  }

 private:
  void onMessage(const WheelCommand::ConstPtr& message) {
    std::lock_guard<std::mutex> lock(mutex_);
    stamps_.push_back(message->header.stamp.toSec());
  }
  mutable std::mutex mutex_;
  std::vector<double> stamps_;
  ros::Subscriber subscriber_;
};

struct ServoSessionResult {
  LatencyResult new_connection;
  LatencyResult persistent;
  LoopResult idle;
  LoopResult stress;
  double calls_per_second = 0;
  std::size_t failed_stress_calls = 0;
};

/// Round trips: the servo bus alone (robot_sim answers after its default 1.5 ms latency).
void measureServoRoundTrips(Context& context, ServoSessionResult* result) {
  const std::string ns = "servo_event";
  const std::string link = context.paths.link(ns);
  const auto sim =
      startRobotSim(context.paths, "robot_sim_" + ns, {"--link", link, "--no-base", "--no-body"});
  ParamList params = commonParams(link, kEventDriven);
  params.insert(params.end(), {{"base/enabled", false}, {"body/enabled", false}});
  DriverProcess driver(context.paths, ns, params);
  const std::string service = driver.topic("servo/read");
  require(ros::service::waitForService(service, ros::Duration(30)),
          service + " did not come up; see " + context.paths.log(ns));
  require(waitUntil([&] { return readVoltage(service, nullptr); }, 20s),
          "servo/read never succeeded against robot_sim");
  const std::size_t calls = context.options.service_calls;
  result->new_connection = timeServoReads(context.nh, service, calls, false);
  result->persistent = timeServoReads(context.nh, service, calls, true);
}

/// Stress: three persistent clients back to back plus one opening a connection per call, for
/// the window; the wheel loop's periods meanwhile.
void stressServoReads(Context& context, const std::string& service, WheelCommandLog& wheel,
                      ServoSessionResult* result) {
  std::atomic<bool> stress_done{false};
  std::atomic<std::size_t> calls{0}, failures{0};
  std::vector<std::thread> clients;
  for (int i = 0; i < 4; ++i) {
    clients.emplace_back([&, persistent = i < 3] {
      ros::ServiceClient client;
      while (!stress_done) {
        if (persistent && !client.isValid()) {
          client = context.nh.serviceClient<ServoRead>(service, true);
        }
        ++(readVoltage(service, persistent ? &client : nullptr) ? calls : failures);
      }
    });
  }
  const std::size_t first = wheel.count();
  const Clock::time_point start = Clock::now();
  sleepUntil(start + fromSeconds(context.options.stress_seconds));
  const std::size_t last = wheel.count();
  result->calls_per_second = calls / toSeconds(Clock::now() - start);
  stress_done = true;
  for (auto& client : clients) client.join();
  result->stress = analyzePeriods(wheel.stamps(first, last));
  result->failed_stress_calls = failures;
}

/// The wheel loop, idle and under a stress of servo/read calls: every device simulated.
void measureWheelLoopUnderStress(Context& context, ServoSessionResult* result) {
  const std::string ns = "full_event";
  const std::string link = context.paths.link(ns);
  const auto sim = startRobotSim(context.paths, "robot_sim_" + ns, {"--link", link});
  DriverProcess driver(context.paths, ns, commonParams(link, kEventDriven));
  WheelCommandLog wheel(context.nh, driver.topic("wheel_command"));
  const std::string service = driver.topic("servo/read");
  require(ros::service::waitForService(service, ros::Duration(30)),
          service + " did not come up; see " + context.paths.log(ns));
  require(waitUntil([&] { return wheel.count() > 0; }, 20s), "no wheel_command received");
  require(sleepUntil(Clock::now() + 1s), "stopped");

  const std::size_t first = wheel.count();
  require(sleepUntil(Clock::now() + fromSeconds(context.options.stress_seconds)), "stopped");
  result->idle = analyzePeriods(wheel.stamps(first, wheel.count()));
  stressServoReads(context, service, wheel, result);
}

ServoSessionResult runServoSession(Context& context) {
  ServoSessionResult result;
  measureServoRoundTrips(context, &result);
  measureWheelLoopUnderStress(context, &result);
  return result;
}

// --- the servo bus at the wire's pace (10) ------------------------------------------------------

constexpr int kBusServos = 20;
constexpr double kBusBaud = 115200;
constexpr double kBusLatencyMs = 0.5;
/// READ_ANGLE: a 6-byte request and an 8-byte answer, 10 bits a byte on the line.
constexpr double kBusLineMs = (6 + 8) * 10.0 / kBusBaud * 1000.0;

/// One run of READ_ANGLE transactions: by whom, how many per second, at what cost.
struct BusRun {
  double per_second = 0;
  double cpu_us = 0;     ///< CPU per transaction of the process doing them
  double cpu_share = 0;  ///< CPU seconds per second
  double turnaround_ms = 0;
};

std::vector<std::string> busSimFlags(const std::string& link, double latency_ms, bool paced) {
  std::string ids;
  for (int id = 0; id < kBusServos; ++id) ids += (id ? "," : "") + std::to_string(id);
  std::vector<std::string> flags = {
      "--link",          link, "--no-base",          "--no-body",
      "--bus-servo-ids", ids,  "--servo-latency-ms", format("%.3f", latency_ms)};
  if (paced) flags.insert(flags.end(), {"--pace-baud", format("%.0f", kBusBaud)});
  return flags;
}

/// servo_floor against its own robot_sim for the window; parses the line it prints.
BusRun runServoFloor(Context& context, const std::string& tag, double latency_ms, bool paced) {
  const std::string link = context.paths.link("bus_floor_" + tag);
  const auto sim = startRobotSim(context.paths, "robot_sim_bus_floor_" + tag,
                                 busSimFlags(link, latency_ms, paced));
  require(waitUntil([&] { return ::access(link.c_str(), F_OK) == 0; }, 20s),
          "robot_sim did not create " + link);
  const std::string log = context.paths.log("servo_floor_" + tag);
  ChildProcess floor("servo_floor",
                     {context.paths.bin_dir + "/servo_floor", link, std::to_string(kBusServos),
                      format("%.1f", context.options.bus_seconds)},
                     log);
  require(
      waitUntil([&] { return !floor.running(); }, fromSeconds(context.options.bus_seconds + 30)),
      "servo_floor did not finish; see " + log);
  std::ifstream in(log);
  std::string line, last;
  while (std::getline(in, line)) {
    if (line.rfind("transactions=", 0) == 0) last = line;
  }
  unsigned long long transactions = 0, lost = 0;
  double seconds = 0, cpu = 0, mean_ms = 0;
  require(std::sscanf(last.c_str(), "transactions=%llu seconds=%lf cpu_s=%lf lost=%llu mean_ms=%lf",
                      &transactions, &seconds, &cpu, &lost, &mean_ms) == 5 &&
              transactions > 0,
          "servo_floor printed no result; see " + log);
  return {transactions / seconds, cpu / transactions * 1e6, cpu / seconds, mean_ms};
}

/// robot_sim's counters of the servo bus as its stats file last had them.
struct SimBusCounters {
  double uptime_s = -1;
  double answers = 0;
};

SimBusCounters readSimBusCounters(const std::string& path) {
  SimBusCounters counters;
  std::ifstream in(path);
  std::string key;
  double value = 0;
  while (in >> key >> value) {
    if (key == "uptime_s") counters.uptime_s = value;
    if (key == "servo_answers") counters.answers = value;
  }
  return counters;
}

/// Waits for robot_sim's next stats write (once a second) and returns it with the node's CPU at
/// that moment, so both windows line up within the 5 ms of polling.
std::pair<SimBusCounters, double> nextSimBusCounters(const std::string& path, pid_t node) {
  const double previous = readSimBusCounters(path).uptime_s;
  SimBusCounters counters;
  require(waitUntil(
              [&] {
                counters = readSimBusCounters(path);
                return counters.uptime_s != previous && counters.uptime_s >= 0;
              },
              5s),
          "robot_sim's stats file " + path + " is not rewritten");
  return {counters, processCpuSeconds(node)};
}

/// Subscribes to `topic` (servo_states of the process `pid`) and counts its messages over the
/// window, one per answered READ_ANGLE, with the process's CPU over the same window.
BusRun measureServoStates(Context& context, const std::string& topic, pid_t pid,
                          const std::string& log) {
  std::atomic<std::size_t> messages{0};
  ros::Subscriber subscriber = context.nh.subscribe<sensor_msgs::JointState>(
      topic, 10000, [&](const sensor_msgs::JointState::ConstPtr&) { ++messages; },
      ros::VoidConstPtr(), ros::TransportHints().tcpNoDelay());
  require(waitUntil([&] { return messages > 0; }, 30s), "no servo_states received; see " + log);
  require(sleepUntil(Clock::now() + 1s), "stopped");
  const std::size_t first = messages;
  const double cpu_start = processCpuSeconds(pid);
  const Clock::time_point start = Clock::now();
  require(sleepUntil(start + fromSeconds(context.options.bus_seconds)), "stopped");
  const double seconds = toSeconds(Clock::now() - start);
  const double cpu = processCpuSeconds(pid) - cpu_start;
  const double count = static_cast<double>(messages - first);
  require(count > 0, "servo_states stopped; see " + log);
  return {count / seconds, cpu / count * 1e6, cpu / seconds, seconds * 1000.0 / count};
}

/// servo_floor --publish: the same blocking client, publishing each answer on servo_states.
BusRun runPublishingServoFloor(Context& context, const std::string& tag, double latency_ms,
                               bool paced) {
  const std::string ns = "bus_floor_pub_" + tag;
  const std::string link = context.paths.link(ns);
  const auto sim =
      startRobotSim(context.paths, "robot_sim_" + ns, busSimFlags(link, latency_ms, paced));
  require(waitUntil([&] { return ::access(link.c_str(), F_OK) == 0; }, 20s),
          "robot_sim did not create " + link);
  const std::string log = context.paths.log("servo_floor_" + ns);
  // It runs past the window (the subscription and a second of settling come first); the
  // measurement is the subscriber's, like driver_node's, and the floor is stopped after it.
  ChildProcess floor("servo_floor",
                     {context.paths.bin_dir + "/servo_floor", link, std::to_string(kBusServos),
                      format("%.1f", context.options.bus_seconds + 60), "--publish", "__ns:=/" + ns,
                      "__name:=servo_floor"},
                     log);
  return measureServoStates(context, "/" + ns + "/servo_states", floor.pid(), log);
}

/// driver_node polling 20 servos at `state_rate` each, the node's CPU from its process clock.
/// `subscribed`: servo_states messages counted (one per answered READ_ANGLE); else nobody
/// subscribes and robot_sim's answers are counted: the transaction path without roscpp's cost of
/// sending each message.
BusRun runServoStates(Context& context, const std::string& tag, double latency_ms, bool paced,
                      double state_rate, bool subscribed = true, double health_rate = 0.0) {
  const std::string ns = "bus_node_" + tag;
  const std::string link = context.paths.link(ns);
  const std::string stats_file = context.paths.work_dir + "/" + ns + ".stats";
  std::vector<std::string> sim_flags = busSimFlags(link, latency_ms, paced);
  sim_flags.insert(sim_flags.end(), {"--stats-file", stats_file});
  const auto sim = startRobotSim(context.paths, "robot_sim_" + ns, sim_flags);
  std::vector<int> ids;
  for (int id = 0; id < kBusServos; ++id) ids.push_back(id);
  ParamList params = commonParams(link, kEventDriven);
  params.insert(params.end(), {{"base/enabled", false},
                               {"body/enabled", false},
                               {"servo_bus/state_ids", toXmlRpc(ids)},
                               {"servo_bus/state_rate", state_rate},
                               // The health poll shares the line (five READ_DATA per servo
                               // and period); off unless asked, so the rows compare servo_states.
                               {"servo_bus/health_rate", health_rate}});
  DriverProcess driver(context.paths, ns, params);
  if (!subscribed) {
    require(waitUntil([&] { return readSimBusCounters(stats_file).answers > 0; }, 30s),
            "driver_node never polled; see " + context.paths.log(ns));
    const auto [first, cpu_start] = nextSimBusCounters(stats_file, driver.pid());
    require(sleepUntil(Clock::now() + fromSeconds(context.options.bus_seconds - 0.5)), "stopped");
    const auto [last, cpu_end] = nextSimBusCounters(stats_file, driver.pid());
    const double seconds = last.uptime_s - first.uptime_s;
    const double count = last.answers - first.answers;
    require(count > 0 && seconds > 0, "driver_node stopped polling");
    return {count / seconds, (cpu_end - cpu_start) / count * 1e6, (cpu_end - cpu_start) / seconds,
            seconds * 1000.0 / count};
  }
  return measureServoStates(context, driver.topic("servo_states"), driver.pid(),
                            context.paths.log(ns));
}

/// The runs of section 10, each pair back to back so the machine's load is alike for both.
struct BusRuns {
  BusRun floor_fast, node_fast, floor_pub_fast, node_quiet;
  BusRun floor_paced, node_paced, node_paced_health, floor_unpaced;
};

/// The line's own rate: READ_ANGLE's bytes at kBusBaud plus the servo's latency.
constexpr double kBusWireRate = 1000.0 / (kBusLineMs + kBusLatencyMs);

BusRuns runBusRuns(Context& context) {
  BusRuns runs;
  runs.floor_fast = runServoFloor(context, "fast", 0.0, false);
  runs.node_fast = runServoStates(context, "fast", 0.0, false, 1000.0);
  runs.floor_pub_fast = runPublishingServoFloor(context, "fast", 0.0, false);
  runs.node_quiet = runServoStates(context, "quiet", 0.0, false, 1000.0, false);
  runs.floor_paced = runServoFloor(context, "paced", kBusLatencyMs, true);
  runs.node_paced = runServoStates(context, "paced", kBusLatencyMs, true, 1000.0);
  runs.node_paced_health =
      runServoStates(context, "paced_health", kBusLatencyMs, true, 1000.0, false, 1.0);
  runs.floor_unpaced = runServoFloor(context, "latency", kBusLatencyMs, false);
  return runs;
}

/// "0.95 of the rate, 1.20 of the CPU": a node's run against a floor's.
std::string versus(const BusRun& node, const BusRun& floor) {
  return format("%.2f of the rate, %.2f of the CPU", node.per_second / floor.per_second,
                node.cpu_us / floor.cpu_us);
}

void addBusRunRows(ResultTable& table, const BusRuns& runs) {
  const double wire_rate = kBusWireRate;
  table.section(
      format("10. The servo bus at the wire's pace: READ_ANGLE of %d servos, "
             "servo_states (driver_node) vs servo_floor",
             kBusServos),
      {"run", "transactions/s", "per transaction", "CPU per transaction", "CPU", "node / floor"});
  auto add = [&](const std::string& what, const BusRun& run, const std::string& ratio_text) {
    table.row({what, format("%.0f", run.per_second), format("%.3f ms", run.turnaround_ms),
               format("%.1f us", run.cpu_us), format("%.2f s per s", run.cpu_share), ratio_text});
  };
  add("servo_floor, pty speed, latency 0", runs.floor_fast, "");
  add("driver_node, pty speed, latency 0, state_rate 1000", runs.node_fast,
      versus(runs.node_fast, runs.floor_fast));
  add("servo_floor --publish (roscpp, one servo_states message per answer), pty speed",
      runs.floor_pub_fast, "");
  add("driver_node against servo_floor --publish", runs.node_fast,
      versus(runs.node_fast, runs.floor_pub_fast));
  add("driver_node, the same, nobody subscribed to servo_states", runs.node_quiet,
      versus(runs.node_quiet, runs.floor_fast));
  add(format("servo_floor, --pace-baud %.0f, latency %.1f ms", kBusBaud, kBusLatencyMs),
      runs.floor_paced, "");
  add(format("driver_node, --pace-baud %.0f, latency %.1f ms, state_rate 1000", kBusBaud,
             kBusLatencyMs),
      runs.node_paced, versus(runs.node_paced, runs.floor_paced));
  add(format("driver_node, the same with health_rate 1 (the default), every transaction counted "
             "(READ_ANGLE and the health poll's READ_DATA)"),
      runs.node_paced_health,
      format("%.2f of the floor's rate",
             runs.node_paced_health.per_second / runs.floor_paced.per_second));
  table.row({format("the line at %.0f baud + %.1f ms latency", kBusBaud, kBusLatencyMs),
             format("%.0f", wire_rate), format("%.3f ms", kBusLineMs + kBusLatencyMs), "", "", ""});
  add(format("servo_floor, pty speed, latency %.1f ms", kBusLatencyMs), runs.floor_unpaced, "");
}

void addBusGoals(ResultTable& table, const BusRuns& runs) {
  const double wire_rate = kBusWireRate;
  table.section("10. Goals of the servo bus");
  table.row("driver_node's turnaround over the floor's, pty speed",
            format("+%.3f ms", runs.node_fast.turnaround_ms - runs.floor_fast.turnaround_ms),
            "<= the floor's own",
            runs.node_fast.turnaround_ms <= 2 * runs.floor_fast.turnaround_ms);
  table.row("driver_node's CPU per transaction, pty speed",
            format("%.1f us", runs.node_fast.cpu_us), "<= 38 us (half of 77)",
            runs.node_fast.cpu_us <= 38.5);
  table.row("driver_node's CPU per transaction over servo_floor --publish's, pty speed",
            format("%+.1f us (%.1f vs %.1f)", runs.node_fast.cpu_us - runs.floor_pub_fast.cpu_us,
                   runs.node_fast.cpu_us, runs.floor_pub_fast.cpu_us),
            "");
  table.row(format("servo_states at %.0f baud, share of the line's rate", kBusBaud),
            format("%.0f of %.0f /s = %.0f %%", runs.node_paced.per_second, wire_rate,
                   100.0 * runs.node_paced.per_second / wire_rate),
            ">= 90 %", runs.node_paced.per_second >= 0.9 * wire_rate);
  const double paced_excess = runs.floor_paced.turnaround_ms - runs.floor_unpaced.turnaround_ms;
  table.row("paced robot_sim: floor turnaround paced - unpaced (same latency)",
            format("%.3f ms (the line: %.3f ms)", paced_excess, kBusLineMs), "line +- 0.1 ms",
            std::abs(paced_excess - kBusLineMs) <= 0.1);
  table.row(
      "paced robot_sim: floor turnaround vs line + latency",
      format("%.3f ms vs %.3f ms", runs.floor_paced.turnaround_ms, kBusLineMs + kBusLatencyMs));
  table.note(
      "Each transaction is a READ_ANGLE of the next servo: servo_states asks for 1000 Hz of each "
      "of 20 servos, more than either line carries, so both clients run back to back. driver_node "
      "runs with ~servo_bus/health_rate 0 except in the row that says otherwise, whose count is "
      "robot_sim's answers (angles and health reads). servo_floor --publish is the least a roscpp "
      "node doing servo_states' job must spend: the floor plus one JointState published per "
      "answer, counted by the same subscriber as driver_node's. CPU is the "
      "process's own clock over the window. The paced robot_sim's excess is the difference of two "
      "floor runs that differ only in --pace-baud, so the pty round trip (the same in both) "
      "cancels; the last row includes it.");
}

void runServoBusSection(Context& context) {
  const BusRuns runs = runBusRuns(context);
  addBusRunRows(context.results, runs);
  addBusGoals(context.results, runs);
}

// --- the run ------------------------------------------------------------------------------------

/// Runs one measurement; a failure is reported in the table and the run goes on.
template <typename Function>
bool attempt(Context& context, const std::string& what, Function&& function) {
  if (stopRequested()) return false;
  std::cerr << "driver_bench: " << what << " ..." << std::endl;
  try {
    function();
    return true;
  } catch (const std::exception& error) {
    ++context.failures;
    context.results.section(what + ": FAILED");
    context.results.note(std::string("error: ") + error.what());
    std::cerr << "driver_bench: " << what << " failed: " << error.what() << std::endl;
    return false;
  }
}

std::string ratio(double polling, double event) {
  return event > 0 ? format("%.1fx", polling / event) : "-";
}

/// Section 11: driver_node and floor_node, each measured `floor_rounds` times, their runs
/// alternated (node first in even rounds, floor first in odd ones) so that a change of machine
/// load falls on both. Each round takes its share of the commands, frames and idle window; a
/// figure is the mean over the rounds.
/// Section 11's figures of one program (driver_node or the floor), one entry per round.
struct FloorFigures {
  std::vector<double> cmd_p50, cmd_p99, cmd_lost, telemetry_p50, telemetry_p99, cpu, idle_cpu,
      jitter;
};

/// One program's base and telemetry sessions in one round of section 11.
void runFloorRound(Context& context, const Variant& variant, std::size_t round,
                   FloorFigures* figures) {
  const Variant tagged{variant.name, variant.tag + "_r" + std::to_string(round), variant.program,
                       variant.read_poll_interval, true};
  attempt(context, format("11. %s base, round %zu", variant.program.c_str(), round + 1), [&] {
    const BaseSessionResult base = runBaseSession(context, tagged, true, true);
    figures->cmd_p50.push_back(base.cmd_vel->ms.p50);
    figures->cmd_p99.push_back(base.cmd_vel->ms.p99);
    figures->cmd_lost.push_back(100.0 * base.cmd_vel->lost /
                                std::max<std::size_t>(1, base.cmd_vel->attempted));
    figures->jitter.push_back(base.idle_loop->period_ms.stddev);
    figures->idle_cpu.push_back(base.idle_loop->cpu_percent / 100.0);
  });
  attempt(context, format("11. %s telemetry, round %zu", variant.program.c_str(), round + 1), [&] {
    const TelemetrySessionResult body = runTelemetrySession(context, tagged, true, false);
    figures->telemetry_p50.push_back(body.latency->ms.p50);
    figures->telemetry_p99.push_back(body.latency->ms.p99);
    figures->cpu.push_back(body.cpu_percent / 100.0);
  });
}

std::optional<double> meanOf(const std::vector<double>& values) {
  if (values.empty()) return std::nullopt;
  double sum = 0;
  for (double value : values) sum += value;
  return sum / values.size();
}

void addFloorRows(ResultTable& table, const FloorFigures& node, const FloorFigures& floor) {
  table.section("11. Each device alone vs the floor (bench/floor_node.cpp), runs alternated",
                {"measurement", "driver_node", "floor", "node / floor"});
  auto compare = [&](const std::string& what, const std::vector<double>& node_values,
                     const std::vector<double>& floor_values, const char* unit, int decimals) {
    const auto n = meanOf(node_values), f = meanOf(floor_values);
    if (!n || !f) return;
    table.row({what, format("%.*f %s", decimals, *n, unit), format("%.*f %s", decimals, *f, unit),
               f > 0 ? format("%.2fx", *n / *f) : "-"});
  };
  compare("telemetry -> joint_states p50", node.telemetry_p50, floor.telemetry_p50, "ms", 3);
  compare("telemetry -> joint_states p99", node.telemetry_p99, floor.telemetry_p99, "ms", 3);
  compare("cmd_vel -> speed frame p50", node.cmd_p50, floor.cmd_p50, "ms", 3);
  compare("cmd_vel -> speed frame p99", node.cmd_p99, floor.cmd_p99, "ms", 3);
  compare("cmd_vel never on the wire", node.cmd_lost, floor.cmd_lost, "%", 1);
  compare("CPU at 100 Hz telemetry", node.cpu, floor.cpu, "s/s", 4);
  compare("CPU idle, base loop 50 Hz", node.idle_cpu, floor.idle_cpu, "s/s", 4);
  compare("loop jitter std, idle 50 Hz", node.jitter, floor.jitter, "ms", 3);
}

void runFloorComparison(Context& context) {
  const Options saved = context.options;
  const std::size_t rounds = saved.floor_rounds;
  context.options.commands = std::max<std::size_t>(50, saved.commands / rounds);
  context.options.telemetry_frames = std::max<std::size_t>(100, saved.telemetry_frames / rounds);
  context.options.loop_seconds = std::max(5.0, saved.loop_seconds / rounds);
  FloorFigures node, floor;
  for (std::size_t round = 0; round < rounds && !stopRequested(); ++round) {
    for (int k = 0; k < 2; ++k) {
      const bool floor_turn = (k == 1) != (round % 2 == 1);
      runFloorRound(context, floor_turn ? kFloor : kEventDriven, round,
                    floor_turn ? &floor : &node);
    }
  }
  context.options = saved;

  addFloorRows(context.results, node, floor);
  context.results.note(format(
      "%zu rounds, node and floor alternated; per round %zu cmd_vel commands 10-40 ms apart "
      "(uniform; a command overtaken before any frame carries it is not timed), %zu telemetry "
      "frames of 20 servos at 100 Hz with one "
      "external joint_states subscriber, %.0f s idle window. Figures are means over the rounds. "
      "CPU from the process's kernel CPU clock (clock_getcpuclockid).",
      rounds, std::max<std::size_t>(50, saved.commands / rounds),
      std::max<std::size_t>(100, saved.telemetry_frames / rounds),
      std::max(5.0, saved.loop_seconds / rounds)));
}

// --- 8. the configuration users run, against the floor ------------------------------------------

/// Section 8's conditions: a background load or not, ~realtime_priority on or off.
struct UserCondition {
  bool loaded = false;
  bool realtime = false;
  std::string load() const { return loaded ? "CPU hog per core" : "quiet"; }
  std::string rt() const { return realtime ? "on" : "off"; }
  std::string tag() const {
    return std::string(loaded ? "load" : "quiet") + (realtime ? "_rt" : "");
  }
};
const UserCondition kQuiet{false, false}, kQuietRt{false, true}, kLoaded{true, false},
    kLoadedRt{true, true};
const std::vector<UserCondition> kUserConditions{kQuiet, kQuietRt, kLoaded, kLoadedRt};

/// One CPU hog per core at nice 0 (a shell's busy loop) while it lives; none when `on` is false.
class BackgroundLoad {
 public:
  BackgroundLoad(const RunPaths& paths, bool on) {
    if (!on) return;
    const long cores = std::max(1L, ::sysconf(_SC_NPROCESSORS_ONLN));
    for (long core = 0; core < cores; ++core) {
      hogs_.push_back(std::make_unique<ChildProcess>(
          "cpu hog", std::vector<std::string>{"sh", "-c", "while :; do :; done"},
          paths.log("cpu_hog")));
    }
  }

 private:
  std::vector<std::unique_ptr<ChildProcess>> hogs_;
};

/// The subscribers a user's robot has besides joint_states (the probe's): joint_state_publisher
/// (wheel_states, as launch/description.launch merges it), rviz (imu/data, odom, /tf), the
/// navigation stack (odom, /tf) and diagnostic_aggregator (/diagnostics). Each counts messages;
/// odom's keep their stamps, which both programs take from their own clock at each loop tick.
class UserSubscribers {
 public:
  UserSubscribers(ros::NodeHandle& nh, const std::string& ns) {
    add<sensor_msgs::Imu>(nh, "/" + ns + "/imu/data");
    subscribers_.push_back(nh.subscribe<nav_msgs::Odometry>(
        "/" + ns + "/odom", 100, [this](const nav_msgs::Odometry::ConstPtr& odom) {
          ++messages_;
          std::lock_guard<std::mutex> lock(stamps_mutex_);
          odom_stamps_s_.push_back(odom->header.stamp.toSec());
        }));
    add<sensor_msgs::JointState>(nh, "/" + ns + "/wheel_states");
    add<tf2_msgs::TFMessage>(nh, "/tf");
    subscribers_.push_back(nh.subscribe<diagnostic_msgs::DiagnosticArray>(
        "/diagnostics", 100, [this](const diagnostic_msgs::DiagnosticArray::ConstPtr& array) {
          ++messages_;
          std::size_t values = 0;
          for (const auto& status : array->status) values += status.values.size();
          statuses_ = array->status.size();
          values_ = values;
        }));
  }
  /// Statuses in the last /diagnostics message (0 before the first).
  std::size_t diagnosticStatuses() const { return statuses_; }
  /// Key/values of all statuses in the last /diagnostics message.
  std::size_t diagnosticValues() const { return values_; }
  /// odom messages received so far.
  std::size_t odomCount() const {
    std::lock_guard<std::mutex> lock(stamps_mutex_);
    return odom_stamps_s_.size();
  }
  /// The stamps (s) of odom messages [from, to).
  std::vector<double> odomStamps(std::size_t from, std::size_t to) const {
    std::lock_guard<std::mutex> lock(stamps_mutex_);
    to = std::min(to, odom_stamps_s_.size());
    from = std::min(from, to);
    return {odom_stamps_s_.begin() + static_cast<std::ptrdiff_t>(from),
            odom_stamps_s_.begin() + static_cast<std::ptrdiff_t>(to)};
  }

 private:
  template <typename Message>
  void add(ros::NodeHandle& nh, const std::string& topic) {
    subscribers_.push_back(nh.subscribe<Message>(
        topic, 100, [this](const typename Message::ConstPtr&) { ++messages_; }));
  }
  std::atomic<std::size_t> messages_{0};
  std::atomic<std::size_t> statuses_{0};
  std::atomic<std::size_t> values_{0};
  mutable std::mutex stamps_mutex_;
  std::vector<double> odom_stamps_s_;
  std::vector<ros::Subscriber> subscribers_;
};

/// The base's side of the shared line: every speed frame logged, battery requests answered (87 %)
/// as the AP1 answers them, so the node's battery poll runs as on a robot. Its reader thread is
/// the one that reads `robot` (over TCP it accepts the program's connection).
class PlayedBase {
 public:
  PlayedBase(RobotEnd& robot, TelemetryProbe& probe)
      : reader_([&robot](uint8_t* buffer, std::size_t capacity,
                         int timeout_ms) { return robot.read(buffer, capacity, timeout_ms); },
                baseFrames(),
                [this, &robot, &probe](auto family, auto data, auto size, auto arrival) {
                  log_.onFrame(family, data, size, arrival);
                  const auto frame = base::decodeFrame(data, size);
                  if (frame && frame->msg_id == static_cast<uint8_t>(base::MsgId::kBattery)) {
                    probe.writeOther(robot, base::encodeBatteryReply(frame->seq, 87));
                  }
                }) {}
  const SpeedFrameLog& log() const { return log_; }

 private:
  static protocol::FramerConfig baseFrames() {
    protocol::FramerConfig framer;
    framer.accept(devices::base::kFrames);
    return framer;
  }
  SpeedFrameLog log_;
  PtyFrameReader reader_;
};

/// ~realtime_priority as --realtime-priority gives it: "true" a bool, else an integer.
XmlRpc::XmlRpcValue realtimeValue(const std::string& text) {
  if (text == "true") return XmlRpc::XmlRpcValue(true);
  return XmlRpc::XmlRpcValue(std::stoi(text));
}

/// The configuration users run: the defaults (base, body and servo bus on one port, odom and
/// tf, diagnostics, battery poll) with 20 body servos. Two base settings differ so that each
/// command is recognisable on the wire (one tick value per command, room for 600 of them); they
/// change no work per frame. floor_node reads the same parameters for what it does.
ParamList userParams(const std::string& port, const UserCondition& condition,
                     const Context& context, const Variant& variant) {
  const Options& options = context.options;
  ParamList params = commonParams(port, variant);
  if (variant.same_job) {
    // As many statuses as driver_node's (it ran first); 5 (port, three devices, e_stop) before.
    const std::size_t statuses =
        context.node_diagnostic_statuses > 0 ? context.node_diagnostic_statuses : 5;
    params.emplace_back("same_job_statuses", static_cast<int>(statuses));
    params.emplace_back("same_job_values", static_cast<int>(context.node_diagnostic_values));
  }
  const ParamList body = TelemetryProbe::nodeParams();
  params.insert(params.end(), body.begin(), body.end());
  params.insert(params.end(), {{"base/speed_dithering", false}, {"base/max_wheel_speed", 20.0}});
  if (condition.realtime) {
    params.emplace_back("realtime_priority", realtimeValue(options.realtime_priority));
  }
  const bool floor = variant.program == kFloor.program;
  const bool control = variant.control_copy && options.control_slice_us >= 0;
  const int slice_us =
      floor ? options.floor_slice_us : control ? options.control_slice_us : options.node_slice_us;
  if (slice_us > 0 || (slice_us == 0 && !floor)) {
    params.emplace_back("scheduler_slice_us", slice_us);
  }
  return params;
}

/// What one session of section 8 measured.
struct UserFigures {
  double cpu = 0;  ///< s/s over the streaming window (telemetry at 100 Hz, no cmd_vel)
  LatencyResult telemetry, cmd_vel;
  LoopResult loop;  ///< speed frame periods over the streaming window
  /// The same window's periods by the program's own clock (its odom stamps): the loop's own
  /// timing, without the line's (the pty worker, the loopback's softirq) between it and the wire.
  LoopResult loop_stamped;
};

/// Telemetry at 100 Hz, `frames` frames numbered from *seq, no cmd_vel: the process's CPU,
/// telemetry -> joint_states and the loop's periods over that window, on the wire and by the
/// program's odom stamps.
UserFigures measureStreamingWindow(TelemetryProbe& probe, RobotEnd& robot, const SpeedFrameLog& log,
                                   const UserSubscribers& subscribers, pid_t pid,
                                   std::size_t frames, uint32_t* seq) {
  const uint32_t first = *seq;
  const std::size_t first_speed_frame = log.count();
  const std::size_t first_odom = subscribers.odomCount();
  const double cpu_start = processCpuSeconds(pid);
  const Clock::time_point start = Clock::now();
  const RateStep run = streamTelemetry(probe, robot, 100.0, frames, seq);
  UserFigures figures;
  figures.cpu = (processCpuSeconds(pid) - cpu_start) / toSeconds(Clock::now() - start);
  figures.loop = analyzePeriods(log.arrivalSeconds(first_speed_frame, log.count()));
  figures.loop_stamped =
      analyzePeriods(subscribers.odomStamps(first_odom, subscribers.odomCount()));
  figures.telemetry = latencyResult(probe.latenciesMs(first, *seq), run.attempted);
  return figures;
}

/// cmd_vel commands 10-40 ms apart, timed to the wire, while a second thread keeps telemetry
/// streaming at 100 Hz (those frames are not timed), numbered from `first_seq`.
LatencyResult timeCmdVelWhileStreaming(TelemetryProbe& probe, RobotEnd& robot, uint32_t first_seq,
                                       ros::Publisher& cmd_vel, const SpeedFrameLog& log,
                                       std::size_t commands) {
  std::atomic<bool> done{false};
  std::thread stream([&] {
    const Clock::time_point start = Clock::now();
    for (uint32_t seq = first_seq; !done && seq < probe.capacity(); ++seq) {
      std::this_thread::sleep_until(start + fromSeconds((seq - first_seq) / 100.0));
      probe.write(robot, seq);
    }
  });
  const LatencyResult result = timeCmdVelSpaced(cmd_vel, log, commands);
  done = true;
  stream.join();
  return result;
}

/// Frames streamed and cmd_vel commands timed in one session of section 8.
struct UserWindow {
  std::size_t frames = 0;
  std::size_t commands = 0;
};

/// The executable `variant` runs: its program in bin_dir, or the control's --control-bin.
std::string programOf(const Context& context, const Variant& variant) {
  if (variant.control_copy && !context.options.control_bin.empty()) {
    return context.options.control_bin;
  }
  return variant.program;
}

/// `variant`'s program in the configuration users run in namespace `ns`, this process playing
/// the robot on one line of `transport` (base and body; the servo bus has nothing to poll by
/// default) and its users (the subscribers attached), warmed up: telemetry flows to joint_states
/// and speed frames to the base. The probe holds `frames` frames after the warm-up.
struct UserSetup {
  static constexpr uint32_t kWarmUpFrames = 2000;

  UserSetup(Context& context, const Variant& variant, const UserCondition& condition,
            const std::string& ns, Transport transport, std::size_t frames)
      : robot(openRobotEnd(transport, context.paths.link(ns))),
        probe(context.nh, "/" + ns + "/joint_states", kWarmUpFrames + frames),
        base(*robot, probe),
        driver(context.paths, ns, userParams(robot->port(), condition, context, variant),
               programOf(context, variant)),
        subscribers(context.nh, ns),
        cmd_vel(context.nh.advertise<geometry_msgs::Twist>(driver.topic("cmd_vel"), 10)) {
    warmUpTelemetry(probe, *robot, kWarmUpFrames, context.paths.log(ns));
    require(waitUntil([&] { return base.log().count() > 0 && cmd_vel.getNumSubscribers() > 0; },
                      30s),
            "no speed frame or no cmd_vel subscriber; see " + context.paths.log(ns));
  }

  // In the order they start; the program stops (and writes its zero-speed frame) while the
  // played base still reads.
  const std::unique_ptr<RobotEnd> robot;
  TelemetryProbe probe;
  const PlayedBase base;
  DriverProcess driver;
  const UserSubscribers subscribers;
  ros::Publisher cmd_vel;
};

/// The pty's (or socket's) name of a session of section 8 (scripts/trace_realtime.sh finds a
/// session by its prefix).
std::string userNamespace(const std::string& tag, const UserCondition& condition,
                          std::size_t round, Transport transport) {
  return "user_" + tag + "_" + condition.tag() + "_r" + std::to_string(round) +
         (transport == Transport::kTcp ? "_tcp" : "");
}

/// One session: `variant`'s program set up as users run it (UserSetup); the load (if any) starts
/// once it runs.
UserFigures runUserSession(Context& context, const Variant& variant, const UserCondition& condition,
                           std::size_t round, Transport transport, const UserWindow& window) {
  // Commands 10-40 ms apart: at most 4 frames streamed per command.
  UserSetup setup(context, variant, condition,
                  userNamespace(variant.tag, condition, round, transport), transport,
                  window.frames + 4 * window.commands + 200);
  const BackgroundLoad load(context.paths, condition.loaded);
  require(sleepUntil(Clock::now() + 1s), "stopped");
  uint32_t seq = UserSetup::kWarmUpFrames;
  UserFigures figures =
      measureStreamingWindow(setup.probe, *setup.robot, setup.base.log(), setup.subscribers,
                             setup.driver.pid(), window.frames, &seq);
  figures.cmd_vel = timeCmdVelWhileStreaming(setup.probe, *setup.robot, seq, setup.cmd_vel,
                                             setup.base.log(), window.commands);
  if (variant.program == kEventDriven.program) {
    context.node_diagnostic_statuses = setup.subscribers.diagnosticStatuses();
    context.node_diagnostic_values = setup.subscribers.diagnosticValues();
  }
  return figures;
}

/// One program's CPU over a window by thread, s/s: its port reader, its base loop, and the rest
/// (roscpp's threads, the callbacks, threads that ended in the window).
struct CpuByThread {
  double reader = 0;
  double loop = 0;
  double rest = 0;
};

/// How a program's reader and loop are told apart: driver_node names them; floor_node names its
/// reader and runs its loop on the main thread (loop nullptr).
struct ThreadRoles {
  const char* reader;
  const char* loop;
};
constexpr ThreadRoles kNodeThreads{"srd_reader", "srd_base_loop"};
constexpr ThreadRoles kFloorThreads{"floor_reader", nullptr};

/// A program's CPU at the start of a window: the whole process and each thread.
struct CpuMark {
  double process = 0;
  std::map<pid_t, ThreadCpu> threads;
};
CpuMark markCpu(pid_t pid) { return {processCpuSeconds(pid), threadCpuSeconds(pid)}; }

/// The window from `start` to now, per second of `seconds`, split by `roles`.
CpuByThread cpuSince(pid_t pid, const CpuMark& start, double seconds, const ThreadRoles& roles) {
  const CpuMark end = markCpu(pid);
  CpuByThread split;
  for (const auto& [tid, thread] : end.threads) {
    const auto before = start.threads.find(tid);  // a thread started in the window: all of it
    const double earlier = before != start.threads.end() ? before->second.seconds : 0;
    const double used = thread.seconds - earlier;
    const bool loop = roles.loop != nullptr ? thread.name == roles.loop : tid == pid;
    if (thread.name == roles.reader) split.reader += used / seconds;
    if (loop) split.loop += used / seconds;
  }
  split.rest = (end.process - start.process) / seconds - split.reader - split.loop;
  return split;
}

double total(const CpuByThread& cpu) { return cpu.reader + cpu.loop + cpu.rest; }

/// CPU of driver_node and of another program (the same-job floor, or driver_node again) measured
/// over one window in which both run.
struct CpuAtOnce {
  CpuByThread node;
  CpuByThread other;
};

/// driver_node and `other` set up side by side (UserSetup each), then telemetry at 100 Hz to both
/// at once, the two frames of a period written back to back in alternating order: each program's
/// CPU over the same `frames`-frame window. Whatever else the machine does in that window weighs
/// on both, where back-to-back sessions each meet their own moment of it. With `other` driver_node
/// too, the control: how far two identical programs' CPU differ in one window.
CpuAtOnce measureCpuAtOnce(Context& context, const UserCondition& condition, std::size_t round,
                           Transport transport, std::size_t frames, const Variant& other_variant) {
  constexpr std::size_t kSettleFrames = 200;  // both streamed before the window (2 s)
  const bool control = !other_variant.same_job;
  UserSetup node(context, kEventDriven, condition,
                 userNamespace("atonce_" + kEventDriven.tag, condition, round, transport),
                 transport, kSettleFrames + frames + 10);
  UserSetup other(context, other_variant, condition,
                  userNamespace(std::string(control ? "atonce_again_" : "atonce_") +
                                    other_variant.tag,
                                condition, round, transport),
                  transport, kSettleFrames + frames + 10);
  UserSetup* const both[] = {&node, &other};
  uint32_t seq = UserSetup::kWarmUpFrames;
  auto stream = [&](std::size_t count) {
    const Clock::time_point start = Clock::now();
    for (std::size_t k = 0; k < count && !stopRequested(); ++k, ++seq) {
      std::this_thread::sleep_until(start + fromSeconds(k / 100.0));
      for (std::size_t i = 0; i < 2; ++i) {
        UserSetup& setup = *both[(i + k) % 2];
        setup.probe.write(*setup.robot, seq);
      }
    }
  };
  const BackgroundLoad load(context.paths, condition.loaded);
  stream(kSettleFrames);
  const CpuMark node_start = markCpu(node.driver.pid());
  const CpuMark other_start = markCpu(other.driver.pid());
  const Clock::time_point start = Clock::now();
  stream(frames);
  const double seconds = toSeconds(Clock::now() - start);
  CpuAtOnce cpu{cpuSince(node.driver.pid(), node_start, seconds, kNodeThreads),
                cpuSince(other.driver.pid(), other_start, seconds,
                         control ? kNodeThreads : kFloorThreads)};
  require(node.driver.running() && other.driver.running(), "a program stopped mid-window");
  return cpu;
}

/// One figure of section 8, taken from a session's UserFigures. A latency or jitter figure is a
/// statistic of samples: over several rounds it is that statistic of every round's samples
/// pooled (a p99 of all the commands, not a mean of each round's p99); the others are the mean
/// of the rounds' values.
struct UserFigure {
  const char* name;
  const char* unit;
  int decimals;
  double (*of)(const UserFigures&);
  const std::vector<double>& (*samples)(const UserFigures&) = nullptr;
  double (*statistic)(const Summary&) = nullptr;
};
const std::vector<double>& cmdVelSamples(const UserFigures& f) { return f.cmd_vel.samples_ms; }
const std::vector<double>& telemetrySamples(const UserFigures& f) {
  return f.telemetry.samples_ms;
}
const std::vector<double>& loopPeriods(const UserFigures& f) { return f.loop.periods_ms; }
const std::vector<double>& stampedLoopPeriods(const UserFigures& f) {
  return f.loop_stamped.periods_ms;
}
double p50Of(const Summary& s) { return s.p50; }
double p99Of(const Summary& s) { return s.p99; }
double stddevOf(const Summary& s) { return s.stddev; }
double maxOf(const Summary& s) { return s.max; }

const std::vector<UserFigure> kUserFigures{
    {"CPU at 100 Hz telemetry, 20 servos", "s/s", 4, [](const UserFigures& f) { return f.cpu; }},
    {"cmd_vel -> speed frame p50", "ms", 3, [](const UserFigures& f) { return f.cmd_vel.ms.p50; },
     cmdVelSamples, p50Of},
    {"cmd_vel -> speed frame p99", "ms", 3, [](const UserFigures& f) { return f.cmd_vel.ms.p99; },
     cmdVelSamples, p99Of},
    {"cmd_vel never on the wire", "%", 1,
     [](const UserFigures& f) {
       return 100.0 * f.cmd_vel.lost / std::max<std::size_t>(1, f.cmd_vel.attempted);
     }},
    {"telemetry -> joint_states p50", "ms", 3,
     [](const UserFigures& f) { return f.telemetry.ms.p50; }, telemetrySamples, p50Of},
    {"telemetry -> joint_states p99", "ms", 3,
     [](const UserFigures& f) { return f.telemetry.ms.p99; }, telemetrySamples, p99Of},
    {"50 Hz loop jitter (std) while telemetry streams", "ms", 3,
     [](const UserFigures& f) { return f.loop.period_ms.stddev; }, loopPeriods, stddevOf},
    {"50 Hz loop worst period", "ms", 3, [](const UserFigures& f) { return f.loop.period_ms.max; },
     loopPeriods, maxOf},
    {"50 Hz loop jitter (std), the program's odom stamps", "ms", 3,
     [](const UserFigures& f) { return f.loop_stamped.period_ms.stddev; }, stampedLoopPeriods,
     stddevOf},
    {"50 Hz loop worst period, the program's odom stamps", "ms", 3,
     [](const UserFigures& f) { return f.loop_stamped.period_ms.max; }, stampedLoopPeriods, maxOf},
};

/// Every session of section 8, per condition (kUserConditions' order), one entry per round: the
/// node's, the same-job floor's (floor_node ~same_job) and the minimal floor's.
struct UserRuns {
  std::vector<std::vector<UserFigures>> node{kUserConditions.size()};
  std::vector<std::vector<UserFigures>> same_job{kUserConditions.size()};
  std::vector<std::vector<UserFigures>> floor{kUserConditions.size()};
  /// measureCpuAtOnce's, per condition with RT off, one entry per round: against the same-job
  /// floor, and the control against driver_node itself.
  std::vector<std::vector<CpuAtOnce>> cpu_at_once{kUserConditions.size()};
  std::vector<std::vector<CpuAtOnce>> cpu_against_itself{kUserConditions.size()};
  std::vector<std::vector<UserFigures>>& of(const Variant& variant) {
    if (variant.same_job) return same_job;
    return variant.program == kFloor.program ? floor : node;
  }
};

/// `figure` over the rounds of one condition (pooled or averaged, see UserFigure); nullopt when
/// none completed, or when a figure of samples has none (the minimal floor publishes no odom).
std::optional<double> roundsFigure(const std::vector<UserFigures>& rounds,
                                   const UserFigure& figure) {
  if (rounds.empty()) return std::nullopt;
  if (figure.samples) {
    std::vector<double> pooled;
    for (const UserFigures& round : rounds) {
      const std::vector<double>& samples = figure.samples(round);
      pooled.insert(pooled.end(), samples.begin(), samples.end());
    }
    if (pooled.empty()) return std::nullopt;
    return figure.statistic(summarize(pooled));
  }
  std::vector<double> values;
  for (const UserFigures& round : rounds) values.push_back(figure.of(round));
  return meanOf(values);
}

/// "node, same-job floor, node / same job, minimal floor, node / minimal" cells of one figure in
/// one condition (kUserConditions' index).
std::vector<std::string> userCells(const UserRuns& runs, std::size_t condition,
                                   const UserFigure& figure) {
  const auto node = roundsFigure(runs.node[condition], figure);
  const auto same_job = roundsFigure(runs.same_job[condition], figure);
  const auto floor = roundsFigure(runs.floor[condition], figure);
  auto cell = [&](std::optional<double> value) {
    return value ? format("%.*f %s", figure.decimals, *value, figure.unit) : std::string("-");
  };
  auto ratio = [&](std::optional<double> yardstick) {
    return node && yardstick && *yardstick > 0 ? format("%.2fx", *node / *yardstick)
                                               : std::string("-");
  };
  return {cell(node), cell(same_job), ratio(same_job), cell(floor), ratio(floor)};
}

/// Node / same-job floor in each round on its own ("0.94x, 1.31x"): how far the figure moves from
/// one round to the next, to judge a goal missed or met by a few percent. Rounds pair in the
/// order they completed.
std::string perRoundRatios(const UserRuns& runs, std::size_t condition, const UserFigure& figure) {
  const std::vector<UserFigures>& node = runs.node[condition];
  const std::vector<UserFigures>& same_job = runs.same_job[condition];
  std::string text;
  for (std::size_t round = 0; round < std::min(node.size(), same_job.size()); ++round) {
    const double yardstick = figure.of(same_job[round]);
    if (!text.empty()) text += ", ";
    text += yardstick > 0 ? format("%.2fx", figure.of(node[round]) / yardstick) : "-";
  }
  return text.empty() ? "-" : text;
}

/// The summary's cells for the CPU measured with two programs at once in one condition's rounds:
/// as userCells() and perRoundRatios() fill them (the minimal floor did not take part).
std::vector<std::string> cpuAtOnceCells(const std::vector<CpuAtOnce>& rounds) {
  if (rounds.empty()) return {"-", "-", "-", "-", "-", "-"};
  std::vector<double> node, other;
  std::string each_round;
  for (const CpuAtOnce& round : rounds) {
    node.push_back(total(round.node));
    other.push_back(total(round.other));
    if (!each_round.empty()) each_round += ", ";
    each_round += other.back() > 0 ? format("%.2fx", node.back() / other.back()) : "-";
  }
  const double node_mean = *meanOf(node), other_mean = *meanOf(other);  // both non-empty
  return {format("%.4f s/s", node_mean), format("%.4f s/s", other_mean),
          other_mean > 0 ? format("%.2fx", node_mean / other_mean) : "-", "-", "-", each_round};
}

/// The columns userCells() fills.
const std::vector<std::string> kUserColumns{"driver_node", "same-job floor", "node / same job",
                                            "minimal floor", "node / minimal"};

/// Indices into kUserFigures and kUserConditions for the summary.
enum UserFigureIndex {
  kCpuFigure = 0,
  kCmdVelP99 = 2,
  kTelemetryP99 = 5,
  kLoopJitter = 6,
  kStampedLoopJitter = 8
};
enum UserConditionIndex { kQuietIndex = 0, kLoadedIndex = 2, kLoadedRtIndex = 3 };

/// What a transport's tables say about the line their figures include.
std::string transportLabel(Transport transport) {
  return transport == Transport::kTcp
             ? "over loopback TCP (no pty worker: the programs' own latency)"
             : "over a pty (includes the kernel's pty worker)";
}

/// Issue 43's table: its rows, in its order, from section 8's sessions over `transport`.
void addUserSummary(ResultTable& table, const UserRuns& runs, Transport transport) {
  std::vector<std::string> columns{"figure"};
  columns.insert(columns.end(), kUserColumns.begin(), kUserColumns.end());
  columns.push_back("node / same job, each round");
  columns.push_back("goal (node / same job)");
  table.section("8. The configuration users run against the floor, " + transportLabel(transport) +
                    ": summary (issue 43's rows)",
                columns);
  struct Row {
    const char* what;
    UserFigureIndex figure;
    UserConditionIndex condition;
    const char* goal;
    /// The CPU with two programs at once (cpuAtOnceCells): the same-job floor, or the control.
    std::vector<std::vector<CpuAtOnce>> UserRuns::*at_once = nullptr;
  };
  constexpr auto kAtOnce = &UserRuns::cpu_at_once;
  constexpr auto kControl = &UserRuns::cpu_against_itself;
  const Row rows[] = {
      {"CPU at 100 Hz telemetry, 20 servos", kCpuFigure, kQuietIndex, "<= 1.1x"},
      {"the same, node and same-job floor at once", kCpuFigure, kQuietIndex, "<= 1.1x", kAtOnce},
      {"control: driver_node and a second driver_node at once", kCpuFigure, kQuietIndex,
       "(the measurement's spread)", kControl},
      {"cmd_vel -> speed frame on the wire, p99", kCmdVelP99, kQuietIndex, "<= 1 ms and <= 1.2x"},
      {"telemetry last byte -> joint_states, p99 (quiet)", kTelemetryP99, kQuietIndex, "keep"},
      {"the same with a CPU hog at nice 0 on each core", kTelemetryP99, kLoadedIndex, "<= 1.2x"},
      {"the same, ~realtime_priority on", kTelemetryP99, kLoadedRtIndex, "<= 1.0x"},
      {"50 Hz loop jitter (std) while telemetry streams, under that load", kLoopJitter,
       kLoadedIndex, "<= 1.2x"},
      {"the same, ~realtime_priority on", kLoopJitter, kLoadedRtIndex, "<= 1.0x"},
      {"the same by the program's own clock (its odom stamps: the loop without the line)",
       kStampedLoopJitter, kLoadedRtIndex, "(where the line's share is)"},
      {"CPU under that load", kCpuFigure, kLoadedIndex, "<= 1.1x"},
      {"the same, node and same-job floor at once", kCpuFigure, kLoadedIndex, "<= 1.1x", kAtOnce},
      {"control: driver_node and a second driver_node at once", kCpuFigure, kLoadedIndex,
       "(the measurement's spread)", kControl},
  };
  for (const Row& row : rows) {
    std::vector<std::string> cells{row.what};
    if (row.at_once != nullptr) {
      const auto figures = cpuAtOnceCells((runs.*row.at_once)[row.condition]);
      cells.insert(cells.end(), figures.begin(), figures.end());
    } else {
      const auto figures = userCells(runs, row.condition, kUserFigures[row.figure]);
      cells.insert(cells.end(), figures.begin(), figures.end());
      cells.push_back(perRoundRatios(runs, row.condition, kUserFigures[row.figure]));
    }
    cells.push_back(row.goal);
    table.row(cells);
  }
  table.note(
      "The control rows put a second driver_node where the same-job floor stands at once: two "
      "identical programs, so each round's ratio is how far this machine moves one program's CPU "
      "against another's in one window (the phases of their threads' wake-ups against each "
      "other's and the load's). A node / same-job ratio within that spread of 1.0 is not told "
      "apart from it by these rounds.");
}

/// Where the CPU measured at once goes, by thread (the mean of the rounds): which of the node's
/// threads holds what it spends beyond the same-job floor, per event of that thread.
void addCpuAtOnceByThread(ResultTable& table, const UserRuns& runs, Transport transport) {
  table.section("8. The configuration users run against the floor, " + transportLabel(transport) +
                    ": CPU at once, by thread (RT off, the mean of the rounds)",
                {"load", "thread", "driver_node", "same-job floor", "node - same job",
                 "the same per event"});
  struct Role {
    const char* name;
    double (*of)(const CpuByThread&);
    double events_per_second;  ///< 0: per second
    const char* event;
  };
  const Role roles[] = {
      {"port reader", [](const CpuByThread& c) { return c.reader; }, 100.0, "telemetry frame"},
      {"base loop", [](const CpuByThread& c) { return c.loop; }, 50.0, "loop tick"},
      {"the rest (roscpp, callbacks)", [](const CpuByThread& c) { return c.rest; }, 0, "s"},
      {"all", total, 0, "s"},
  };
  for (UserConditionIndex condition : {kQuietIndex, kLoadedIndex}) {
    const std::vector<CpuAtOnce>& rounds = runs.cpu_at_once[condition];
    if (rounds.empty()) continue;
    for (const Role& role : roles) {
      std::vector<double> node, same_job;
      for (const CpuAtOnce& round : rounds) {
        node.push_back(role.of(round.node));
        same_job.push_back(role.of(round.other));
      }
      const double node_ms = 1e3 * *meanOf(node), same_job_ms = 1e3 * *meanOf(same_job);
      const double gap_ms = node_ms - same_job_ms;
      const std::string per_event =
          role.events_per_second > 0
              ? format("%+.1f us a %s", 1e3 * gap_ms / role.events_per_second, role.event)
              : format("%+.3f ms/s", gap_ms);
      table.row({kUserConditions[condition].load(), role.name, format("%.3f ms/s", node_ms),
                 format("%.3f ms/s", same_job_ms), format("%+.3f ms/s", gap_ms), per_event});
    }
  }
  table.note(
      "Each program's CPU by thread over the at-once window, from the scheduler's count of each "
      "thread (/proc/<pid>/task/<tid>/schedstat): driver_node's srd_reader and srd_base_loop, "
      "floor_node's floor_reader and its main thread (its loop); the rest is the process's CPU "
      "less those two.");
}

/// Every figure in every condition, over `transport`.
void addUserRows(ResultTable& table, const UserRuns& runs, Transport transport) {
  std::vector<std::string> columns{"figure", "load", "RT"};
  columns.insert(columns.end(), kUserColumns.begin(), kUserColumns.end());
  table.section("8. The configuration users run against the floor, " + transportLabel(transport) +
                    ": every figure",
                columns);
  for (const UserFigure& figure : kUserFigures) {
    for (std::size_t condition = 0; condition < kUserConditions.size(); ++condition) {
      std::vector<std::string> row{figure.name, kUserConditions[condition].load(),
                                   kUserConditions[condition].rt()};
      const auto cells = userCells(runs, condition, figure);
      row.insert(row.end(), cells.begin(), cells.end());
      table.row(row);
    }
  }
}

/// Each transport's session window: --telemetry-frames and half of --commands, shared over the
/// rounds; over TCP scaled by tcpWindow() to keep the default run under 9 minutes.
UserWindow userWindow(const Options& options, Transport transport) {
  const double share = transport == Transport::kTcp ? options.tcpWindow() : 1.0;
  const std::size_t rounds = options.floor_rounds;
  return {std::max<std::size_t>(200, std::lround(share * options.telemetry_frames / rounds)),
          std::max<std::size_t>(100, std::lround(share * options.commands / (2 * rounds)))};
}

void addUserNote(Context& context) {
  const Options& o = context.options;
  ResultTable& table = context.results;
  table.note(
      "driver_node in the configuration users run (the defaults: base, body and servo bus on one "
      "port, odom and /tf, diagnostics, battery poll; 20 body servos; speed_dithering off and "
      "max_wheel_speed 20 so each command is recognisable on the wire) and floor_node with the "
      "same parameters, twice: the same-job floor (~same_job: besides joint_states, imu/data per "
      "frame, odom + /tf + wheel_states per tick, /diagnostics at 1 Hz with as many statuses and "
      "key/values as "
      "driver_node's, all as minimally as possible; ~same_interface: the rest of driver_node's "
      "publications, subscriptions, dynamic_reconfigure servers and action server, each doing "
      "nothing but exist, and the 1 Hz battery poll) and the minimal floor (joint_states only); "
      "this process plays the robot (telemetry of 20 servos at 100 Hz, battery answers).");
  table.note(
      "Subscribed throughout: joint_states (robot_state_publisher), wheel_states "
      "(joint_state_publisher), imu/data, odom, /tf (rviz, navigation), /diagnostics "
      "(diagnostic_aggregator).");
  table.note(
      "Transports: over a pty this process holds the master and the program opens the slave; the "
      "kernel moves the bytes each way on its pty worker (flush_to_ldisc, a normal-priority "
      "kworker), which no thread priority reaches. Over loopback TCP this process listens on "
      "127.0.0.1 (an ephemeral port per session) and the program connects to "
      "tcp://127.0.0.1:<port> (TCP_NODELAY at both ends): a write() wakes the reader directly, so "
      "those figures are the programs' own latency.");
  for (Transport transport : o.transports) {
    const UserWindow window = userWindow(o, transport);
    table.note(format(
        "Per session over %s: %zu frames at 100 Hz without cmd_vel (CPU from the process's clock "
        "over that window, telemetry latency, loop periods from speed frame arrivals and from the "
        "program's own odom stamps, which both programs take from their clock at each tick), "
        "then %zu cmd_vel commands 10-40 ms apart while telemetry streams.",
        transportName(transport).c_str(), window.frames, window.commands));
  }
  table.note(format(
      "%zu round(s); per condition and transport node and both floors back to back, which goes "
      "first rotating; the transports alternate within each condition. Percentiles and the "
      "loop's std and worst period are of every round's samples pooled, CPU and the lost share "
      "the mean of the rounds'; the summary also gives node / same job in each round alone, "
      "which shows how far a ratio moves between rounds on this machine.",
      o.floor_rounds));
  table.note(
      "\"At once\" (RT off, per round after the three sessions): driver_node and the same-job "
      "floor set up side by side, each on its own line with its own subscribers, then telemetry "
      "at 100 Hz to both, a period's two frames back to back in alternating order, for as many "
      "frames as a session's window: each process's CPU over that one window. What else the "
      "machine does then weighs on both, where sessions back to back each meet their own "
      "moment of it; the two share the cores, so the absolute figures are not a lone program's.");
  table.note(format(
      "Load: one `sh` busy loop per core at nice 0, from 1 s before the window. RT on: "
      "~realtime_priority %s for all (the floors take SCHED_FIFO at it on their main thread before "
      "roscpp starts, so every thread inherits it; driver_node takes one below there and the "
      "priority itself on its port readers and base loop; memory locked). This benchmark's own "
      "threads: %s. ~scheduler_slice_us: driver_node %s, the floors %s, the control's second "
      "driver_node %s. The control's second driver_node: %s.",
      o.realtime_priority.c_str(),
      context.bench_priority > 0 ? format("SCHED_FIFO %d", context.bench_priority).c_str()
                                 : "normal priority",
      o.node_slice_us < 0 ? "its default (100 us)" : format("%d us", o.node_slice_us).c_str(),
      o.floor_slice_us > 0 ? format("%d us", o.floor_slice_us).c_str() : "the kernel's slice",
      o.control_slice_us < 0 ? "as driver_node" : format("%d us", o.control_slice_us).c_str(),
      o.control_bin.empty() ? "the same executable" : o.control_bin.c_str()));
}

/// Section 8's sessions, per transport.
using UserRunsByTransport = std::map<Transport, UserRuns>;

/// One round of section 8: in each condition run, over each transport, driver_node and both
/// floors back to back, which goes first rotating (driver_node first of all: the same-job floor
/// takes its count of diagnostic statuses).
void runUserRound(Context& context, std::size_t round, UserRunsByTransport* runs) {
  const Options& o = context.options;
  for (std::size_t c = 0; c < kUserConditions.size(); ++c) {
    const UserCondition& condition = kUserConditions[c];
    if (!o.conditions.empty() && o.conditions.count(condition.tag()) == 0) continue;
    for (Transport transport : o.transports) {
      const UserWindow window = userWindow(o, transport);
      const Variant* const programs[] = {&kEventDriven, &kSameJobFloor, &kFloor};
      for (std::size_t k = 0; k < 3; ++k) {
        const Variant& variant = *programs[(k + c + round) % 3];
        auto& into = (*runs)[transport].of(variant)[c];
        attempt(
            context,
            format("8. %s, %s, RT %s, %s, round %zu",
                   variant.same_job ? "floor_node ~same_job" : variant.program.c_str(),
                   condition.load().c_str(), condition.rt().c_str(),
                   transportName(transport).c_str(), round + 1),
            [&] {
              into.push_back(runUserSession(context, variant, condition, round, transport, window));
            });
      }
      if (condition.realtime) continue;
      // At once against the same-job floor, then the control against a second driver_node.
      const std::pair<const Variant*, std::vector<std::vector<CpuAtOnce>> UserRuns::*> at_once[] =
          {{&kSameJobFloor, &UserRuns::cpu_at_once},
           {&kControlCopy, &UserRuns::cpu_against_itself}};
      for (const auto& entry : at_once) {
        const Variant* const other = entry.first;
        const auto into = entry.second;
        attempt(context,
                format("8. driver_node and %s at once, %s, %s, round %zu",
                       other->same_job ? "floor_node ~same_job" : "a second driver_node",
                       condition.load().c_str(), transportName(transport).c_str(), round + 1),
                [&] {
                  ((*runs)[transport].*into)[c].push_back(measureCpuAtOnce(
                      context, condition, round, transport, window.frames, *other));
                });
      }
    }
  }
}

/// Section 8: driver_node and floor_node (same job, minimal) in every condition (quiet / loaded, RT
/// off / on), over each transport (--transport); the summary and every figure per transport.
void runUserConfiguration(Context& context) {
  UserRunsByTransport runs;
  for (std::size_t round = 0; round < context.options.floor_rounds && !stopRequested(); ++round) {
    runUserRound(context, round, &runs);
  }
  for (Transport transport : context.options.transports) {
    addUserSummary(context.results, runs[transport], transport);
    addCpuAtOnceByThread(context.results, runs[transport], transport);
  }
  for (Transport transport : context.options.transports) {
    addUserRows(context.results, runs[transport], transport);
  }
  addUserNote(context);
}

/// What the sessions of sections 1-5 measured, compared again in 7 and 9.
struct SessionResults {
  BaseSessionResult base_event, base_polling;
  TelemetrySessionResult body_event, body_polling;
};

/// Sections 1-3: the event-driven node's base.
void runBaseSections(Context& context, SessionResults* results) {
  const Options& o = context.options;
  ResultTable& table = context.results;
  BaseSessionResult& base_event = results->base_event;
  if (o.runs(1) || o.runs(2) || o.runs(3)) {
    attempt(context, "base session (1-3)", [&] {
      base_event = runBaseSession(context, kEventDriven, o.runs(1), o.runs(2) || o.runs(3));
    });
  }
  if (base_event.cmd_vel) {
    table.section("1. cmd_vel publish -> speed frame's last byte on the pty (50 Hz loop)");
    addLatencyRows(table, "cmd_vel -> frame", *base_event.cmd_vel, 1.0);
    table.note(
        "One command per loop period, published 12 ms after a loop frame (outside the "
        "node's 2x-loop-rate limit), distinct wheel ticks per command.");
  }
  if (base_event.idle_loop && o.runs(2)) {
    table.section(format("2. Base loop period at 50 Hz, idle, from pty arrival times (%.0f s)",
                         o.loop_seconds));
    addLoopRows(table, "loop", *base_event.idle_loop, true);
  }
  if (base_event.idle_loop && o.runs(3)) {
    table.section("3. driver_node CPU, idle at 50 Hz (base only)");
    table.row("CPU (utime+stime / wall)", percent(base_event.idle_loop->cpu_percent), "<= 0.5 %",
              base_event.idle_loop->cpu_percent <= 0.5);
    table.note("From the process's kernel CPU clock (clock_getcpuclockid, ns resolution).");
  }
}

// The goal applies to the node as shipped (event-driven); the polling variant is only compared.
void addRateSteps(ResultTable& table, const std::string& title,
                  const TelemetrySessionResult& session, bool with_goal, double step_seconds) {
  table.section(
      title, {"target", "achieved", "frames", "dropped at pty", "delivered", "ratio", ">= 99.9 %"});
  for (const RateStep& step : session.steps) {
    table.row({format("%.0f Hz", step.target_hz), format("%.0f Hz", step.achieved_hz),
               format("%zu", step.attempted), format("%zu", step.dropped_at_pty),
               format("%zu", step.delivered), format("%.2f %%", 100 * step.ratio()),
               verdict(step.ratio() >= 0.999)});
  }
  const double best = session.max_rate_hz.value_or(0);
  table.note(format("Highest rate with >= 99.9 %% published: %.0f Hz%s. Each step %g s.", best,
                    with_goal ? (" (goal >= 1000 Hz: " + verdict(best >= 1000) + ")").c_str() : "",
                    step_seconds));
}

/// Sections 4-5: the event-driven node's telemetry.
void runTelemetrySections(Context& context, SessionResults* results) {
  const Options& o = context.options;
  ResultTable& table = context.results;
  TelemetrySessionResult& body_event = results->body_event;
  if (o.runs(4) || o.runs(5)) {
    attempt(context, "telemetry session (4-5)",
            [&] { body_event = runTelemetrySession(context, kEventDriven, o.runs(4), o.runs(5)); });
  }
  if (body_event.latency) {
    table.section("4. Telemetry last byte written -> joint_states received (20 servos, 100 Hz)");
    addLatencyRows(table, "telemetry -> joint_states", *body_event.latency, 0.5);
    table.row("driver_node CPU at 100 Hz", percent(body_event.cpu_percent), "<= 0.5 %",
              body_event.cpu_percent <= 0.5);
  }
  if (!body_event.steps.empty()) {
    addRateSteps(table, "5. Telemetry rate steps: frames published as joint_states", body_event,
                 true, o.rate_step_seconds);
  }
}

/// Section 6.
void runServoSessionSection(Context& context) {
  ResultTable& table = context.results;
  attempt(context, "servo session (6)", [&] {
    const ServoSessionResult servo = runServoSession(context);
    table.section("6. servo/read round trip against robot_sim, and the wheel loop under calls");
    addLatencyRows(table, "servo/read, new connection per call", servo.new_connection, {});
    addLatencyRows(table, "servo/read, persistent client", servo.persistent, {});
    addLoopRows(table, "wheel loop idle", servo.idle, false);
    addLoopRows(table, "wheel loop under servo/read stress", servo.stress, false);
    table.row("stress: servo/read calls completed",
              format("%.0f /s (%zu failed)", servo.calls_per_second, servo.failed_stress_calls));
    table.note(
        "robot_sim answers after 1.5 ms (its default --servo-latency-ms). Wheel periods "
        "from wheel_command header stamps; stress = 3 persistent clients + 1 opening a "
        "connection per call, back to back.");
  });
}

/// A row of a before/after comparison (7, 9): both values and after / before.
void compareRow(ResultTable& table, const std::string& what, double before, double after,
                const std::string& unit, int decimals) {
  table.row({what, format("%.*f %s", decimals, before, unit.c_str()),
             format("%.*f %s", decimals, after, unit.c_str()), ratio(after, before)});
}

/// Section 7: the polling variant against what 1-5 measured.
void runPollingComparison(Context& context, SessionResults* results) {
  const Options& o = context.options;
  ResultTable& table = context.results;
  const BaseSessionResult& base_event = results->base_event;
  const TelemetrySessionResult& body_event = results->body_event;
  BaseSessionResult& base_polling = results->base_polling;
  TelemetrySessionResult& body_polling = results->body_polling;
  if (o.runs(1) && base_event.cmd_vel) {
    attempt(context, "polling base session (7)",
            [&] { base_polling = runBaseSession(context, kPolling, true, false); });
  }
  if ((o.runs(4) && body_event.latency) || (o.runs(5) && !body_event.steps.empty())) {
    attempt(context, "polling telemetry session (7)",
            [&] { body_polling = runTelemetrySession(context, kPolling, o.runs(4), o.runs(5)); });
  }
  table.section("7. Event-driven vs polling reads (~read_poll_interval 0.02)",
                {"measurement", kEventDriven.name, kPolling.name, "polling / event"});
  if (base_event.cmd_vel && base_polling.cmd_vel) {
    compareRow(table, "1. cmd_vel -> frame p50", base_event.cmd_vel->ms.p50,
               base_polling.cmd_vel->ms.p50, "ms", 3);
    compareRow(table, "1. cmd_vel -> frame p99", base_event.cmd_vel->ms.p99,
               base_polling.cmd_vel->ms.p99, "ms", 3);
  }
  if (body_event.latency && body_polling.latency) {
    compareRow(table, "4. telemetry -> joint_states p50", body_event.latency->ms.p50,
               body_polling.latency->ms.p50, "ms", 3);
    compareRow(table, "4. telemetry -> joint_states p99", body_event.latency->ms.p99,
               body_polling.latency->ms.p99, "ms", 3);
    compareRow(table, "4. node CPU at 100 Hz", body_event.cpu_percent, body_polling.cpu_percent,
               "%", 2);
  }
  if (!body_event.steps.empty() && !body_polling.steps.empty()) {
    compareRow(table, "5. highest rate >= 99.9 %", body_event.max_rate_hz.value_or(0),
               body_polling.max_rate_hz.value_or(0), "Hz", 0);
  }
  table.note(
      "cmd_vel -> frame does not go through the port reader, so polling should not "
      "change it; telemetry does.");
  if (!body_polling.steps.empty()) {
    addRateSteps(table, "7b. Telemetry rate steps, polling variant", body_polling, false,
                 o.rate_step_seconds);
  }
}

/// Section 9: ~capture on against off (2-4's numbers when they ran, else measured here).
void runCaptureComparison(Context& context, SessionResults* results) {
  ResultTable& table = context.results;
  BaseSessionResult& base_event = results->base_event;
  TelemetrySessionResult& body_event = results->body_event;
  if (!base_event.idle_loop) {
    attempt(context, "base session without capture (9)",
            [&] { base_event = runBaseSession(context, kEventDriven, false, true); });
  }
  if (!body_event.latency) {
    attempt(context, "telemetry session without capture (9)",
            [&] { body_event = runTelemetrySession(context, kEventDriven, true, false); });
  }
  BaseSessionResult base_capture;
  TelemetrySessionResult body_capture;
  attempt(context, "base session with capture (9)",
          [&] { base_capture = runBaseSession(context, kCapturing, false, true); });
  attempt(context, "telemetry session with capture (9)",
          [&] { body_capture = runTelemetrySession(context, kCapturing, true, false); });
  table.section("9. ~capture off vs on (serial_raw subscribed)",
                {"measurement", "capture off", "capture on", "on / off"});
  if (base_event.idle_loop && base_capture.idle_loop) {
    const LoopResult& off = *base_event.idle_loop;
    const LoopResult& on = *base_capture.idle_loop;
    compareRow(table, "2. base loop period std", off.period_ms.stddev, on.period_ms.stddev, "ms",
               3);
    compareRow(table, "2. base loop worst period", off.period_ms.max, on.period_ms.max, "ms", 3);
    compareRow(table, "2. missed ticks", off.missed_ticks, on.missed_ticks, "", 0);
    compareRow(table, "3. node CPU idle at 50 Hz", off.cpu_percent, on.cpu_percent, "%", 2);
  }
  if (body_event.latency && body_capture.latency) {
    compareRow(table, "4. telemetry -> joint_states p50", body_event.latency->ms.p50,
               body_capture.latency->ms.p50, "ms", 3);
    compareRow(table, "4. telemetry -> joint_states p99", body_event.latency->ms.p99,
               body_capture.latency->ms.p99, "ms", 3);
    compareRow(table, "4. node CPU at 100 Hz", body_event.cpu_percent, body_capture.cpu_percent,
               "%", 2);
  }
  table.note(
      "With capture every chunk read and every frame written is copied, stamped and queued; "
      "a thread of its own publishes serial_raw, so the loop and the reader never wait for it.");
}

void run(Context& context) {
  const Options& o = context.options;
  SessionResults results;
  runBaseSections(context, &results);
  runTelemetrySections(context, &results);
  if (o.runs(6)) runServoSessionSection(context);
  if (o.runs(7)) runPollingComparison(context, &results);
  if (o.runs(8)) runUserConfiguration(context);
  if (o.runs(9)) runCaptureComparison(context, &results);
  if (o.runs(10)) {
    attempt(context, "servo bus at the wire's pace (10)", [&] { runServoBusSection(context); });
  }
  if (o.runs(11)) runFloorComparison(context);
}

std::string executableDirectory() {
  std::vector<char> path(4096);
  const ssize_t length = ::readlink("/proc/self/exe", path.data(), path.size() - 1);
  if (length <= 0) return ".";
  const std::string exe(path.data(), static_cast<std::size_t>(length));
  return exe.substr(0, exe.rfind('/'));
}

std::string header(const Options& options) {
  const std::time_t now = std::time(nullptr);
  char date[64];
  std::strftime(date, sizeof(date), "%Y-%m-%d %H:%M:%S", std::localtime(&now));
  double load[3] = {0, 0, 0};
  ::getloadavg(load, 3);
  return format("# driver_node benchmarks\n\n%s, %ld CPUs, load average %.2f %.2f %.2f, %s run.\n",
                date, ::sysconf(_SC_NPROCESSORS_ONLN), load[0], load[1], load[2],
                options.long_run ? "long" : "default");
}

/// Whether every program the run starts is in paths.bin_dir (said on stderr when not).
bool programsFound(const RunPaths& paths) {
  for (const char* program :
       {"driver_node", "polling_driver_node", "robot_sim", "floor_node", "servo_floor"}) {
    if (::access((paths.bin_dir + "/" + program).c_str(), X_OK) != 0) {
      std::cerr << "driver_bench: " << paths.bin_dir << "/" << program
                << " not found: build the driver_bench target first\n";
      return false;
    }
  }
  return true;
}

/// This process's threads (and every thread it starts from now on: the robot it plays, the
/// subscribers that time the node) at SCHED_FIFO `priority`, so that a background load delays the
/// node under test rather than the measuring. Children start with the normal policy
/// (ChildProcess). Returns the priority applied; 0 when off or not allowed (said on stderr).
int raiseOwnPriority(int priority) {
  if (priority <= 0) return 0;
  sched_param param{};
  param.sched_priority = priority;
  if (::sched_setscheduler(0, SCHED_FIFO, &param) != 0) {
    std::cerr << "driver_bench: SCHED_FIFO " << priority << " not allowed (" << std::strerror(errno)
              << "); measuring at normal priority" << std::endl;
    return 0;
  }
  return priority;
}

/// Runs the sections against a roscore of our own; the exit status, the report in `report`
/// (empty when the run never got to it).
int runWithMaster(int argc, char** argv, const Options& options, const RunPaths& paths,
                  std::string* report) {
  const std::string started = header(options);
  const int bench_priority = raiseOwnPriority(options.bench_priority);
  int status = 0;
  try {
    RosMaster master(paths, options.master_port ? options.master_port : findFreeTcpPort());
    ros::init(argc, argv, "driver_bench", ros::init_options::NoSigintHandler);
    // Our own INFO lines (waitForService ...) would interleave with the table on stdout.
    if (ros::console::set_logger_level("ros", ros::console::levels::Warn)) {
      ros::console::notifyLoggerLevelsChanged();
    }
    std::cerr << "driver_bench: roscore at " << master.uri() << ", logs in " << paths.work_dir
              << std::endl;
    master.waitUntilUp(std::chrono::seconds(60));
    Context context{options, paths, ros::NodeHandle(), {}, 0, bench_priority};
    ros::AsyncSpinner spinner(2);
    spinner.start();
    run(context);
    spinner.stop();
    *report = started + context.results.markdown();
    if (stopRequested()) *report += "\n**Interrupted: partial results.**\n";
    if (context.failures > 0) status = 1;
    ros::shutdown();
  } catch (const std::exception& error) {
    std::cerr << "driver_bench: " << error.what() << std::endl;
    status = 1;
  }
  return status;
}

/// The report with the load at the end, on stdout and in --output when given.
void writeReport(const Options& options, const RunPaths& paths, std::string report) {
  double load[3] = {0, 0, 0};
  ::getloadavg(load, 3);
  report += format("\nLoad average at the end: %.2f %.2f %.2f. Logs of the nodes: %s\n", load[0],
                   load[1], load[2], paths.work_dir.c_str());
  std::cout << report << std::flush;
  if (!options.output.empty()) {
    std::ofstream(options.output) << report;
    std::cerr << "driver_bench: results written to " << options.output << std::endl;
  }
}

}  // namespace
}  // namespace serial_robot_driver::bench

int main(int argc, char** argv) {
  namespace bench = serial_robot_driver::bench;
  bench::Options options;
  try {
    options = bench::parseOptions(argc, argv);
  } catch (const std::exception& error) {
    std::cerr << "driver_bench: " << error.what() << "\n\n" << bench::kUsage;
    return 2;
  }
  bench::installStopHandler();

  bench::RunPaths paths;
  paths.bin_dir = options.bin_dir.empty() ? bench::executableDirectory() : options.bin_dir;
  if (!bench::programsFound(paths)) return 2;
  char work_dir[] = "/tmp/srd_bench_XXXXXX";
  if (::mkdtemp(work_dir) == nullptr) {
    std::cerr << "driver_bench: cannot create a work directory in /tmp\n";
    return 1;
  }
  paths.work_dir = work_dir;

  std::string report;
  int status = bench::runWithMaster(argc, argv, options, paths, &report);
  if (bench::stopRequested()) status = 130;
  if (!report.empty()) bench::writeReport(options, paths, report);
  return status;
}
