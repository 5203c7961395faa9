// SerialPort on a pty: opening, bytes both ways untranslated, raw 8N1, timeouts and wakeRead.
#include <gtest/gtest.h>

#include "support/transport_fixture.h"

namespace serial_robot_driver::transport {
namespace {

using namespace transport_test;  // NOLINT: the shared fixture

TEST_F(TransportTest, OpensBySlavePathAndExchangesBytesBothWays) {
  PseudoTerminal pty;
  SerialPort port({pty.slavePath(), 115200});
  port.open();
  ASSERT_TRUE(port.isOpen());

  const Bytes& to_robot = golden::base::kResetSeq2;
  writeBytes(port, to_robot);
  EXPECT_EQ(readExactly(pty, to_robot.size()), to_robot);

  const Bytes from_robot = {0xFF, 0xFF, 0xFD, 0x00, 0x01};
  writeBytes(pty, from_robot);
  EXPECT_EQ(readExactly(port, from_robot.size()), from_robot);
}

TEST_F(TransportTest, OpensBySymlink) {
  PseudoTerminal pty(linkPath());
  EXPECT_EQ(pty.linkPath(), linkPath());
  char target[256] = {};
  ASSERT_GT(::readlink(linkPath().c_str(), target, sizeof(target) - 1), 0);
  EXPECT_EQ(std::string(target), pty.slavePath());

  SerialPort port({linkPath(), 115200});
  port.open();
  EXPECT_EQ(port.name(), linkPath());
  const Bytes bytes = {1, 2, 3};
  writeBytes(pty, bytes);
  EXPECT_EQ(readExactly(port, bytes.size()), bytes);
}

TEST_F(TransportTest, AllByteValuesPassUntranslatedInBothDirections) {
  // Raw mode: no CR/LF mapping, no XON/XOFF, no special characters, no echo.
  PseudoTerminal pty;
  SerialPort port({pty.slavePath(), 115200});
  port.open();
  const Bytes bytes = allByteValues();

  writeBytes(pty, bytes);
  EXPECT_EQ(readExactly(port, bytes.size()), bytes);

  writeBytes(port, bytes);
  EXPECT_EQ(readExactly(pty, bytes.size()), bytes);

  // Nothing echoed back to either side.
  uint8_t extra[16];
  EXPECT_EQ(pty.read(extra, sizeof(extra), 50), 0u);
  EXPECT_EQ(port.read(extra, sizeof(extra), 50), 0u);
}

TEST_F(TransportTest, PseudoTerminalIsRawBeforeAnyClientConfiguresIt) {
  PseudoTerminal pty;
  const int slave = ::open(pty.slavePath().c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK);
  ASSERT_GE(slave, 0);
  termios settings{};
  ASSERT_EQ(::tcgetattr(slave, &settings), 0);
  ::close(slave);
  EXPECT_EQ(settings.c_lflag & (ECHO | ICANON | ISIG), 0u);
  EXPECT_EQ(settings.c_iflag & (ICRNL | INLCR | IXON), 0u);
  EXPECT_EQ(settings.c_oflag & OPOST, 0u);
}

TEST_F(TransportTest, SerialPortConfiguresACookedTerminalAsRaw8N1) {
  PseudoTerminal pty;
  // Cook the terminal first, as a previous program might have left it.
  const int slave = ::open(pty.slavePath().c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK);
  ASSERT_GE(slave, 0);
  termios cooked{};
  ASSERT_EQ(::tcgetattr(slave, &cooked), 0);
  cooked.c_lflag |= ECHO | ICANON | ISIG;
  cooked.c_iflag |= ICRNL | IXON;
  cooked.c_oflag |= OPOST | ONLCR;
  cooked.c_cflag |= PARENB | CSTOPB;
  ASSERT_EQ(::tcsetattr(slave, TCSANOW, &cooked), 0);

  SerialPort port({pty.slavePath(), 57600});
  port.open();
  termios settings{};
  ASSERT_EQ(::tcgetattr(slave, &settings), 0);
  ::close(slave);
  EXPECT_EQ(settings.c_lflag & (ECHO | ICANON | ISIG), 0u);
  EXPECT_EQ(settings.c_iflag & (ICRNL | IXON | IXOFF), 0u);
  EXPECT_EQ(settings.c_oflag & OPOST, 0u);
  EXPECT_EQ(settings.c_cflag & (PARENB | CSTOPB | CRTSCTS), 0u);
  EXPECT_EQ(settings.c_cflag & CSIZE, static_cast<tcflag_t>(CS8));
  // Reads never block (O_NONBLOCK); with VMIN 1 one that finds nothing is EAGAIN, not a 0 that
  // would read as the end of a hung-up tty.
  EXPECT_EQ(settings.c_cc[VMIN], 1);
  EXPECT_EQ(settings.c_cc[VTIME], 0);
  EXPECT_EQ(::cfgetospeed(&settings), static_cast<speed_t>(B57600));
  EXPECT_EQ(::cfgetispeed(&settings), static_cast<speed_t>(B57600));

  // And the bytes that cooked mode would mangle (CR, LF, XON, XOFF, ^C, ^D) pass intact.
  const Bytes tricky = {'\r', '\n', 0x11, 0x13, 0x03, 0x04, 0x7F, 0x00};
  writeBytes(pty, tricky);
  EXPECT_EQ(readExactly(port, tricky.size()), tricky);
  writeBytes(port, tricky);
  EXPECT_EQ(readExactly(pty, tricky.size()), tricky);
}

TEST_F(TransportTest, ReadTimeoutReturnsZero) {
  PseudoTerminal pty;
  SerialPort port({pty.slavePath(), 115200});
  port.open();
  uint8_t buffer[8];
  EXPECT_EQ(port.read(buffer, sizeof(buffer), 20), 0u);
  EXPECT_EQ(port.read(buffer, sizeof(buffer), 0), 0u);
  EXPECT_EQ(pty.read(buffer, sizeof(buffer), 20), 0u);
}

// The link's reader sleeps in read() with no periodic time-out; stop() and a failed write wake it.
// A wake-up given before the read is kept for it, and bytes already waiting stay for the next read.
TEST_F(TransportTest, WakeReadEndsTheNextReadWithZeroAndKeepsPendingBytes) {
  PseudoTerminal pty;
  SerialPort port({pty.slavePath(), 115200});
  port.open();
  ASSERT_TRUE(port.wakeable());

  const Bytes from_robot = {0xFF, 0xFF, 0xFD, 0x00, 0x01};
  writeBytes(pty, from_robot);
  port.wakeRead();
  uint8_t buffer[8];
  EXPECT_EQ(port.read(buffer, sizeof(buffer), kPatientTimeoutMs), 0u);
  EXPECT_EQ(readExactly(port, from_robot.size()), from_robot);
}

// The reader is told of each arrival once: bytes a read had no room for are read next, though no
// new byte comes to announce them.
TEST_F(TransportTest, BytesASmallReadLeftAreReadNextWithoutNewArrivals) {
  PseudoTerminal pty;
  SerialPort port({pty.slavePath(), 115200});
  port.open();
  const Bytes from_robot = {0x55, 0xAA, 0x01, 0x02, 0x03, 0x04};
  writeBytes(pty, from_robot);
  Bytes received = readExactly(port, 2);  // whatever had come, two at a time
  while (received.size() < from_robot.size()) {
    const Bytes more = readExactly(port, 2);
    ASSERT_EQ(more.size(), 2u);
    received.insert(received.end(), more.begin(), more.end());
  }
  EXPECT_EQ(received, from_robot);
  // The last read filled its buffer too: the one after it looks, finds nothing, and says so.
  uint8_t buffer[2];
  EXPECT_EQ(port.read(buffer, sizeof(buffer), 0), 0u);
}

// A hang-up after a read that left bytes behind (which a pty's hang-up discards) is the loss it is,
// not a wait for more.
TEST_F(TransportTest, AHangUpAfterAReadThatLeftBytesIsALoss) {
  PseudoTerminal pty;
  SerialPort port({pty.slavePath(), 115200});
  port.open();
  writeBytes(pty, Bytes{0x01, 0x02, 0x03, 0x04});
  EXPECT_EQ(readExactly(port, 1), Bytes{0x01});
  pty.close();
  uint8_t buffer[8];
  EXPECT_EQ(errorKindOf([&] {
              for (int attempt = 0; attempt < 4; ++attempt)
                port.read(buffer, sizeof(buffer), kPatientTimeoutMs);
            }),
            TransportErrorKind::kDisconnected);
}

}  // namespace
}  // namespace serial_robot_driver::transport
