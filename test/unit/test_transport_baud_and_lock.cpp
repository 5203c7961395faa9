// The baud-rate table, and the lock that tells a second opener that the port is busy.
#include <gtest/gtest.h>

#include "support/transport_fixture.h"

namespace serial_robot_driver::transport {
namespace {

using namespace transport_test;  // NOLINT: the shared fixture

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
  for (unsigned rate : {1152000u, 2500000u, 3500000u, 4000000u})
    EXPECT_TRUE(isSupportedBaud(rate)) << rate;
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
  EXPECT_NE(failure.find("locked by another process (pid " + std::to_string(child)),
            std::string::npos)
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
