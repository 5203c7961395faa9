// The echo device as a device of the driver: its frames, its ~echo/... section and checks. Its
// section is declared here like every device's: adding it edited no shared parameter struct.
#include "serial_robot_driver/core/device_module.h"
#include "serial_robot_driver/devices/echo/echo_codec.h"
#include "serial_robot_driver/devices/echo/echo_device.h"
#include "serial_robot_driver/devices/echo/echo_params.h"
#include "serial_robot_driver/params/driver_params.h"

namespace serial_robot_driver::devices::echo {
extern const params::SectionKey<EchoParams> kEchoSection{"echo"};
}

namespace serial_robot_driver::devices::echo {

namespace {

using params::DriverParams;

void addParameters(std::vector<params::ParamSpec>& table) {
  params::SectionRows<EchoParams>(table, "echo", "echo", [](DriverParams& p) -> EchoParams& {
    return p.section(kEchoSection);
  }).add("timeout", &EchoParams::timeout_ms, params::integerWithin(1, 10000, "ms"));
}

void validate(const DriverParams& p) {
  // A timeout the framer's stale-frame limit can hold: one answer at the slowest baud.
  const int baud = p.baudOf(*core::findDevice("echo"));
  const double answer_ms = 10.0 * (kOverhead + kMaxPayload) * 1000.0 / baud;
  params::require(p.section(kEchoSection).timeout_ms >= answer_ms, "echo/timeout",
                  "is shorter than the longest answer takes at " + std::to_string(baud) + " baud");
}

}  // namespace

extern const core::DeviceModule kModule{
    .name = "echo",
    .title = "Echo",
    .driver_frames = {kAnswerFrames},
    .simulator_frames = {kRequestFrames},
    .sections = {&kEchoSection},
    .add_parameters = addParameters,
    .validate = validate,
    // An unfinished answer holds back the next one no longer than a ping waits for it.
    .stale_frame_timeout =
        [](const DriverParams& p) {
          return std::chrono::milliseconds(p.section(kEchoSection).timeout_ms);
        },
    .make_device = core::makeDevice<EchoDevice>,
};

}  // namespace serial_robot_driver::devices::echo
