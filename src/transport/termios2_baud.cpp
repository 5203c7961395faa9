// Arbitrary baud rates on Linux: termios2 with BOTHER, the way serial libraries (pyserial, the
// Linux serial drivers' own docs) set a rate that has no Bxxx constant, e.g. the servos' 250000.
// Its own file because <asm/termbits.h> (struct termios2) cannot share a translation unit with
// glibc's <termios.h>.
#include "serial_robot_driver/transport/termios2_baud.h"

#ifdef __linux__
#include <asm/ioctls.h>
#include <asm/termbits.h>
#include <sys/ioctl.h>
#endif

#include <cerrno>

namespace serial_robot_driver::transport {

int setBaudWithTermios2(int fd, unsigned baud) {
#if defined(__linux__) && defined(BOTHER) && defined(TCGETS2)
  struct termios2 settings {};
  if (::ioctl(fd, TCGETS2, &settings) != 0) return errno;
  settings.c_cflag &= ~(CBAUD | (CBAUD << IBSHIFT));
  settings.c_cflag |= BOTHER | (BOTHER << IBSHIFT);
  settings.c_ispeed = baud;
  settings.c_ospeed = baud;
  if (::ioctl(fd, TCSETS2, &settings) != 0) return errno;
  return 0;
#else
  (void)fd;
  (void)baud;
  return ENOTSUP;
#endif
}

std::optional<unsigned> readBaudWithTermios2(int fd) {
#if defined(__linux__) && defined(TCGETS2)
  struct termios2 settings {};
  if (::ioctl(fd, TCGETS2, &settings) != 0) return std::nullopt;
  return settings.c_ospeed;
#else
  (void)fd;
  return std::nullopt;
#endif
}

}  // namespace serial_robot_driver::transport
