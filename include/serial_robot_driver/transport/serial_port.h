// POSIX serial port (termios): raw 8N1 at the configured baud. Reads and writes are independent
// (one reader thread, writers serialized by the caller), as in wjwwood/serial.
#pragma once

#include <optional>
#include <string>

#include "serial_robot_driver/transport/byte_stream.h"

namespace serial_robot_driver::transport {

struct SerialPortOptions {
  std::string path;
  unsigned baud = 115200;
};

class SerialPort : public ByteStream {
 public:
  explicit SerialPort(SerialPortOptions options);
  ~SerialPort() override;
  SerialPort(const SerialPort&) = delete;
  SerialPort& operator=(const SerialPort&) = delete;

  /// Opens and configures the port. Requests ASYNC_LOW_LATENCY where the driver supports it; a pty
  /// or a driver that refuses the ioctl is "not supported", not an error.
  void open() override;
  void close() override;
  bool isOpen() const override { return fd_ >= 0; }
  std::size_t read(uint8_t* buffer, std::size_t capacity, int timeout_ms) override;
  void write(const uint8_t* data, std::size_t size) override;
  std::string name() const override { return options_.path; }

  bool lowLatencyEnabled() const { return low_latency_; }
  /// The USB-serial adapter's latency_timer in ms (sysfs), when the port is such an adapter.
  std::optional<int> latencyTimerMs() const { return latency_timer_ms_; }

 private:
  SerialPortOptions options_;
  int fd_ = -1;
  bool low_latency_ = false;
  std::optional<int> latency_timer_ms_;
};

/// termios speed constant for a baud rate; nullopt when unsupported.
std::optional<unsigned> baudToSpeed(unsigned baud);

/// Reads /sys/bus/usb-serial/devices/<ttyX>/latency_timer for a device path (symlinks resolved).
std::optional<int> readLatencyTimerMs(const std::string& device_path);

}  // namespace serial_robot_driver::transport
