// dds_bench: what the ROS 2 front end (issue 42) costs and how fast it delivers, measured from the
// outside as driver_bench measures the ROS 1 node: this process plays the servo board on a pty
// (20-servo telemetry at 100 Hz, each frame numbered in its first two positions, the time its last
// byte was written kept) and receives joint_states as a plain Cyclone participant (the tests'
// test/dds_front/ros2_peer.h: its own domain, unicast peer 127.0.0.1, rclcpp's default QoS) and,
// for driver_node, as a ROS 1 subscriber too. Three programs, in one run, alternating per round:
//   driver_node with ~ros2/enabled false (ROS 1 only), the same with it true (both graphs), and
//   dds_driver --config <generated yaml> (ROS 2 only, no roscore contacted).
// Each session: the process's CPU over 10 s of streaming, telemetry last byte -> joint_states
// sample received (DDS and ROS 1, matched by the frame number the positions carry, not by order).
// The body alone (base and servo bus off, as driver_bench section 4), so the figures are the
// telemetry path's. Prints a Markdown table; asserts nothing. Run: bench/run_benchmarks.sh --dds.
#include <ros/ros.h>
#include <sensor_msgs/JointState.h>
#include <unistd.h>

#include <array>
#include <cmath>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <memory>
#include <mutex>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "bench_support.h"
#include "dds_front/ros2_peer.h"
#include "ros_bench_support.h"
#include "serial_robot_driver/dds/messages.h"
#include "serial_robot_driver/devices/body/body_codec.h"

namespace serial_robot_driver::bench {
namespace {

using namespace std::chrono_literals;
namespace body = devices::body;

struct Options {
  std::size_t rounds = 3;
  std::size_t frames = 1000;  ///< per session, at 100 Hz
  std::string output;
};

const char* const kUsage = R"(usage: dds_bench [--rounds N] [--frames N] [--output FILE]
  --rounds N   sessions per program, alternating which goes first (default 3)
  --frames N   telemetry frames per session at 100 Hz (default 1000: 10 s)
  --output F   also write the Markdown report to F
  --long       3000 frames per session (give --frames after it to override)
)";

Options parseOptions(int argc, char** argv) {
  Options options;
  for (int i = 1; i < argc; ++i) {
    const std::string flag = argv[i];
    if (flag.find(":=") != std::string::npos) continue;  // ROS remappings
    if (flag == "--long") {                              // run_benchmarks.sh's longer runs
      options.frames = 3000;
      continue;
    }
    if (flag == "--help" || flag == "-h" || i + 1 >= argc) {
      std::cout << kUsage;
      std::exit(flag == "--help" || flag == "-h" ? 0 : 2);
    }
    const std::string value = argv[++i];
    if (flag == "--rounds") {
      options.rounds = std::max<std::size_t>(1, std::stoul(value));
    } else if (flag == "--frames") {
      options.frames = std::stoul(value);
    } else if (flag == "--output") {
      options.output = value;
    } else {
      throw std::invalid_argument("unknown flag: " + flag);
    }
  }
  return options;
}

// --- telemetry frames and the messages they become -------------------------------------------

constexpr std::size_t kServos = 20;
constexpr int kTicksPerRevolution = 4096;

/// Written frames (numbered in the first two servo positions, 12 bits each) and when each
/// subscriber received the message carrying that number.
class FrameTimes {
 public:
  enum Channel { kDds = 0, kRos1 = 1 };

  explicit FrameTimes(std::size_t capacity) : written_(capacity) {
    for (auto& received : received_) received.assign(capacity, Clock::time_point{});
  }
  std::size_t capacity() const { return written_.size(); }

  /// Writes frame `seq`; the time is taken under the lock, so no answer is matched before it.
  bool write(sim::PseudoTerminal& pty, uint32_t seq) {
    body::Telemetry telemetry;
    telemetry.servo_count = kServos;
    for (std::size_t i = 0; i < kServos; ++i) telemetry.servos[i].position = 2048;
    telemetry.servos[0].position = static_cast<uint16_t>(seq & 0xFFF);
    telemetry.servos[1].position = static_cast<uint16_t>((seq >> 12) & 0xFFF);
    const std::vector<uint8_t> frame = body::encodeTelemetry(telemetry);
    std::lock_guard<std::mutex> lock(mutex_);
    if (!writeFrameOrDrop(pty, frame)) return false;
    written_[seq] = Clock::now();
    return true;
  }

