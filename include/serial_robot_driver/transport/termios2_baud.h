// Baud rates by number (Linux termios2, BOTHER), for the rates without a Bxxx constant.
#pragma once

#include <optional>

namespace serial_robot_driver::transport {

/// Sets both directions of the open tty `fd` to `baud` bits/s. Returns 0, or the errno of the
/// failed ioctl (ENOTSUP where termios2 does not exist).
int setBaudWithTermios2(int fd, unsigned baud);

/// The output speed of `fd` in bits/s as the kernel holds it; nullopt when termios2 is refused.
std::optional<unsigned> readBaudWithTermios2(int fd);

}  // namespace serial_robot_driver::transport
