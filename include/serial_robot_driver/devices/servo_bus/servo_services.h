// The servo/* services, ROS-free: what each request does (a call on the client, the bus or the
// motion claims) and the outcome handling every front end shares: the reply's message (naming the
// parameter that arms a refused dangerous write), the refusal counted under the service's name,
// the lines in the core's log (core/log.h: every outcome at debug; a changed setting at info). A
// front end copies its request's fields into these calls and the reply's fields into its response,
// and serves them on threads of its own (a stop service must never wait behind another call:
// servo_bus_ros.h).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "serial_robot_driver/core/input_refusals.h"
#include "serial_robot_driver/devices/servo_bus/servo_bus.h"
#include "serial_robot_driver/devices/servo_bus/servo_identity.h"
#include "serial_robot_driver/devices/servo_bus/servo_motion_claims.h"

namespace serial_robot_driver::devices::servo_bus {

/// The services' names: where they are offered, the source their refusals are counted under and
/// the prefix of their log lines.
namespace servo_service {
constexpr char kPing[] = "servo/ping";
constexpr char kRead[] = "servo/read";
constexpr char kReadAngle[] = "servo/read_angle";
constexpr char kScan[] = "servo/scan";
constexpr char kReadAll[] = "servo/read_all";
constexpr char kInfo[] = "servo/info";
constexpr char kWrite[] = "servo/write";
constexpr char kResetUserData[] = "servo/reset_user_data";
constexpr char kMove[] = "servo/move";
constexpr char kRotate[] = "servo/rotate";
constexpr char kSpin[] = "servo/spin";
constexpr char kDamping[] = "servo/damping";
constexpr char kRelax[] = "servo/relax";
constexpr char kHold[] = "servo/hold";
}  // namespace servo_service

/// What every servo/* answer carries: whether it succeeded (servo/ping: the servo is online;
/// servo/scan has no flag) and the message.
struct ServoReply {
  bool ok = false;
  std::string message;
};
/// servo/read: the value in `unit` (0 and "" unless ok).
struct ServoReadReply : ServoReply {
  int64_t value = 0;
  std::string unit;
};
/// servo/read_angle: the angle and, multi-turn only, the turn count (0 unless ok).
struct ServoAngleReply : ServoReply {
  double angle_deg = 0.0;
  int16_t turns = 0;
};
/// servo/scan: the ids that answered.
struct ServoScanReply : ServoReply {
  std::vector<uint8_t> ids;
};
/// servo/read_all: the user-block parameters read, each in its unit.
struct ServoReadAllReply : ServoReply {
  std::vector<std::string> names;
  std::vector<int64_t> values;
};
/// servo/info: the identity read (complete only when ok).
struct ServoInfoReply : ServoReply {
  ServoIdentity identity;
};

class ServoServices {
 public:
  /// `bus`, `claims` and `refusals` (where refused requests are counted) must outlive this object.
  ServoServices(ServoBus& bus, ServoMotionClaims& claims, core::InputRefusals& refusals)
      : bus_(bus), claims_(claims), refusals_(refusals) {}

  // Reads: allowed while the e-stop holds.
  ServoReply ping(uint8_t id);
  ServoReadReply read(uint8_t id, const std::string& param);
  ServoAngleReply readAngle(uint8_t id, bool multi_turn);
  ServoScanReply scan(uint8_t first_id, uint8_t last_id);
  ServoReadAllReply readAll(uint8_t id);
  ServoInfoReply info(uint8_t id);
  // Writes: they change a servo's settings (logged at info).
  ServoReply write(uint8_t id, const std::string& param, int64_t value);
  ServoReply resetUserData(uint8_t id);
  // Motion, claimed (the e-stop, the trajectories: servo_motion_claims.h).
  ServoReply move(const MoveRequest& request);
  ServoReply rotate(const RotateRequest& request);
  // The stops (a front end serves them apart from the others).
  ServoReply spin(const SpinRequest& request);
  ServoReply damping(uint8_t id, uint16_t power_mw, bool wait);
  ServoReply relax(const std::vector<uint8_t>& ids);
  ServoReply hold(const std::vector<uint8_t>& ids);

 private:
  enum class Announce { kDebug, kInfo };
  /// Logs the outcome of `service`, counts a refused request and fills `reply`'s outcome.
  void conclude(const char* service, const ServoStatus& status, ServoReply& reply,
                Announce announce = Announce::kDebug) const;
  ServoReply concluded(const char* service, const ServoStatus& status,
                       Announce announce = Announce::kDebug) const;

  ServoBus& bus_;
  ServoMotionClaims& claims_;
  core::InputRefusals& refusals_;
};

}  // namespace serial_robot_driver::devices::servo_bus