  /// A joint_states message whose first two positions (radians) were received at `when`.
  void received(Channel channel, double first, double second, Clock::time_point when) {
    const uint32_t seq = ticksOf(first) | (ticksOf(second) << 12);
    std::lock_guard<std::mutex> lock(mutex_);
    if (seq >= written_.size() || written_[seq] == Clock::time_point{}) return;
    if (received_[channel][seq] == Clock::time_point{}) received_[channel][seq] = when;
  }

  std::vector<double> latenciesMs(Channel channel, uint32_t begin, uint32_t end) const {
    std::lock_guard<std::mutex> lock(mutex_);
    std::vector<double> samples;
    for (uint32_t seq = begin; seq < end && seq < written_.size(); ++seq) {
      const Clock::time_point when = received_[channel][seq];
      if (when != Clock::time_point{}) samples.push_back(toMs(when - written_[seq]));
    }
    return samples;
  }

 private:
  static uint32_t ticksOf(double radians) {
    const long ticks = std::lround(radians * kTicksPerRevolution / (2 * M_PI));
    return static_cast<uint32_t>(((ticks % kTicksPerRevolution) + kTicksPerRevolution) %
                                 kTicksPerRevolution);
  }

  mutable std::mutex mutex_;
  std::vector<Clock::time_point> written_;  ///< per frame number; epoch: not written
  std::array<std::vector<Clock::time_point>, 2> received_;  ///< per channel and frame number
};

/// A DDS reader of joint_states on the peer; a listener stamps each sample in Cyclone's receive
/// thread, as a ROS 2 subscriber's executor would see it at the earliest.
class DdsJointStates {
 public:
  DdsJointStates(dds_test::Ros2Peer& peer, const std::string& topic, FrameTimes& times)
      : times_(times), reader_(peer.reader(sensor_msgs_msg_dds__JointState__desc, topic)) {
    dds_listener_t* listener = dds_create_listener(this);
    dds_lset_data_available(listener, &DdsJointStates::onData);
    dds_set_listener(reader_, listener);
    dds_delete_listener(listener);
  }
  ~DdsJointStates() { dds_delete(reader_); }
  DdsJointStates(const DdsJointStates&) = delete;
  DdsJointStates& operator=(const DdsJointStates&) = delete;

