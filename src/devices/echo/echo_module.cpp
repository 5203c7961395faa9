// The echo device as a device of the driver: its frames, its ~echo/... section and checks. Its
// section is declared here like every device's: adding it edited no shared parameter struct.
#include "serial_robot_driver/device/device_module.h"
#include "serial_robot_driver/devices/echo/echo_codec.h"
#include "serial_robot_driver/devices/echo/echo_params.h"
#include "serial_robot_driver/params/driver_params.h"

namespace serial_robot_driver::params {
extern const SectionKey<EchoParams> kEchoSection{"echo"};
}

namespace serial_robot_driver::devices::echo {

namespace {

using params::DriverParams;
using params::EchoParams;

void addParameters(std::vector<params::ParamSpec>& table) {
  params::SectionRows<EchoParams>(table, "echo", "echo", [](DriverParams& p) -> EchoParams& {
    return p.section(params::kEchoSection);
  }).add("timeout", &EchoParams::timeout_ms, params::integerWithin(1, 10000, "ms"));
}

void validate(const DriverParams& p) {
  // A timeout the framer's stale-frame limit can hold: one answer at the slowest baud.
  const int baud = p.baudOf(*device::findDevice("echo"));
  const double answer_ms =
      10.0 * (protocol::echo::kOverhead + protocol::echo::kMaxPayload) * 1000.0 / baud;
  params::require(p.section(params::kEchoSection).timeout_ms >= answer_ms, "echo/timeout",
                  "is shorter than the longest answer takes at " + std::to_string(baud) + " baud");
}

}  // namespace

extern const device::DeviceModule kModule{
    .name = "echo",
    .title = "Echo",
    .driver_frames = {protocol::echo::kAnswerFrames},
    .simulator_frames = {protocol::echo::kRequestFrames},
    .sections = {&params::kEchoSection},
    .add_parameters = addParameters,
    .validate = validate,
    // An unfinished answer holds back the next one no longer than a ping waits for it.
    .stale_frame_timeout =
        [](const DriverParams& p) {
          return std::chrono::milliseconds(p.section(params::kEchoSection).timeout_ms);
        },
};

}  // namespace serial_robot_driver::devices::echo
