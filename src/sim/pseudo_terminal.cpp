#include "serial_robot_driver/sim/pseudo_terminal.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <termios.h>
#include <unistd.h>

#include <cerrno>
#include <climits>
#include <cstdlib>
#include <cstring>

#include "serial_robot_driver/transport/byte_stream.h"
#include "serial_robot_driver/transport/serial_port.h"

namespace serial_robot_driver::sim {

using transport::readFromFd;
using transport::TransportError;
using transport::TransportErrorKind;
using transport::writeAllToFd;

namespace {

[[noreturn]] void throwOpenFailed(const std::string& message, int error_number) {
  throw TransportError(TransportErrorKind::kOpenFailed,
                       message + ": " + std::strerror(error_number));
}

bool isSymlink(const std::string& path) {
  struct stat info {};
  return ::lstat(path.c_str(), &info) == 0 && S_ISLNK(info.st_mode);
}

bool pathExists(const std::string& path) {
  struct stat info {};
  return ::lstat(path.c_str(), &info) == 0;
}

std::string symlinkTarget(const std::string& path) {
  char target[PATH_MAX];
  const ssize_t length = ::readlink(path.c_str(), target, sizeof(target) - 1);
  return length < 0 ? std::string() : std::string(target, static_cast<std::size_t>(length));
}

}  // namespace

PseudoTerminal::PseudoTerminal(const std::string& link_path) {
  // Everything acquired so far is released by close() if a later step throws (the destructor
  // does not run for a constructor that throws).
  try {
    const int master = ::posix_openpt(O_RDWR | O_NOCTTY | O_CLOEXEC);
    if (master < 0) throwOpenFailed("posix_openpt failed", errno);
    master_fd_ = master;
    if (::grantpt(master) != 0) throwOpenFailed("grantpt failed", errno);
    if (::unlockpt(master) != 0) throwOpenFailed("unlockpt failed", errno);
    char name[PATH_MAX];
    const int name_error = ::ptsname_r(master, name, sizeof(name));
    if (name_error != 0) throwOpenFailed("ptsname_r failed", name_error);
    slave_path_ = name;

    const int flags = ::fcntl(master, F_GETFL);
    if (flags < 0 || ::fcntl(master, F_SETFL, flags | O_NONBLOCK) != 0) {
      throwOpenFailed("cannot make the pty master non-blocking", errno);
    }

    slave_fd_ = ::open(slave_path_.c_str(), O_RDWR | O_NOCTTY | O_CLOEXEC | O_NONBLOCK);
    if (slave_fd_ < 0) throwOpenFailed("cannot open " + slave_path_, errno);
    // Raw from the start: bytes written before a client configured the port must not be echoed or
    // have CR/LF translated.
    termios settings{};
    if (::tcgetattr(slave_fd_, &settings) != 0)
      throwOpenFailed("tcgetattr on " + slave_path_, errno);
    ::cfmakeraw(&settings);
    if (::tcsetattr(slave_fd_, TCSANOW, &settings) != 0) {
      throwOpenFailed("tcsetattr on " + slave_path_, errno);
    }

    if (!link_path.empty()) {
      // A link left behind by a crashed run is replaced; anything that is not a link is not ours.
      if (isSymlink(link_path)) {
        ::unlink(link_path.c_str());
      } else if (pathExists(link_path)) {
        throw TransportError(TransportErrorKind::kOpenFailed,
                             "cannot create the pty link " + link_path +
                                 ": a file that is not a symlink is in the way");
      }
      if (::symlink(slave_path_.c_str(), link_path.c_str()) != 0) {
        throwOpenFailed("cannot create the pty link " + link_path, errno);
      }
      link_path_ = link_path;
    }
  } catch (...) {
    close();
    throw;
  }
}

PseudoTerminal::~PseudoTerminal() { close(); }

void PseudoTerminal::close() {
  // Only remove the link while it still points to us: a newer pty may have taken the path over.
  if (!link_path_.empty() && isSymlink(link_path_) && symlinkTarget(link_path_) == slave_path_) {
    ::unlink(link_path_.c_str());
  }
  link_path_.clear();
  if (slave_fd_ >= 0) {
    ::close(slave_fd_);
    slave_fd_ = -1;
  }
  const int master = master_fd_.exchange(-1);
  if (master >= 0) ::close(master);
}

std::size_t PseudoTerminal::read(uint8_t* buffer, std::size_t capacity, int timeout_ms) {
  return readFromFd(master_fd_, buffer, capacity, timeout_ms, slave_path_);
}

void PseudoTerminal::write(const uint8_t* data, std::size_t size) {
  writeAllToFd(master_fd_, data, size, slave_path_);
}

}  // namespace serial_robot_driver::sim