 private:
  static void onData(dds_entity_t reader, void* self) {
    const Clock::time_point when = Clock::now();
    dds_test::takeAll(reader, [&](const void* sample) {
      const auto& state = *static_cast<const sensor_msgs_msg_dds__JointState_*>(sample);
      if (state.position._length < 2) return;
      static_cast<DdsJointStates*>(self)->times_.received(
          FrameTimes::kDds, state.position._buffer[0], state.position._buffer[1], when);
    });
  }
  FrameTimes& times_;
  dds_entity_t reader_;
};

/// A ROS 1 subscriber of joint_states (a robot_state_publisher), timed the same way.
ros::Subscriber subscribeRos1(ros::NodeHandle& nh, const std::string& topic, FrameTimes& times) {
  return nh.subscribe<sensor_msgs::JointState>(
      topic, 1000,
      [&times](const sensor_msgs::JointState::ConstPtr& message) {
        const Clock::time_point when = Clock::now();
        if (message->position.size() < 2) return;
        times.received(FrameTimes::kRos1, message->position[0], message->position[1], when);
      },
      ros::VoidConstPtr(), ros::TransportHints().tcpNoDelay());
}

// --- the programs under test --------------------------------------------------------------------

enum class Program { kNodeRos1Only, kNodeBothGraphs, kDdsDriver };
constexpr std::array<Program, 3> kPrograms{Program::kNodeRos1Only, Program::kNodeBothGraphs,
                                           Program::kDdsDriver};

/// How the report names a program, and the tag in its namespace.
struct ProgramNames {
  const char* name;
  const char* tag;
};
ProgramNames namesOf(Program program) {
  if (program == Program::kNodeRos1Only) return {"driver_node, ~ros2/enabled false", "off"};
  if (program == Program::kNodeBothGraphs) return {"driver_node, ~ros2/enabled true", "on"};
  return {"dds_driver --config", "dds"};
}
const char* nameOf(Program program) { return namesOf(program).name; }
const char* tagOf(Program program) { return namesOf(program).tag; }
bool servesRos1(Program program) { return program != Program::kDdsDriver; }
bool servesRos2(Program program) { return program != Program::kNodeRos1Only; }

struct Context {
  Options options;
  RunPaths paths;
  ros::NodeHandle nh;
  int domain = 0;
  dds_test::Ros2Peer& peer;
};

/// The body's 20 servos, positions decoding back to raw ticks (zero 0, direction +1).
struct BodyLists {
  std::vector<int> ids, zeros, directions;
  std::vector<std::string> names;
  BodyLists() : zeros(kServos, 0), directions(kServos, 1) {
    for (std::size_t i = 0; i < kServos; ++i) {
      ids.push_back(static_cast<int>(i + 1));
      names.push_back("joint_" + std::to_string(i + 1));
    }
  }
};

/// driver_node's parameters: the body alone, the ROS 2 front end on or off in the bench's domain.
ParamList nodeParams(const Context& context, const std::string& port, bool ros2) {
  const BodyLists body;
  return {{"port", port},
          {"reconnect_interval", 0.2},
          {"base/enabled", false},
          {"servo_bus/enabled", false},
          {"body/servo_ids", toXmlRpc(body.ids)},
          {"body/joint_names", toXmlRpc(body.names)},
          {"body/zero_ticks", toXmlRpc(body.zeros)},
          {"body/directions", toXmlRpc(body.directions)},
          {"body/ticks_per_revolution", kTicksPerRevolution},
          {"ros2/enabled", ros2},
          {"ros2/domain_id", context.domain},
          {"ros2/peers", toXmlRpc(std::vector<std::string>{"127.0.0.1"})}};
}

template <typename T>
std::string yamlList(const std::vector<T>& values) {
  std::ostringstream out;
  out << "[";
  for (std::size_t i = 0; i < values.size(); ++i) out << (i ? ", " : "") << values[i];
  out << "]";
  return out.str();
}

/// The same configuration as dds_driver's YAML file (the form `rosparam load` reads).
std::string writeConfig(const Context& context, const std::string& ns, const std::string& port) {
  const BodyLists body;
  const std::string path = context.paths.work_dir + "/" + ns + ".yaml";
  std::ofstream(path) << "port: " << port << "\nreconnect_interval: 0.2\n"
                      << "base: {enabled: false}\nservo_bus: {enabled: false}\n"
                      << "body: {servo_ids: " << yamlList(body.ids)
                      << ", joint_names: " << yamlList(body.names)
                      << ", zero_ticks: " << yamlList(body.zeros)
                      << ", directions: " << yamlList(body.directions)
                      << ", ticks_per_revolution: " << kTicksPerRevolution << "}\n"
                      << "ros2: {domain_id: " << context.domain << ", peers: [127.0.0.1]}\n";
  return path;
}

/// The program of a session, running on `port` in namespace `ns` (node name "driver").
class ProgramUnderTest {
 public:
  ProgramUnderTest(Context& context, Program program, const std::string& ns,
                   const std::string& port) {
    if (program == Program::kDdsDriver) {
      dds_driver_ = std::make_unique<ChildProcess>(
          ns,
          std::vector<std::string>{context.paths.bin_dir + "/dds_driver", "--config",
                                   writeConfig(context, ns, port), "--namespace", "/" + ns,
                                   "--name", "driver"},
          context.paths.log(ns));
    } else {
      node_ = std::make_unique<DriverProcess>(
          context.paths, ns, nodeParams(context, port, program == Program::kNodeBothGraphs));
    }
  }
  pid_t pid() const { return node_ ? node_->pid() : dds_driver_->pid(); }

