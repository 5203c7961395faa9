// Who may move the bus servos now. The e-stop refuses motion (counted by source), and a joint
// servo under a trajectory yields to the service or topic that takes it: its goal aborts and its
// trajectory move still queued is dropped, so no trajectory move follows the other command.
//
// Threading: the e-stop and the executor are attached before the bus starts; afterwards any thread
// (the services' spinners, the topic's callback, the bus worker).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "serial_robot_driver/core/e_stop.h"
#include "serial_robot_driver/devices/servo_bus/servo_bus.h"
#include "serial_robot_driver/trajectory/bus_joint.h"
#include "serial_robot_driver/trajectory/executor.h"

namespace serial_robot_driver::devices::servo_bus {

class ServoMotionClaims {
 public:
  /// `bus` and `joints` (the servos named as joints) must outlive this object.
  ServoMotionClaims(ServoBus& bus, const std::vector<trajectory::BusJoint>& joints)
      : bus_(bus), joints_(joints) {}

  void attachEStop(core::EStop& e_stop) { e_stop_ = &e_stop; }
  void attachTrajectories(trajectory::TrajectoryExecutor& executor) { trajectories_ = &executor; }
  /// The node's executor, or null when the bus has no joints under trajectories.
  trajectory::TrajectoryExecutor* trajectories() const { return trajectories_; }

  /// A motion service or topic (`source`) while the e-stop holds: counted, and its refusal (else
  /// ok).
  ServoStatus refuseWhileEStopped(const std::string& source);
  /// A motion service (`source`) taking servos `ids` (empty: every configured servo): refused
  /// while the e-stop holds, else the joints among them yield (yieldJoints) and ok.
  ServoStatus claimServos(const std::vector<uint8_t>& ids, const char* source);
  /// A motion service (`source`) for servo `id`: when it is a joint under a trajectory, the
  /// trajectory stops (its goal aborts) and its queued move is dropped.
  void yieldJoint(uint8_t id, const char* source);
  /// yieldJoint() for each of `ids`; empty: every configured servo (servo/relax, servo/hold).
  void yieldJoints(const std::vector<uint8_t>& ids, const char* source);
  /// servo/move, servo/rotate, servo/hold (`source`): the servos claimed (claimServos), then the
  /// motion; refused while the e-stop holds.
  ServoStatus move(const MoveRequest& request, const char* source);
  ServoStatus rotate(const RotateRequest& request, const char* source);
  ServoStatus hold(const std::vector<uint8_t>& ids, const char* source);
  /// servo/spin, served with the stops (BusPriority::kStop): a SPIN stop (mode 0) is no motion and
  /// works while the e-stop holds, any other mode is refused then; the joint yields either way.
  ServoStatus spin(SpinRequest request, const char* source);
  /// servo/damping, servo/relax: torque off moves nothing actively, so they work while the e-stop
  /// holds (motion_safety.h); the joints yield.
  ServoStatus damping(uint8_t id, uint16_t power_mw, bool wait, const char* source);
  ServoStatus relax(const std::vector<uint8_t>& ids, const char* source);
  /// Queues `moves` (servo_commands, already checked): the joint servos among them under a
  /// trajectory are taken over by them, and their goals aborted.
  void queueCommand(const std::vector<MoveRequest>& moves, const char* source);
  /// The joints' measurements come as often as the poll: their freshness limit follows its rate.
  void followPollRate(double poll_rate);

 private:
  ServoBus& bus_;
  const std::vector<trajectory::BusJoint>& joints_;
  core::EStop* e_stop_ = nullptr;                           // the node's, set before start
  trajectory::TrajectoryExecutor* trajectories_ = nullptr;  // the node's, set before start
};

}  // namespace serial_robot_driver::devices::servo_bus
