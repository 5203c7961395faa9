// servo_floor: the least a host must do per servo bus transaction, the yardstick of the servo
// section of driver_bench. Benchmark only, never installed.
//
// One thread: write a READ_ANGLE request, block in poll() until the answer's bytes are readable,
// read them, decode the answer, next servo. No second thread, no queue, no busy waiting.
//
// With --publish it is also the least any roscpp node doing servo_states' job must spend: each
// answer becomes one sensor_msgs/JointState on `servo_states` (name servo_<id>, position in rad,
// stamped on arrival), published from that same thread. It waits for its first subscriber before
// the window starts. Without --publish nothing of ROS runs.
//
// usage: servo_floor PORT SERVOS SECONDS [--publish [ROS remapping args...]]
// prints one line: transactions=N seconds=S cpu_s=C lost=L mean_ms=M
#include <fcntl.h>
#include <poll.h>
#include <ros/ros.h>
#include <sensor_msgs/JointState.h>
#include <termios.h>
#include <time.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "serial_robot_driver/devices/servo_bus/servo_bus_codec.h"

namespace servo_bus = serial_robot_driver::devices::servo_bus;
using Clock = std::chrono::steady_clock;

namespace {

/// A lost answer (a fault, a restart) costs this wait; robot_sim never loses one unless told to.
constexpr int kAnswerTimeoutMs = 50;
constexpr std::size_t kAngleAnswerSize = servo_bus::kOverhead + 3;  // id, i16 angle

double processCpuSeconds() {
  timespec cpu{};
  ::clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &cpu);
  return static_cast<double>(cpu.tv_sec) + static_cast<double>(cpu.tv_nsec) * 1e-9;
}

/// Reads one answer of `size` bytes (blocking); false after a timeout or a bad answer.
bool readAnswer(int fd, std::size_t size, servo_bus::Packet* packet) {
  uint8_t buffer[servo_bus::kMaxFrameSize];
  std::size_t have = 0;
  while (have < size) {
    pollfd pfd{fd, POLLIN, 0};
    if (::poll(&pfd, 1, kAnswerTimeoutMs) <= 0) return false;
    const ssize_t n = ::read(fd, buffer + have, size - have);
    if (n <= 0) return false;
    have += static_cast<std::size_t>(n);
  }
  const auto decoded = servo_bus::decodeResponse(buffer, have);
  if (!decoded.ok()) return false;
  *packet = *decoded;
  return true;
}

/// The port raw; -1 (said on stderr) when it cannot be opened.
int openRawPort(const char* path) {
  const int fd = ::open(path, O_RDWR | O_NOCTTY);
  if (fd < 0) {
    std::perror("servo_floor: open");
    return -1;
  }
  termios tio{};
  ::tcgetattr(fd, &tio);
  ::cfmakeraw(&tio);
  ::tcsetattr(fd, TCSANOW, &tio);
  return fd;
}

/// What the window did.
struct Totals {
  uint64_t transactions = 0;
  uint64_t lost = 0;
  long angle_sum = 0;  // keeps the decode from being optimised away
};

/// One READ_ANGLE request and its answer (published as `name` when `states` is given).
void transact(int fd, const std::vector<uint8_t>& request, const std::string& name,
              ros::Publisher* states, Totals* totals) {
  servo_bus::Packet answer;
  if (::write(fd, request.data(), request.size()) != static_cast<ssize_t>(request.size()) ||
      !readAnswer(fd, kAngleAnswerSize, &answer)) {
    ++totals->lost;
    ::tcflush(fd, TCIFLUSH);  // a late answer must not pass for the next one
    return;
  }
  const auto angle = servo_bus::decodeAngleAnswer(answer);
  if (angle.ok()) {
    totals->angle_sum += angle->angle_decidegrees;
    if (states != nullptr) {
      sensor_msgs::JointState message;
      message.header.stamp = ros::Time::now();
      message.name.push_back(name);
      message.position.push_back(angle->angle_decidegrees * (M_PI / 1800.0));
      states->publish(message);
    }
  }
  ++totals->transactions;
}

/// Publishing: advertises servo_states and waits for its first subscriber.
ros::Publisher advertiseStates(int argc, char** argv, std::unique_ptr<ros::NodeHandle>* nh) {
  ros::init(argc, argv, "servo_floor");
  *nh = std::make_unique<ros::NodeHandle>();
  ros::Publisher states = (*nh)->advertise<sensor_msgs::JointState>("servo_states", 10);
  while (ros::ok() && states.getNumSubscribers() == 0) ros::Duration(0.01).sleep();
  return states;
}

}  // namespace

int main(int argc, char** argv) {
  const bool publish = argc >= 5 && std::strcmp(argv[4], "--publish") == 0;
  if (argc < 4 || (argc > 4 && !publish)) {
    std::fprintf(stderr, "usage: servo_floor PORT SERVOS SECONDS [--publish [ROS args]]\n");
    return 2;
  }
  std::unique_ptr<ros::NodeHandle> nh;
  ros::Publisher states;
  if (publish) states = advertiseStates(argc, argv, &nh);
  const int fd = openRawPort(argv[1]);
  if (fd < 0) return 1;
  const int servos = std::atoi(argv[2]);
  const auto window = std::chrono::duration<double>(std::atof(argv[3]));

  std::vector<std::vector<uint8_t>> requests;
  std::vector<std::string> names;
  for (int id = 0; id < servos; ++id) {
    requests.push_back(servo_bus::encodeReadAngle(id));
    names.push_back("servo_" + std::to_string(id));
  }

  Totals totals;
  const double cpu_start = processCpuSeconds();
  const Clock::time_point start = Clock::now();
  Clock::time_point now = start;
  for (std::size_t next = 0; now - start < window; next = (next + 1) % requests.size()) {
    transact(fd, requests[next], names[next], publish ? &states : nullptr, &totals);
    now = Clock::now();
  }
  const double seconds = std::chrono::duration<double>(now - start).count();
  const double cpu = processCpuSeconds() - cpu_start;
  const uint64_t transactions = totals.transactions;
  std::printf("transactions=%llu seconds=%.3f cpu_s=%.4f lost=%llu mean_ms=%.4f checksum=%ld\n",
              static_cast<unsigned long long>(transactions), seconds, cpu,
              static_cast<unsigned long long>(totals.lost),
              transactions ? seconds * 1000.0 / static_cast<double>(transactions) : 0.0,
              totals.angle_sum);
  return 0;
}