 private:
  std::unique_ptr<DriverProcess> node_;
  std::unique_ptr<ChildProcess> dds_driver_;
};

/// What one session measured.
struct SessionFigures {
  double cpu = 0;  ///< s/s over the streaming window
  std::size_t written = 0;
  std::vector<double> dds_ms, ros1_ms;
};

/// Writes frames numbered from *seq at `rate_hz` (absolute schedule) until `done` holds, at most
/// `count` of them; the number of frames written.
std::size_t stream(
    FrameTimes& times, sim::PseudoTerminal& pty, double rate_hz, std::size_t count, uint32_t* seq,
    const std::function<bool()>& done = [] { return false; }) {
  const Clock::time_point start = Clock::now();
  std::size_t written = 0;
  for (std::size_t k = 0; k < count && !done() && !stopRequested(); ++k) {
    std::this_thread::sleep_until(start + fromSeconds(k / rate_hz));
    written += times.write(pty, (*seq)++);
  }
  return written;
}

/// Frames at 50 Hz until every subscriber of `program` has received one (the node is up, the
/// DDS endpoints matched, the ROS 1 connection made).
void warmUp(FrameTimes& times, sim::PseudoTerminal& pty, Program program, uint32_t* seq,
            const std::string& log) {
  const auto arrived = [&] {
    return (!servesRos2(program) || !times.latenciesMs(FrameTimes::kDds, 0, *seq).empty()) &&
           (!servesRos1(program) || !times.latenciesMs(FrameTimes::kRos1, 0, *seq).empty());
  };
  stream(times, pty, 50.0, 3000, seq, arrived);  // at most 60 s
  if (!arrived()) throw std::runtime_error("no joint_states for the telemetry written; see " + log);
  sleepUntil(Clock::now() + 1s);
}

SessionFigures runSession(Context& context, Program program, std::size_t round) {
  constexpr uint32_t kWarmUpFrames = 3000;
  const std::string ns = std::string("dds_") + tagOf(program) + "_r" + std::to_string(round);
  sim::PseudoTerminal pty(context.paths.link(ns));
  FrameTimes times(kWarmUpFrames + context.options.frames);
  const DdsJointStates dds(context.peer, "rt/" + ns + "/joint_states", times);
  ros::Subscriber ros1;
  if (servesRos1(program)) ros1 = subscribeRos1(context.nh, "/" + ns + "/joint_states", times);
  const ProgramUnderTest process(context, program, ns, pty.linkPath());
  uint32_t seq = 0;
  warmUp(times, pty, program, &seq, context.paths.log(ns));
  seq = kWarmUpFrames;
  SessionFigures figures;
  const double cpu_start = processCpuSeconds(process.pid());
  const Clock::time_point start = Clock::now();
  figures.written = stream(times, pty, 100.0, context.options.frames, &seq);
  figures.cpu = (processCpuSeconds(process.pid()) - cpu_start) / toSeconds(Clock::now() - start);
  sleepUntil(Clock::now() + 500ms);  // the last frames' messages
  figures.dds_ms = times.latenciesMs(FrameTimes::kDds, kWarmUpFrames, seq);
  figures.ros1_ms = times.latenciesMs(FrameTimes::kRos1, kWarmUpFrames, seq);
  return figures;
}

// --- rounds and the report -------------------------------------------------------------------

/// Every session of one program, pooled.
struct ProgramFigures {
  std::vector<double> cpu;  ///< per round
  std::size_t written = 0;
  std::vector<double> dds_ms, ros1_ms;
  double meanCpu() const {
    double sum = 0;
    for (double value : cpu) sum += value;
    return cpu.empty() ? 0.0 : sum / static_cast<double>(cpu.size());
  }
};

/// Each round runs the three programs back to back, the first one rotating from round to round.
std::array<ProgramFigures, 3> runRounds(Context& context) {
  std::array<ProgramFigures, 3> figures;
  for (std::size_t round = 0; round < context.options.rounds && !stopRequested(); ++round) {
    for (std::size_t k = 0; k < kPrograms.size() && !stopRequested(); ++k) {
      const std::size_t index = (k + round) % kPrograms.size();
      std::cerr << "dds_bench: round " << round + 1 << ", " << nameOf(kPrograms[index]) << "\n";
      const SessionFigures session = runSession(context, kPrograms[index], round);
      ProgramFigures& pooled = figures[index];
      pooled.cpu.push_back(session.cpu);
      pooled.written += session.written;
      pooled.dds_ms.insert(pooled.dds_ms.end(), session.dds_ms.begin(), session.dds_ms.end());
      pooled.ros1_ms.insert(pooled.ros1_ms.end(), session.ros1_ms.begin(), session.ros1_ms.end());
    }
  }
  return figures;
}

/// "p50 / p99 ms (received/written)", or "-" for a graph the program does not serve.
std::string latencyCell(const std::vector<double>& samples_ms, std::size_t written, bool served) {
  if (!served) return "-";
  const Summary summary = summarize(samples_ms);
  return format("%.3f / %.3f (%zu/%zu)", summary.p50, summary.p99, summary.count, written);
}

std::string cpuCell(const ProgramFigures& figures) {
  std::string rounds;
  for (double cpu : figures.cpu) rounds += (rounds.empty() ? "" : ", ") + format("%.4f", cpu);
  return format("%.4f (%s)", figures.meanCpu(), rounds.c_str());
}

std::string report(const Options& options, const std::array<ProgramFigures, 3>& figures) {
  ResultTable table;
  table.section("Telemetry -> joint_states and CPU, ROS 2 front end on and off",
                {"program", "CPU s/s, mean (per round)", "DDS: p50 / p99 ms (received/written)",
                 "ROS 1: p50 / p99 ms (received/written)"});
  for (std::size_t i = 0; i < kPrograms.size(); ++i) {
    const Program program = kPrograms[i];
    table.row({nameOf(program), cpuCell(figures[i]),
               latencyCell(figures[i].dds_ms, figures[i].written, servesRos2(program)),
               latencyCell(figures[i].ros1_ms, figures[i].written, servesRos1(program))});
  }
  const double off = figures[0].meanCpu();
  table.section("Ratios of the mean CPU", {"ratio", "value"});
  table.row({"driver_node, DDS on / DDS off", format("%.2fx", figures[1].meanCpu() / off)});
  table.row({"dds_driver / driver_node DDS off", format("%.2fx", figures[2].meanCpu() / off)});
  table.row({"driver_node, DDS on - DDS off, per telemetry frame",
             format("%.1f us", (figures[1].meanCpu() - off) / 100.0 * 1e6)});
  table.note(
      format("%zu rounds of %zu frames at 100 Hz (20 servos) per program; latency from the "
             "frame's last byte written to the message received, pooled over the rounds.",
             options.rounds, options.frames));
  return table.markdown();
}

std::string header() {
  const std::time_t now = std::time(nullptr);
  char date[64];
  std::strftime(date, sizeof(date), "%Y-%m-%d %H:%M:%S %Z", std::localtime(&now));
  double load[3] = {0, 0, 0};
  ::getloadavg(load, 3);
  return format("# ROS 2 front end (dds_bench)\n\n%s, %ld CPUs, load average %.2f %.2f %.2f.\n",
                date, ::sysconf(_SC_NPROCESSORS_ONLN), load[0], load[1], load[2]);
}

/// A private roscore, the DDS peer in a domain of the bench's own, the rounds; the report.
std::string runWithMaster(int argc, char** argv, const Options& options, const RunPaths& paths) {
  const std::string started = header();
  RosMaster master(paths, findFreeTcpPort());
  ros::init(argc, argv, "dds_bench", ros::init_options::NoSigintHandler);
  std::cerr << "dds_bench: roscore at " << master.uri() << ", logs in " << paths.work_dir << "\n";
  master.waitUntilUp(60s);
  const int domain = dds_test::privateDomainId(180, 40);  // the DDS tests use 120-169
  dds_test::Ros2Peer peer(domain);
  Context context{options, paths, ros::NodeHandle(), domain, peer};
  ros::AsyncSpinner spinner(1);
  spinner.start();
  const std::array<ProgramFigures, 3> figures = runRounds(context);
  spinner.stop();
  return started + report(options, figures);
}

}  // namespace
}  // namespace serial_robot_driver::bench

int main(int argc, char** argv) {
  namespace bench = serial_robot_driver::bench;
  try {
    const bench::Options options = bench::parseOptions(argc, argv);
    bench::installStopHandler();
    bench::RunPaths paths;
    paths.bin_dir = std::filesystem::read_symlink("/proc/self/exe").parent_path();  // beside us
    char work_dir[] = "/tmp/srd_dds_bench_XXXXXX";
    if (::mkdtemp(work_dir) == nullptr) throw std::runtime_error("cannot create a work directory");
    paths.work_dir = work_dir;
    const std::string report = bench::runWithMaster(argc, argv, options, paths);
    std::cout << report;
    if (!options.output.empty()) std::ofstream(options.output) << report;
    return bench::stopRequested() ? 130 : 0;
  } catch (const std::exception& error) {
    std::cerr << "dds_bench: " << error.what() << "\n";
    return 1;
  }
}
