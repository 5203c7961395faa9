// The echo device as a device of the driver: its frames, its ~echo/... section and checks. It
// lives in DriverParams::sections: adding it edited no shared parameter struct.
#include "serial_robot_driver/device/device_module.h"
#include "serial_robot_driver/devices/echo/echo_codec.h"
#include "serial_robot_driver/devices/echo/echo_params.h"
#include "serial_robot_driver/params/driver_params.h"

namespace serial_robot_driver::devices::echo {

namespace {

using params::DriverParams;
using params::EchoParams;

EchoParams& section(DriverParams& p) { return p.sections.get<EchoParams>("echo"); }

void addParameters(std::vector<params::ParamSpec>& table) {
  params::SectionRows<EchoParams>(table, "echo", "echo", section)
      .add("timeout", &EchoParams::timeout_ms, params::integerWithin(1, 10000, "ms"));
}

void validate(const DriverParams& p) {
  // A timeout the framer's stale-frame limit can hold: one answer at the slowest baud.
  const int baud = p.baudOf(*device::findDevice("echo"));
  const double answer_ms =
      10.0 * (protocol::echo::kOverhead + protocol::echo::kMaxPayload) * 1000.0 / baud;
  params::require(p.sections.get<EchoParams>("echo").timeout_ms >= answer_ms, "echo/timeout",
                  "is shorter than the longest answer takes at " + std::to_string(baud) + " baud");
}

}  // namespace

extern const device::DeviceModule kModule{
    "echo",
    "Echo",
    {protocol::echo::kAnswerFrames},
    {protocol::echo::kRequestFrames},
    [](DriverParams& p) -> params::DevicePortParams& { return section(p); },
    addParameters,
    validate,
    nullptr,
    // An unfinished answer holds back the next one no longer than a ping waits for it.
    [](const DriverParams& p) {
      return std::chrono::milliseconds(p.sections.get<EchoParams>("echo").timeout_ms);
    },
};

}  // namespace serial_robot_driver::devices::echo
