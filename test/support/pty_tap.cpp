// ROS-free tap between the node under test and a device played elsewhere (see the header).
#include "support/pty_tap.h"

#include <fcntl.h>
#include <poll.h>
#include <termios.h>
#include <unistd.h>

#include <cerrno>
#include <stdexcept>

#include "serial_robot_driver/transport/byte_stream.h"
#include "support/test_helpers.h"

namespace test_support {

namespace protocol = serial_robot_driver::protocol;
namespace transport = serial_robot_driver::transport;

PtyTap::PtyTap(const std::string& node_link, const std::string& device_path,
               const protocol::FramerConfig& framer)
    : node_pty_(node_link) {
  device_fd_ = ::open(device_path.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK);
  if (device_fd_ < 0) throw std::runtime_error("cannot open " + device_path);
  termios tio{};
  if (::tcgetattr(device_fd_, &tio) == 0) {
    ::cfmakeraw(&tio);
    ::tcsetattr(device_fd_, TCSANOW, &tio);
  }
  device_thread_ = std::thread([this] { forwardFromDevice(); });
  reader_ = std::make_unique<PtyFrameReader>(
      node_pty_, framer,
      [this](protocol::FrameFamily family, const uint8_t* data, std::size_t size,
             Clock::time_point arrival) {
        std::lock_guard<std::mutex> lock(mutex_);
        frames_.push_back({family, Bytes(data, data + size), arrival});
      },
      [this](const uint8_t* data, std::size_t size) {
        // Node -> device, as read (the device's side never blocks for long: the simulator reads).
        std::size_t done = 0;
        while (done < size && !stopping_) {
          const ssize_t n = ::write(device_fd_, data + done, size - done);
          if (n > 0) {
            done += static_cast<std::size_t>(n);
          } else if (n < 0 && errno != EAGAIN && errno != EINTR) {
            return;
          } else {
            pollfd pfd{device_fd_, POLLOUT, 0};
            ::poll(&pfd, 1, 20);
          }
        }
      });
}

PtyTap::~PtyTap() {
  stopping_ = true;
  reader_.reset();
  device_thread_.join();
  ::close(device_fd_);
}

void PtyTap::forwardFromDevice() {
  uint8_t buffer[4096];
  while (!stopping_) {
    pollfd pfd{device_fd_, POLLIN, 0};
    if (::poll(&pfd, 1, 20) <= 0) continue;
    const ssize_t n = ::read(device_fd_, buffer, sizeof(buffer));
    if (n <= 0) {
      sleepSeconds(0.02);
      continue;
    }
    try {
      node_pty_.write(buffer, static_cast<std::size_t>(n));
    } catch (const transport::TransportError&) {
      sleepSeconds(0.02);  // the node is not attached yet: the bytes are lost, as on a real line
    }
  }
}

std::vector<PtyTap::Frame> PtyTap::frames() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return frames_;
}

std::size_t PtyTap::frameCount() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return frames_.size();
}

bool PtyTap::waitForFrames(const std::function<bool(const std::vector<Frame>&)>& done,
                           double timeout_s) const {
  return waitFor([&] { return done(frames()); }, timeout_s);
}

}  // namespace test_support
