#include "serial_robot_driver/core/guarded_call.h"

#include <optional>

namespace serial_robot_driver::core {

bool runGuarded(InputRefusals& counters, const std::string& source,
                const std::function<void()>& callback, std::string* error,
                const CallbackErrorLog& log) {
  std::optional<std::string> what;
  catchAll(callback, [&what](const std::string& caught) { what = caught; });
  if (!what) return true;
  counters.failed(source);
  if (log) {
    log(source + ": internal error, this input was dropped (or answered as a failure): " + *what);
  }
  if (error) *error = *what;
  return false;
}

std::string internalErrorText(const std::string& what) { return "internal error: " + what; }

}  // namespace serial_robot_driver::core
