// TransportTest: SerialPort and PseudoTerminal over real pseudo-terminals (never a real /dev/tty*),
// a private directory per test for symlinks, and byte helpers.
#pragma once

#include <fcntl.h>
#include <gtest/gtest.h>
#include <poll.h>
#include <signal.h>
#include <stdlib.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <termios.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "serial_robot_driver/sim/pseudo_terminal.h"
#include "serial_robot_driver/transport/serial_port.h"
#include "support/golden_frames.h"

namespace serial_robot_driver::transport::transport_test {

using Bytes = std::vector<uint8_t>;
using sim::PseudoTerminal;

constexpr int kPatientTimeoutMs = 2000;  // generous: only the failure case waits this long

inline Bytes allByteValues() {
  Bytes bytes(256);
  for (int value = 0; value < 256; ++value) bytes[value] = static_cast<uint8_t>(value);
  return bytes;
}

// Reads until `count` bytes arrived or a whole patient timeout passed without any byte.
template <typename Reader>
Bytes readExactly(Reader& reader, std::size_t count) {
  Bytes received;
  uint8_t chunk[512];
  while (received.size() < count) {
    const std::size_t got =
        reader.read(chunk, std::min(sizeof(chunk), count - received.size()), kPatientTimeoutMs);
    if (got == 0) break;
    received.insert(received.end(), chunk, chunk + got);
  }
  return received;
}

inline void writeBytes(ByteStream& stream, const Bytes& bytes) {
  stream.write(bytes.data(), bytes.size());
}
inline void writeBytes(PseudoTerminal& pty, const Bytes& bytes) {
  pty.write(bytes.data(), bytes.size());
}

inline TransportErrorKind errorKindOf(const std::function<void()>& action) {
  try {
    action();
  } catch (const TransportError& error) {
    return error.kind();
  }
  ADD_FAILURE() << "no TransportError thrown";
  return TransportErrorKind::kIoError;
}

// A private directory per test for symlinks, so parallel test runs never collide.
class TransportTest : public ::testing::Test {
 protected:
  void SetUp() override {
    char pattern[] = "/tmp/srd_transport_XXXXXX";
    ASSERT_NE(::mkdtemp(pattern), nullptr);
    dir_ = pattern;
  }
  void TearDown() override {
    ::unlink(linkPath().c_str());
    ::unlink((dir_ + "/regular_file").c_str());
    ::rmdir(dir_.c_str());
  }
  std::string linkPath() const { return dir_ + "/robot_port"; }

  std::string dir_;
};

}  // namespace serial_robot_driver::transport::transport_test
