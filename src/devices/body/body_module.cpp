// The servo controller board as a device of the driver: its frames, its parameter sections
// (~body/... and its IMU's ~imu/...) and checks.
#include <array>
#include <set>

#include "serial_robot_driver/core/device_module.h"
#include "serial_robot_driver/devices/body/body_codec.h"
#include "serial_robot_driver/devices/body/body_device.h"
#include "serial_robot_driver/devices/body/body_params.h"
#include "serial_robot_driver/devices/body/gyro_bias.h"
#include "serial_robot_driver/params/driver_params.h"

namespace serial_robot_driver::devices::body {
extern const params::SectionKey<BodyParams> kBodySection{"body"};
extern const params::SectionKey<ImuParams> kImuSection{"imu"};
}  // namespace serial_robot_driver::devices::body

namespace serial_robot_driver::devices::body {

namespace {

using params::DriverParams;
using params::require;

void servoIds(const std::vector<int>& ids, const std::string& key) {
  require(!ids.empty(), key, "must list at least one servo id");
  require(ids.size() <= kMaxTelemetryServos, key,
          "at most " + std::to_string(kMaxTelemetryServos) + " servos fit in a telemetry frame");
  std::set<int> seen;
  for (int id : ids) {
    // 253 = FD would put FF FF FD, the sync-write header, inside a sync-write frame.
    require(id >= 0 && id <= 252, key,
            "ids must be 0..252 (253 would look like a frame header, 254 is broadcast), got " +
                std::to_string(id));
    require(seen.insert(id).second, key, "id " + std::to_string(id) + " is listed twice");
  }
}

void addParameters(std::vector<params::ParamSpec>& table) {
  // The board's own values and the calibration every joint shares (BodyParams::calibration), in
  // the documented order.
  using Own = BodyParams;
  using Calibration = JointCalibration;
  params::SectionRows<Own> own(table, "body", "body",
                               [](DriverParams& p) -> Own& { return p.section(kBodySection); });
  params::SectionRows<Calibration> joints(
      table, "body", "body",
      [](DriverParams& p) -> Calibration& { return p.section(kBodySection).calibration; });
  own.add("servo_ids", &Own::servo_ids, servoIds)
      .add("joint_names", &Own::joint_names, params::uniqueNames);
  joints.add("ticks_per_revolution", &Calibration::ticks_per_revolution,
             [](const int& v, const std::string& key) { require(v > 0, key, "must be > 0"); });
  own.add("zero_ticks", &Own::zero_ticks,
          [](const std::vector<int>& zeros, const std::string& key) {
            for (int zero : zeros)
              require(zero >= 0 && zero <= 65535, key, "entries must be 0..65535");
          })
      .add("directions", &Own::directions, params::directionList);
  joints.add("velocity_scale", &Calibration::velocity_scale, params::nonNegativeNumber);
  // The IMU is the board's: its keys are checked while the body is enabled.
  params::SectionRows<ImuParams>(
      table, "body", "imu", [](DriverParams& p) -> ImuParams& { return p.section(kImuSection); })
      .add("frame_id", &ImuParams::frame_id,
           [](const std::string& v, const std::string& key) {
             require(!v.empty(), key, "must not be empty");
           })
      .add("axis_map", &ImuParams::axis_map,
           [](const std::vector<std::string>& entries, const std::string& key) {
             std::string problem;
             require(parseAxisMap(entries, &problem).has_value(), key, problem);
           })
      .add("accel_scale", &ImuParams::accel_scale, params::positiveNumber)
      .add("gyro_scale", &ImuParams::gyro_scale, params::positiveNumber)
      .add("angle_scale", &ImuParams::angle_scale, params::positiveNumber)
      .add("orientation_variance", &ImuParams::orientation_variance, params::finiteNumber)
      .add("angular_velocity_variance", &ImuParams::angular_velocity_variance,
           params::nonNegativeNumber)
      .add("linear_acceleration_variance", &ImuParams::linear_acceleration_variance,
           params::nonNegativeNumber)
      .add("calibration_time", &ImuParams::calibration_time, params::numberWithin(0.1, 60.0, "s"))
      .add("calibrate_on_start", &ImuParams::calibrate_on_start);
}

void validate(const DriverParams& p) {
  const BodyParams& body = p.section(kBodySection);
  const std::size_t n = body.servo_ids.size();
  const auto requireOnePerServo = [n](std::size_t size, const std::string& name) {
    require(size == n, name,
            "has " + std::to_string(size) + " entries but body/servo_ids has " + std::to_string(n));
  };
  requireOnePerServo(body.joint_names.size(), "body/joint_names");
  requireOnePerServo(body.zero_ticks.size(), "body/zero_ticks");
  requireOnePerServo(body.directions.size(), "body/directions");
}

void resolveFrames(DriverParams& p) {
  ImuParams& imu = p.section(kImuSection);
  imu.frame_id = params::resolveFrame(p.tf_prefix, imu.frame_id);
}

}  // namespace

extern const core::DeviceModule kModule{
    .name = "body",
    .title = "Body",
    .driver_frames = {kTelemetryFrames},
    .simulator_frames = {kSyncWriteFrames},
    .sections = {&kBodySection, &kImuSection},
    .add_parameters = addParameters,
    .validate = validate,
    .resolve_frames = resolveFrames,
    // A telemetry frame's LEN depends on how many servos it carries.
    .probe_argument =
        [](const DriverParams& p) { return p.section(kBodySection).servo_ids.size(); },
    .make_device = core::makeDevice<BodyDevice>,
};

}  // namespace serial_robot_driver::devices::body

namespace serial_robot_driver::devices::body {

GyroUnits gyroUnits(const ImuParams& imu) {
  return {imu.gyro_scale, parseAxisMap(imu.axis_map, nullptr).value_or(AxisMap{})};
}

std::optional<AxisMap> parseAxisMap(const std::vector<std::string>& entries, std::string* problem) {
  const auto fail = [problem](const std::string& text) {
    if (problem) *problem = text;
    return std::nullopt;
  };
  if (entries.size() != 3) {
    return fail("must list 3 axes (imu x, y, z), e.g. [x, y, z] or [-y, x, z]; got " +
                std::to_string(entries.size()));
  }
  AxisMap map;
  std::array<bool, 3> used{};
  for (std::size_t i = 0; i < 3; ++i) {
    std::string entry = entries[i];
    int sign = 1;
    if (!entry.empty() && (entry[0] == '-' || entry[0] == '+')) {
      sign = entry[0] == '-' ? -1 : 1;
      entry.erase(0, 1);
    }
    if (entry != "x" && entry != "y" && entry != "z") {
      return fail("entry '" + entries[i] + "' is not x, y or z with an optional sign");
    }
    const int source = entry[0] - 'x';
    if (used[source]) return fail("sensor axis " + entry + " is used twice");
    used[source] = true;
    map.source[i] = source;
    map.sign[i] = sign;
  }
  // The determinant of a signed permutation: the permutation's parity times the signs.
  const int inversions = (map.source[0] > map.source[1]) + (map.source[0] > map.source[2]) +
                         (map.source[1] > map.source[2]);
  const int determinant = (inversions % 2 ? -1 : 1) * map.sign[0] * map.sign[1] * map.sign[2];
  if (determinant != 1) {
    return fail("is a mirror image (left-handed); flip the sign of one axis to make it a rotation");
  }
  return map;
}

}  // namespace serial_robot_driver::devices::body
