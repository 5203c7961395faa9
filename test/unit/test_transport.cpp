// SerialPort and PseudoTerminal over real pseudo-terminals (never a real /dev/tty*).
#include <fcntl.h>
#include <signal.h>
#include <gtest/gtest.h>
#include <poll.h>
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

namespace serial_robot_driver::transport {
namespace {

using Bytes = std::vector<uint8_t>;
using sim::PseudoTerminal;

constexpr int kPatientTimeoutMs = 2000;  // generous: only the failure case waits this long

Bytes allByteValues() {
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

void writeBytes(ByteStream& stream, const Bytes& bytes) {
  stream.write(bytes.data(), bytes.size());
}
void writeBytes(PseudoTerminal& pty, const Bytes& bytes) { pty.write(bytes.data(), bytes.size()); }

TransportErrorKind errorKindOf(const std::function<void()>& action) {
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
  EXPECT_EQ(settings.c_cc[VMIN], 0);
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

TEST(TransportBaud, StandardRatesMapToTermiosConstants) {
  EXPECT_EQ(baudToSpeed(9600), std::optional<unsigned>(B9600));
  EXPECT_EQ(baudToSpeed(115200), std::optional<unsigned>(B115200));
  EXPECT_EQ(baudToSpeed(1000000), std::optional<unsigned>(B1000000));
  EXPECT_EQ(baudToSpeed(4000000), std::optional<unsigned>(B4000000));
}

// The rates the servos offer (their baudrate option 0x01..0x07), written out from the datasheet.
const std::vector<unsigned> kServoRates = {9600, 19200, 38400, 57600, 115200, 250000, 500000};

TEST(TransportBaud, TheTableHoldsTheServoRatesAndTheLargeStandardOnes) {
  for (unsigned rate : kServoRates) EXPECT_TRUE(isSupportedBaud(rate)) << rate;
  for (unsigned rate : {1152000u, 2500000u, 3500000u, 4000000u}) EXPECT_TRUE(isSupportedBaud(rate)) << rate;
  for (unsigned rate : {0u, 12345u, 115201u, 5000000u}) EXPECT_FALSE(isSupportedBaud(rate)) << rate;
  EXPECT_TRUE(std::is_sorted(supportedBaudRates().begin(), supportedBaudRates().end()));
}

TEST(TransportBaud, RateWithoutATermiosConstantIsSetByNumber) {
  EXPECT_FALSE(baudToSpeed(250000).has_value());  // glibc has no B250000
  EXPECT_TRUE(isSupportedBaud(250000));
}

// Every rate of the table opens a pty and reads back as set. A pty stores the speed without
// using it; should the kernel refuse to report it (termios2 not supported), that rate's speed is
// not checked, but the port must still have opened.
TEST_F(TransportTest, EveryTableRateOpensAndReadsBack) {
  PseudoTerminal pty;
  std::size_t verified = 0;
  for (unsigned rate : supportedBaudRates()) {
    SerialPort port({pty.slavePath(), rate});
    ASSERT_NO_THROW(port.open()) << rate;
    const int probe = ::open(pty.slavePath().c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK);
    ASSERT_GE(probe, 0);
    const std::optional<unsigned> read_back = readBaudRate(probe);
    ::close(probe);
    if (!read_back) continue;  // "not supported" by this device: nothing to verify
    EXPECT_EQ(*read_back, rate);
    ++verified;
    // And the bytes still flow at that setting.
    const Bytes bytes = {0xFF, static_cast<uint8_t>(rate & 0xFF)};
    writeBytes(pty, bytes);
    EXPECT_EQ(readExactly(port, bytes.size()), bytes) << rate;
  }
  RecordProperty("rates_read_back", static_cast<int>(verified));
#ifdef __linux__
  EXPECT_EQ(verified, supportedBaudRates().size()) << "a Linux pty reports its speed";
#endif
}

TEST_F(TransportTest, UnsupportedRateIsRefusedNamingTheTable) {
  PseudoTerminal pty;
  SerialPort port({pty.slavePath(), 12345});
  try {
    port.open();
    FAIL() << "opened at 12345 baud";
  } catch (const TransportError& error) {
    EXPECT_EQ(error.kind(), TransportErrorKind::kConfigureFailed);
    EXPECT_NE(std::string(error.what()).find("250000"), std::string::npos) << error.what();
  }
}

TEST(TransportBaud, NonStandardRatesAreUnsupported) {
  EXPECT_FALSE(baudToSpeed(0).has_value());
  EXPECT_FALSE(baudToSpeed(12345).has_value());
  EXPECT_FALSE(baudToSpeed(115201).has_value());
  EXPECT_FALSE(baudToSpeed(5000000).has_value());
}

std::string openFailure(SerialPort& port) {
  try {
    port.open();
  } catch (const TransportError& error) {
    EXPECT_EQ(error.kind(), TransportErrorKind::kOpenFailed);
    return error.what();
  }
  return "opened";
}

// Issue 15: a port is taken exclusively; a second opener is told "port busy" and, once the first
// lets go, gets the port.
TEST_F(TransportTest, SecondOpenerOfAPortIsToldItIsBusy) {
  PseudoTerminal pty(linkPath());
  SerialPort first({linkPath(), 115200});
  first.open();
  SerialPort second({linkPath(), 115200});
  const std::string failure = openFailure(second);
  EXPECT_NE(failure.find("port busy: " + linkPath()), std::string::npos) << failure;
  EXPECT_FALSE(second.isOpen());

  // The first keeps working.
  const Bytes bytes = {7, 8, 9};
  writeBytes(pty, bytes);
  EXPECT_EQ(readExactly(first, bytes.size()), bytes);

  first.close();
  second.open();
  EXPECT_TRUE(second.isOpen());
}

// The holder's pid comes from /proc/locks when another process holds the lock.
TEST_F(TransportTest, PortBusyNamesTheProcessHoldingTheLock) {
  PseudoTerminal pty(linkPath());
  int ready[2];
  ASSERT_EQ(::pipe(ready), 0);
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    SerialPort holder({linkPath(), 115200});
    try {
      holder.open();
    } catch (...) {
      ::_exit(1);
    }
    const char ok = 1;
    (void)!::write(ready[1], &ok, 1);
    ::pause();
    ::_exit(0);
  }
  char ok = 0;
  ASSERT_EQ(::read(ready[0], &ok, 1), 1);
  ::close(ready[0]);
  ::close(ready[1]);

  SerialPort second({linkPath(), 115200});
  const std::string failure = openFailure(second);
  EXPECT_NE(failure.find("locked by another process (pid " + std::to_string(child)), std::string::npos)
      << failure;
  const std::optional<PortHolder> holder = findPortHolder(linkPath());
  ASSERT_TRUE(holder.has_value());
  EXPECT_EQ(holder->pid, child);

  ::kill(child, SIGKILL);
  ::waitpid(child, nullptr, 0);
  EXPECT_FALSE(findPortHolder(linkPath()).has_value());
  second.open();
  EXPECT_TRUE(second.isOpen());
}

}  // namespace
}  // namespace serial_robot_driver::transport
