// SerialPort's errors, disconnects and reopening, the pty's symlink, latency and concurrent use.
#include <gtest/gtest.h>

#include "support/transport_fixture.h"

namespace serial_robot_driver::transport {
namespace {

using namespace transport_test;  // NOLINT: the shared fixture

TEST_F(TransportTest, MissingPathThrowsOpenFailedNamingPathAndReason) {
  const std::string path = dir_ + "/no_such_port";
  SerialPort port({path, 115200});
  try {
    port.open();
    FAIL() << "open of a missing path succeeded";
  } catch (const TransportError& error) {
    EXPECT_EQ(error.kind(), TransportErrorKind::kOpenFailed);
    EXPECT_NE(std::string(error.what()).find(path), std::string::npos) << error.what();
    EXPECT_NE(std::string(error.what()).find(std::strerror(ENOENT)), std::string::npos)
        << error.what();
  }
  EXPECT_FALSE(port.isOpen());
}

TEST_F(TransportTest, UnsupportedBaudThrowsConfigureFailedNamingTheBaud) {
  PseudoTerminal pty;
  SerialPort port({pty.slavePath(), 12345});
  try {
    port.open();
    FAIL() << "open with baud 12345 succeeded";
  } catch (const TransportError& error) {
    EXPECT_EQ(error.kind(), TransportErrorKind::kConfigureFailed);
    EXPECT_NE(std::string(error.what()).find("12345"), std::string::npos) << error.what();
  }
  EXPECT_FALSE(port.isOpen());
}

TEST_F(TransportTest, PathThatIsNoTerminalThrowsConfigureFailed) {
  const std::string path = dir_ + "/regular_file";
  std::ofstream(path) << "not a tty";
  SerialPort port({path, 115200});
  EXPECT_EQ(errorKindOf([&] { port.open(); }), TransportErrorKind::kConfigureFailed);
  EXPECT_FALSE(port.isOpen());
}

TEST_F(TransportTest, ClosingThePtyMakesReadThrowDisconnected) {
  PseudoTerminal pty;
  SerialPort port({pty.slavePath(), 115200});
  port.open();
  pty.close();
  uint8_t buffer[8];
  EXPECT_EQ(errorKindOf([&] { port.read(buffer, sizeof(buffer), kPatientTimeoutMs); }),
            TransportErrorKind::kDisconnected);
}

TEST_F(TransportTest, WriteAfterThePtyClosedThrowsDisconnected) {
  PseudoTerminal pty;
  SerialPort port({pty.slavePath(), 115200});
  port.open();
  pty.close();
  const Bytes bytes = {0x55, 0xAA};
  EXPECT_EQ(errorKindOf([&] { writeBytes(port, bytes); }), TransportErrorKind::kDisconnected);
}

TEST_F(TransportTest, ReopensAfterANewPtyAppearsAtTheSameSymlink) {
  auto first = std::make_unique<PseudoTerminal>(linkPath());
  SerialPort port({linkPath(), 115200});
  port.open();
  first->close();
  uint8_t buffer[8];
  EXPECT_EQ(errorKindOf([&] { port.read(buffer, sizeof(buffer), kPatientTimeoutMs); }),
            TransportErrorKind::kDisconnected);

  PseudoTerminal second(linkPath());
  port.close();
  port.open();
  const Bytes bytes = {0xDE, 0xAD, 0xBE, 0xEF};
  writeBytes(second, bytes);
  EXPECT_EQ(readExactly(port, bytes.size()), bytes);
  writeBytes(port, bytes);
  EXPECT_EQ(readExactly(second, bytes.size()), bytes);
}

TEST_F(TransportTest, OpenDropsStaleBytes) {
  PseudoTerminal pty;
  writeBytes(pty, Bytes{'o', 'l', 'd'});
  {
    // Wait until the stale bytes really sit in the slave's input queue (without consuming them).
    const int observer = ::open(pty.slavePath().c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK);
    ASSERT_GE(observer, 0);
    pollfd waiter{observer, POLLIN, 0};
    ASSERT_EQ(::poll(&waiter, 1, kPatientTimeoutMs), 1);
    ::close(observer);
  }
  SerialPort port({pty.slavePath(), 115200});
  port.open();
  const Bytes fresh = {'n', 'e', 'w'};
  writeBytes(pty, fresh);
  EXPECT_EQ(readExactly(port, fresh.size()), fresh);
}

TEST_F(TransportTest, StaleSymlinkIsReplacedAndRemovedOnClose) {
  ASSERT_EQ(::symlink("/dev/pts/does_not_exist", linkPath().c_str()), 0);
  PseudoTerminal pty(linkPath());
  char target[256] = {};
  ASSERT_GT(::readlink(linkPath().c_str(), target, sizeof(target) - 1), 0);
  EXPECT_EQ(std::string(target), pty.slavePath());
  pty.close();
  struct stat info {};
  EXPECT_NE(::lstat(linkPath().c_str(), &info), 0);
}

TEST_F(TransportTest, ClosingAnOldPtyLeavesANewerPtysLinkAlone) {
  PseudoTerminal old_pty(linkPath());
  PseudoTerminal new_pty(linkPath());
  old_pty.close();
  char target[256] = {};
  ASSERT_GT(::readlink(linkPath().c_str(), target, sizeof(target) - 1), 0);
  EXPECT_EQ(std::string(target), new_pty.slavePath());
}

TEST_F(TransportTest, RegularFileAtTheLinkPathIsNeverReplaced) {
  const std::string path = dir_ + "/regular_file";
  std::ofstream(path) << "keep me";
  EXPECT_EQ(errorKindOf([&] { PseudoTerminal pty(path); }), TransportErrorKind::kOpenFailed);
  std::ifstream file(path);
  std::string content;
  std::getline(file, content);
  EXPECT_EQ(content, "keep me");
}

TEST_F(TransportTest, MasterSeesNoHangUpWhileNoClientIsAttached) {
  PseudoTerminal pty;
  uint8_t buffer[8];
  EXPECT_EQ(pty.read(buffer, sizeof(buffer), 20), 0u);  // never attached
  {
    SerialPort port({pty.slavePath(), 115200});
    port.open();
  }  // detached again
  EXPECT_EQ(pty.read(buffer, sizeof(buffer), 20), 0u);
  EXPECT_TRUE(pty.isOpen());
}

TEST_F(TransportTest, LowLatencyRequestOnAPtyIsNotAnError) {
  PseudoTerminal pty;
  SerialPort port({pty.slavePath(), 115200});
  EXPECT_NO_THROW(port.open());
  EXPECT_TRUE(port.isOpen());
  EXPECT_FALSE(port.info().low_latency);  // ptys do not implement TIOCGSERIAL
  EXPECT_FALSE(port.info().latency_timer_ms.has_value());
}

TEST_F(TransportTest, LatencyTimerOfAPtyOrMissingPathIsUnknown) {
  PseudoTerminal pty(linkPath());
  EXPECT_FALSE(readLatencyTimerMs(pty.slavePath()).has_value());
  EXPECT_FALSE(readLatencyTimerMs(linkPath()).has_value());
  EXPECT_FALSE(readLatencyTimerMs(dir_ + "/no_such_port").has_value());
}

TEST_F(TransportTest, CloseIsIdempotentAndAClosedPortReportsDisconnected) {
  PseudoTerminal pty;
  SerialPort port({pty.slavePath(), 115200});
  port.open();
  port.close();
  port.close();
  EXPECT_FALSE(port.isOpen());
  uint8_t buffer[4] = {};
  EXPECT_EQ(errorKindOf([&] { port.read(buffer, sizeof(buffer), 0); }),
            TransportErrorKind::kDisconnected);
  EXPECT_EQ(errorKindOf([&] { port.write(buffer, sizeof(buffer)); }),
            TransportErrorKind::kDisconnected);
  pty.close();
  pty.close();
  EXPECT_FALSE(pty.isOpen());
}

TEST_F(TransportTest, OneThreadReadsWhileAnotherWrites) {
  PseudoTerminal pty;
  SerialPort port({pty.slavePath(), 115200});
  port.open();
  // Small enough to fit the pty buffers, so no writer ever waits on a slow reader.
  Bytes to_robot;
  Bytes from_robot;
  for (int i = 0; i < 16; ++i) {
    const Bytes block = allByteValues();
    to_robot.insert(to_robot.end(), block.begin(), block.end());
    from_robot.insert(from_robot.end(), block.rbegin(), block.rend());
  }

  Bytes port_received;
  std::thread port_reader([&] { port_received = readExactly(port, from_robot.size()); });
  std::thread port_writer([&] {
    for (std::size_t offset = 0; offset < to_robot.size(); offset += 64) {
      port.write(to_robot.data() + offset, 64);
    }
  });
  writeBytes(pty, from_robot);
  const Bytes pty_received = readExactly(pty, to_robot.size());
  port_writer.join();
  port_reader.join();

  EXPECT_EQ(pty_received, to_robot);
  EXPECT_EQ(port_received, from_robot);
}

}  // namespace
}  // namespace serial_robot_driver::transport
